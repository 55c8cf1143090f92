#pragma once
// `patchskin compare A B`: numeric comparison of two image files in the manner of
// OpenImageIO's idiff, with the same thresholds as the golden tests.
//
//   patchskin compare A B [--fail T] [--failpercent P] [--hardfail H]
//                         [--diff D.png] [--scale S]
//
// Prints mean, RMS, PSNR, max error (with its pixel and channel) and the share of
// failing pixels, then PASS or FAIL. 8-bit/16-bit files are compared in their
// sRGB-encoded values (as idiff does on such files), float files (EXR) in linear
// values. --diff writes |A - B| amplified by --scale (also written on PASS).
// Exit codes: 0 pass, 1 fail, 2 error (missing file, unreadable, size mismatch,
// bad option); on error the first stderr line is the formatted error.

#include <string>

namespace CLI {
class App;
}

namespace app {

struct CompareCommandOptions {
  std::string image_a;
  std::string image_b;
  float fail = 0.004f;         // per-value threshold for a failing pixel
  float fail_percent = 0.02f;  // percent of pixels allowed over `fail`
  float hard_fail = 0.012f;    // no value may differ more
  std::string diff_path;       // optional difference image (.png/.exr/...)
  float diff_scale = 10.0f;    // amplification of the difference image
};

inline constexpr int kComparePass = 0;
inline constexpr int kCompareFail = 1;
inline constexpr int kCompareError = 2;

// Adds the `compare` subcommand to `app`, storing its arguments in `*options`
// (which must outlive parsing). Returns the subcommand.
CLI::App* AddCompareCommand(CLI::App& app, CompareCommandOptions* options);

// Runs the comparison; prints to stdout (report) and stderr (errors). Returns the
// exit code.
int RunCompareCommand(const CompareCommandOptions& options);

}  // namespace app
