#pragma once
// Numeric image comparison in the manner of OpenImageIO's idiff, built on
// OIIO::ImageBufAlgo::compare (OIIO stays inside image_compare.cpp).
//
// Every channel of every pixel is compared: d = |a - b|. A pixel "fails" when any
// of its channels has d > fail_thresh. The images differ (passed == false) when
//   failing pixels > fail_percent / 100 * #pixels   or   max d > hard_fail,
// which is idiff's rule and the one OpenImageIO's own test suite uses with
// fail 0.004, fail_percent 0.02, hard_fail 0.012 (our defaults). Thresholds of 0
// ask for bit-exact equality of the compared values.
//
// Space: frames are written as 8-bit sRGB, so by default colour is compared in
// sRGB-encoded values (what the PNG stores; 0.004 is about one 8-bit step) —
// the numbers then match `idiff` run on the PNG files. Alpha is never encoded.

#include <cstdint>

#include "base/error.h"
#include "render/image.h"

namespace render {

using base::Result;

// Which values are compared.
enum class CompareSpace {
  kSrgbEncoded,  // RGB through LinearToSrgb (not quantized), alpha as is
  kLinear,       // Image values as stored (for float files, EXR)
};

struct CompareThresholds {
  float fail_thresh = 0.004f;    // per-value difference that makes a pixel fail
  float fail_percent = 0.02f;    // percent of pixels allowed to fail (0.02 = 1 in 5000)
  float hard_fail = 0.012f;      // any value differing more fails the comparison
  CompareSpace space = CompareSpace::kSrgbEncoded;
};

struct CompareResult {
  double max_error = 0.0;     // largest |a - b| over all values
  int max_x = 0;              // pixel and channel (0=R..3=A) of max_error
  int max_y = 0;
  int max_channel = 0;
  double mean_error = 0.0;    // mean |a - b| over all #pixels x 4 values
  double rms_error = 0.0;     // sqrt(mean (a - b)^2) over all values
  double psnr_db = 0.0;       // 20 log10(1 / rms_error); +inf when identical
  std::int64_t num_pixels = 0;
  std::int64_t num_failing = 0;  // pixels with a value over fail_thresh
  double failing_percent = 0.0;  // 100 * num_failing / num_pixels
  bool passed = true;            // by the rule above
};

// Compares two images of the same size (RGBA only; depth is ignored).
// Errors: kInvalidArgument when the sizes differ or an image is empty/inconsistent,
// kInternal when OpenImageIO reports a failure.
[[nodiscard]] Result<CompareResult> Compare(const Image& a, const Image& b,
                                            const CompareThresholds& thresholds = {});

// Amplified difference image for people to look at: rgb = scale * |a - b| per
// channel in `space` (clamped to 1), alpha = 1. Sizes must match (else error).
[[nodiscard]] Result<Image> MakeDiffImage(const Image& a, const Image& b, float scale = 10.0f,
                                          CompareSpace space = CompareSpace::kSrgbEncoded);

}  // namespace render
