#include "app/compare_command.h"

#include <cmath>
#include <cstdio>

#include <CLI/CLI.hpp>

#include "render/output/image_compare.h"
#include "render/output/image_io.h"

namespace app {
namespace {

int Error(const std::string& formatted) {
  std::fprintf(stderr, "%s\n", formatted.c_str());
  return kCompareError;
}

const char* ChannelName(int c) {
  static const char* kNames[] = {"R", "G", "B", "A"};
  return c >= 0 && c < 4 ? kNames[c] : "?";
}

}  // namespace

CLI::App* AddCompareCommand(CLI::App& app, CompareCommandOptions* o) {
  CLI::App* cmd = app.add_subcommand(
      "compare", "Compare two images (as OpenImageIO's idiff): exit 0 pass, 1 fail, 2 error");
  cmd->add_option("A", o->image_a, "first image")->required();
  cmd->add_option("B", o->image_b, "second image (the reference)")->required();
  cmd->add_option("--fail", o->fail, "per-value difference that makes a pixel fail")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--failpercent", o->fail_percent, "percent of pixels allowed to fail")
      ->capture_default_str()
      ->check(CLI::Range(0.0f, 100.0f));
  cmd->add_option("--hardfail", o->hard_fail, "fail if any value differs more than this")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--diff", o->diff_path, "write the amplified difference image here");
  cmd->add_option("--scale", o->diff_scale, "amplification of the difference image")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  return cmd;
}

int RunCompareCommand(const CompareCommandOptions& o) {
  render::ReadInfo info_a, info_b;
  mocap::Result<render::Image> a = render::ReadImage(o.image_a, &info_a);
  if (!a.ok()) return Error(a.error().ToString());
  mocap::Result<render::Image> b = render::ReadImage(o.image_b, &info_b);
  if (!b.ok()) return Error(b.error().ToString());

  render::CompareThresholds t;
  t.fail_thresh = o.fail;
  t.fail_percent = o.fail_percent;
  t.hard_fail = o.hard_fail;
  // Integer files hold sRGB codes: compare those, as idiff would on the files.
  t.space = info_a.srgb_encoded || info_b.srgb_encoded ? render::CompareSpace::kSrgbEncoded
                                                       : render::CompareSpace::kLinear;
  mocap::Result<render::CompareResult> cmp = render::Compare(*a, *b, t);
  if (!cmp.ok()) {
    return Error(o.image_a + ": error: " + cmp.error().message + " (" + o.image_b + ")");
  }
  const render::CompareResult& r = *cmp;
  std::printf("Comparing \"%s\" and \"%s\" (%s values)\n", o.image_a.c_str(), o.image_b.c_str(),
              t.space == render::CompareSpace::kSrgbEncoded ? "sRGB-encoded" : "linear");
  std::printf("  Mean error = %.6g\n", r.mean_error);
  std::printf("  RMS error = %.6g\n", r.rms_error);
  if (std::isinf(r.psnr_db)) {
    std::printf("  Peak SNR = inf\n");
  } else {
    std::printf("  Peak SNR = %.6g dB\n", r.psnr_db);
  }
  std::printf("  Max error  = %.6g @ (%d, %d, %s)\n", r.max_error, r.max_x, r.max_y,
              ChannelName(r.max_channel));
  std::printf("  %lld pixels (%.4g%%) over %g (allowed %g%%, hard fail %g)\n",
              static_cast<long long>(r.num_failing), r.failing_percent, t.fail_thresh,
              t.fail_percent, t.hard_fail);

  if (!o.diff_path.empty()) {
    mocap::Result<render::Image> diff = render::MakeDiffImage(*a, *b, o.diff_scale, t.space);
    if (!diff.ok()) return Error(diff.error().ToString());
    if (mocap::Status s = render::WriteImage(*diff, o.diff_path); !s) {
      return Error(s.error().ToString());
    }
    std::printf("  difference image: %s (x%g)\n", o.diff_path.c_str(), o.diff_scale);
  }
  std::printf("%s\n", r.passed ? "PASS" : "FAIL");
  std::fflush(stdout);
  return r.passed ? kComparePass : kCompareFail;
}

}  // namespace app
