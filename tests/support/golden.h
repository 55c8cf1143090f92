#pragma once
// Golden-image harness (STYLE.md section 8). A test renders an image and calls
//
//   testsupport::ExpectMatchesGolden(image, "case_name", thresholds);
//
// which compares it with tests/golden/ref/<case_name>.png using render::Compare
// (OpenImageIO's ImageBufAlgo::compare and idiff's fail / fail_percent / hard_fail
// rule). The image is first quantized to 8-bit sRGB as the PNG would store it, so
// an unchanged render compares bit-exactly (max error 0).
//
// On failure it writes <build>/test-output/golden/<case>/actual.png and diff.png
// (|actual - ref| in sRGB values, amplified x kGoldenDiffScale) and prints both
// paths with the maximum error and its pixel. A missing reference fails and says
// how to create it. Only GOLDEN_UPDATE=1 (e.g. `GOLDEN_UPDATE=1 ctest -L golden`
// or the `update_golden` target) writes references; nothing else ever does.

#include <filesystem>
#include <optional>
#include <string>

#include "render/image.h"
#include "render/output/image_compare.h"

namespace testsupport {

// Amplification of diff.png: one 8-bit step (1/255) shows as ~10 % grey.
inline constexpr float kGoldenDiffScale = 25.0f;

struct GoldenDirs {
  std::filesystem::path ref_dir;     // holds <case>.png references
  std::filesystem::path output_dir;  // gets <case>/actual.png and <case>/diff.png
  bool update = false;               // rewrite the reference instead of comparing
};

// tests/golden/ref, <build>/test-output/golden, and update = (GOLDEN_UPDATE == "1").
GoldenDirs DefaultGoldenDirs();

struct GoldenOutcome {
  bool passed = false;
  bool updated = false;                  // the reference was (re)written
  std::string message;                   // what happened, with paths; for the test log
  std::filesystem::path reference;       // <ref_dir>/<case>.png
  std::filesystem::path actual_path;     // written on failure, else empty
  std::filesystem::path diff_path;       // written on a comparable failure, else empty
  std::optional<render::CompareResult> compare;  // when both images could be compared
};

// The check without gtest assertions (so the harness itself can be tested).
GoldenOutcome CheckGolden(const render::Image& actual, const std::string& case_name,
                          const render::CompareThresholds& thresholds,
                          const GoldenDirs& dirs = DefaultGoldenDirs());

// CheckGolden + ADD_FAILURE with its message on failure.
void ExpectMatchesGolden(const render::Image& actual, const std::string& case_name,
                         const render::CompareThresholds& thresholds = {});

}  // namespace testsupport
