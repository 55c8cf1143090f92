#pragma once
// Comparison of two image files as OpenImageIO 2.4's `idiff` makes it: every
// channel of the files (R, G, B, A, Z and any other), the values as the files
// store them (8/16-bit codes scaled to 0..1, half/float as is: no colour
// conversion), over the union of the two images' pixel windows, a pixel or
// channel that one image lacks counting as 0.
//
//   inputs:  two paths, IdiffThresholds
//   outputs: FileCompareResult (idiff's figures, the largest error per channel,
//            the verdict) or an error (kIo) naming the unreadable file
//   cost:    both files decoded to float (4 bytes per sample) plus one pass over
//            the union of their pixels; files over kMaxReadSamples are refused
//
// Verdict, with N the pixels of the union (idiff 2.4's rule, found by running it):
//   pass     when  #failing pixels <= allowfailures (whatever else holds: so
//                  differences under `fail` never warn, however many)
//   failure  when  #failing pixels > failpercent/100 * N  or  max error > hardfail
//   warning  when  #warning pixels > warnpercent/100 * N  or  max error > hardwarn
//   pass     otherwise.
// A pixel fails (warns) when any of its channels differs by more than `fail`
// (`warn`). The sums come from OIIO::ImageBufAlgo::compare, the function idiff
// calls, so the figures are idiff's to the last digit.

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "base/error.h"

namespace render {

struct IdiffThresholds {
  float fail = 1e-6f;          // per-value difference that makes a pixel fail
  float fail_percent = 0.0f;   // percent of pixels allowed to fail
  float hard_fail = std::numeric_limits<float>::infinity();  // no value may differ more
  float warn = 1e-6f;          // per-value difference that makes a pixel warn
  float warn_percent = 0.0f;   // percent of pixels allowed to warn
  float hard_warn = std::numeric_limits<float>::infinity();  // a larger error warns
  std::int64_t allow_failures = 0;  // this many failing pixels pass, by any amount
};

// idiff's exit codes for the verdicts.
enum class CompareVerdict { kPass = 0, kWarning = 1, kFailure = 2 };

// "PASS", "WARNING", "FAILURE" (idiff's last line).
const char* VerdictName(CompareVerdict v);

struct FileCompareResult {
  int width_a = 0, height_a = 0, width_b = 0, height_b = 0;
  bool same_size = true;
  std::vector<std::string> channels;  // the union's channels: A's names, then B's extra ones
  int channels_a = 0, channels_b = 0;
  std::int64_t num_pixels = 0;        // pixels of the union of the two windows
  double mean_error = 0.0;            // over every value of the union
  double rms_error = 0.0;
  double psnr_db = 0.0;               // +inf when identical
  double max_error = 0.0;
  int max_x = 0, max_y = 0, max_channel = 0;
  std::vector<float> values_a, values_b;  // each file's values at (max_x, max_y)
  std::vector<double> channel_max_error;  // the largest error in each channel
  std::int64_t num_warn = 0;          // pixels with a value over `warn`
  std::int64_t num_fail = 0;          // pixels with a value over `fail`
  CompareVerdict verdict = CompareVerdict::kPass;
};

// Compares the first subimage of the two files. Errors: kIo naming the file that
// is missing or unreadable, kLimitExceeded for a file over kMaxReadSamples samples.
[[nodiscard]] base::Result<FileCompareResult> CompareImageFiles(
    const std::string& path_a, const std::string& path_b, const IdiffThresholds& thresholds = {});

}  // namespace render
