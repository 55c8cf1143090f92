#include "support/golden.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <sstream>

#include <gtest/gtest.h>

#include "render/output/image_io.h"

namespace testsupport {
namespace {

namespace fs = std::filesystem;

// The image as an 8-bit sRGB PNG would hold it, back in linear values.
render::Image QuantizeLikePng(const render::Image& img) {
  render::Image q(img.width, img.height);
  for (std::size_t i = 0; i < img.rgba.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      q.rgba[i][c] = render::Srgb8ToLinear(render::LinearToSrgb8(img.rgba[i][c]));
    }
    const float a = std::clamp(img.rgba[i].a, 0.0f, 1.0f);
    q.rgba[i].a = std::round(a * 255.0f) / 255.0f;
  }
  return q;
}

const char* ChannelName(int c) {
  static const char* kNames[] = {"R", "G", "B", "A"};
  return c >= 0 && c < 4 ? kNames[c] : "?";
}

}  // namespace

GoldenDirs DefaultGoldenDirs() {
  GoldenDirs d;
  d.ref_dir = fs::path(GOLDEN_DIR) / "ref";
  d.output_dir = fs::path(TEST_OUTPUT_DIR) / "golden";
  const char* env = std::getenv("GOLDEN_UPDATE");
  d.update = env != nullptr && std::string(env) == "1";
  return d;
}

GoldenOutcome CheckGolden(const render::Image& actual, const std::string& case_name,
                          const render::CompareThresholds& thresholds, const GoldenDirs& dirs) {
  GoldenOutcome out;
  out.reference = dirs.ref_dir / (case_name + ".png");
  const render::Image quantized = QuantizeLikePng(actual);
  render::WriteOptions png;
  png.png_compression = 9;  // references live in git: smallest files

  if (dirs.update) {
    fs::create_directories(dirs.ref_dir);
    const base::Status s = render::WriteImage(quantized, out.reference.string(), png);
    out.passed = s.ok();
    out.updated = s.ok();
    out.message = s.ok() ? "golden " + case_name + ": updated reference " + out.reference.string()
                         : "golden " + case_name + ": cannot update reference: " +
                               s.error().ToString();
    return out;
  }

  const fs::path case_dir = dirs.output_dir / case_name;
  std::error_code ec;
  fs::remove_all(case_dir, ec);  // stale files from an earlier failure would mislead
  auto write_actual = [&]() {
    fs::create_directories(case_dir);
    out.actual_path = case_dir / "actual.png";
    (void)render::WriteImage(quantized, out.actual_path.string(), png);
  };

  std::ostringstream msg;
  msg << "golden " << case_name << ": ";
  if (!fs::exists(out.reference)) {
    write_actual();
    msg << "no reference image " << out.reference.string() << "\n  actual: "
        << out.actual_path.string()
        << "\n  look at it, then create the reference deliberately with\n"
           "    GOLDEN_UPDATE=1 ctest -L golden   (or: cmake --build <build> --target "
           "update_golden)\n  and commit it";
    out.message = msg.str();
    return out;
  }
  base::Result<render::Image> ref = render::ReadImage(out.reference.string());
  if (!ref.ok()) {
    msg << "cannot read the reference: " << ref.error().ToString();
    out.message = msg.str();
    return out;
  }
  base::Result<render::CompareResult> cmp = render::Compare(quantized, *ref, thresholds);
  if (!cmp.ok()) {
    write_actual();
    msg << cmp.error().message << "\n  reference: " << out.reference.string()
        << "\n  actual:    " << out.actual_path.string();
    out.message = msg.str();
    return out;
  }
  out.compare = *cmp;
  const render::CompareResult& r = *cmp;
  msg << (r.passed ? "PASS" : "FAIL") << "  max error " << r.max_error << " at pixel (" << r.max_x
      << ", " << r.max_y << ") channel " << ChannelName(r.max_channel) << ", mean " << r.mean_error
      << ", PSNR " << r.psnr_db << " dB, " << r.num_failing << " of " << r.num_pixels
      << " pixels (" << r.failing_percent << " %) over " << thresholds.fail_thresh
      << " (allowed " << thresholds.fail_percent << " %, hard fail " << thresholds.hard_fail
      << ")";
  out.passed = r.passed;
  if (!r.passed) {
    write_actual();
    base::Result<render::Image> diff =
        render::MakeDiffImage(quantized, *ref, kGoldenDiffScale, thresholds.space);
    if (diff.ok()) {
      out.diff_path = case_dir / "diff.png";
      (void)render::WriteImage(*diff, out.diff_path.string());
    }
    msg << "\n  reference: " << out.reference.string() << "\n  actual:    "
        << out.actual_path.string() << "\n  diff:      " << out.diff_path.string()
        << "\n  if the change is intended: GOLDEN_UPDATE=1 ctest -L golden, review, commit";
  }
  out.message = msg.str();
  return out;
}

void ExpectMatchesGolden(const render::Image& actual, const std::string& case_name,
                         const render::CompareThresholds& thresholds) {
  const GoldenOutcome o = CheckGolden(actual, case_name, thresholds);
  if (!o.passed) {
    ADD_FAILURE() << o.message;
  } else {
    std::cout << o.message << "\n";
  }
}

}  // namespace testsupport
