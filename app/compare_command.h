#pragma once
// `patchskin compare A B`: a drop-in for OpenImageIO 2.4's `idiff` (the one
// scripts/setup.sh installs): the same figures, thresholds, defaults, verdict
// and exit codes, on every channel of the files (Z and beyond RGBA included);
// see render/output/image_file_compare.h for the rule.
//
//   patchskin compare A B [--fail T] [--failpercent P] [--hardfail H]
//                         [--warn T] [--warnpercent P] [--hardwarn H]
//                         [--allowfailures N] [--diff D.png] [--scale S]
//
// idiff's single-dash spellings (-fail, -warn, -failpercent, -warnpercent,
// -hardfail, -hardwarn, -allowfailures, -scale) are accepted as well
// (NormalizeIdiffSpelling, called by main before parsing).
// Prints idiff's lines (mean, RMS, PSNR, max error with its pixel, channel and
// values, pixels over warn and fail), the largest error of each channel, a note
// when the sizes differ, then PASS, WARNING or FAILURE.
// Exit codes: 0 pass, 1 warning, 2 failure, 4 error (unreadable or missing file,
// bad option; idiff exits 1 on a bad option, which a CI script would take for a
// warning). On error the first stderr line is the formatted error.

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace app {

struct CompareCommandOptions {
  std::string image_a;
  std::string image_b;
  // idiff's defaults: any difference over 1e-6 fails.
  float fail = 1e-6f;
  float fail_percent = 0.0f;
  float hard_fail = std::numeric_limits<float>::infinity();
  float warn = 1e-6f;
  float warn_percent = 0.0f;
  float hard_warn = std::numeric_limits<float>::infinity();
  std::int64_t allow_failures = 0;
  std::string diff_path;       // optional difference image (.png/.exr/...)
  float diff_scale = 10.0f;    // amplification of the difference image
};

inline constexpr int kComparePass = 0;
inline constexpr int kCompareWarning = 1;
inline constexpr int kCompareFail = 2;
inline constexpr int kCompareError = 4;

// Rewrites idiff's single-dash option names after a "compare" argument into
// the double-dash ones CLI11 parses ("-fail" -> "--fail"); others are unchanged.
void NormalizeIdiffSpelling(std::vector<std::string>& args);

// Runs the comparison; prints to stdout (report) and stderr (errors). Returns the
// exit code.
int RunCompareCommand(const CompareCommandOptions& options);

}  // namespace app
