#include "app/compare_command.h"

#include <charconv>
#include <cmath>
#include <cstdio>

#include "render/output/image_compare.h"
#include "render/output/image_file_compare.h"
#include "render/output/image_io.h"

namespace app {
namespace {

// idiff's option names that take the double-dash form here.
constexpr const char* kIdiffNames[] = {"fail",     "failpercent", "hardfail",      "warn",
                                       "warnpercent", "hardwarn", "allowfailures", "scale"};

int Error(const std::string& formatted) {
  std::fprintf(stderr, "%s\n", formatted.c_str());
  return kCompareError;
}

// The shortest text that reads back as `v` (as idiff prints pixel values).
std::string Shortest(float v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof(buf), v);
  return ec == std::errc() ? std::string(buf, end) : "?";
}

std::string JoinValues(const std::vector<float>& values) {
  std::string s;
  for (float v : values) s += (s.empty() ? "" : ", ") + Shortest(v);
  return s;
}

void PrintReport(const CompareCommandOptions& o, const render::FileCompareResult& r) {
  const auto percent = [&r](std::int64_t n) {
    return r.num_pixels > 0 ? 100.0 * static_cast<double>(n) / static_cast<double>(r.num_pixels)
                            : 0.0;
  };
  std::printf("  Mean error = %g\n", r.mean_error);
  std::printf("  RMS error = %g\n", r.rms_error);
  std::printf("  Peak SNR = %g\n", r.psnr_db);
  if (r.max_error > 0.0) {
    std::printf("  Max error  = %g @ (%d, %d, %s)  values are %s vs %s\n", r.max_error, r.max_x,
                r.max_y, r.channels[static_cast<std::size_t>(r.max_channel)].c_str(),
                JoinValues(r.values_a).c_str(), JoinValues(r.values_b).c_str());
  } else {
    std::printf("  Max error  = 0\n");
  }
  std::printf("  %lld pixels (%.3g%%) over %g\n", static_cast<long long>(r.num_warn),
              percent(r.num_warn), static_cast<double>(o.warn));
  std::printf("  %lld pixels (%.3g%%) over %g\n", static_cast<long long>(r.num_fail),
              percent(r.num_fail), static_cast<double>(o.fail));
  std::printf("  Max error per channel:");
  for (std::size_t c = 0; c < r.channels.size(); ++c) {
    std::printf(" %s %g", r.channels[c].c_str(), r.channel_max_error[c]);
  }
  std::printf("\n");
  if (!r.same_size) {
    std::printf("  Sizes differ: %dx%d and %dx%d (compared over both; a missing pixel counts as 0)\n",
                r.width_a, r.height_a, r.width_b, r.height_b);
  }
  if (r.channels_a != r.channels_b) {
    std::printf("  Channels differ: %d and %d (a missing channel counts as 0)\n", r.channels_a,
                r.channels_b);
  }
}

// Writes |A - B| amplified, for people to look at (colour only).
int WriteDiff(const CompareCommandOptions& o) {
  render::ReadInfo info_a, info_b;
  base::Result<render::Image> a = render::ReadImage(o.image_a, &info_a);
  if (!a.ok()) return Error(a.error().ToString());
  base::Result<render::Image> b = render::ReadImage(o.image_b, &info_b);
  if (!b.ok()) return Error(b.error().ToString());
  const render::CompareSpace space = info_a.srgb_encoded || info_b.srgb_encoded
                                         ? render::CompareSpace::kSrgbEncoded
                                         : render::CompareSpace::kLinear;
  base::Result<render::Image> diff = render::MakeDiffImage(*a, *b, o.diff_scale, space);
  if (!diff.ok()) {
    std::printf("  no difference image: %s\n", diff.error().message.c_str());
    return kComparePass;
  }
  if (base::Status s = render::WriteImage(*diff, o.diff_path); !s)
    return Error(s.error().ToString());
  std::printf("  difference image: %s (x%g)\n", o.diff_path.c_str(), static_cast<double>(o.diff_scale));
  return kComparePass;
}

}  // namespace

void NormalizeIdiffSpelling(std::vector<std::string>& args) {
  bool in_compare = false;
  for (std::string& a : args) {
    if (!in_compare) {
      in_compare = a == "compare";
      continue;
    }
    if (a.size() < 3 || a[0] != '-' || a[1] == '-') continue;
    for (const char* name : kIdiffNames) {
      if (a.compare(1, std::string::npos, name) == 0) {
        a = "-" + a;
        break;
      }
    }
  }
}

int RunCompareCommand(const CompareCommandOptions& o) {
  const render::IdiffThresholds t{.fail = o.fail,
                                  .fail_percent = o.fail_percent,
                                  .hard_fail = o.hard_fail,
                                  .warn = o.warn,
                                  .warn_percent = o.warn_percent,
                                  .hard_warn = o.hard_warn,
                                  .allow_failures = o.allow_failures};
  std::printf("Comparing \"%s\" and \"%s\"\n", o.image_a.c_str(), o.image_b.c_str());
  std::fflush(stdout);
  base::Result<render::FileCompareResult> r = render::CompareImageFiles(o.image_a, o.image_b, t);
  if (!r.ok()) return Error(r.error().ToString());
  PrintReport(o, *r);
  if (!o.diff_path.empty()) {
    if (const int code = WriteDiff(o); code != kComparePass) return code;
  }
  std::printf("%s\n", render::VerdictName(r->verdict));
  std::fflush(stdout);
  return static_cast<int>(r->verdict);
}

}  // namespace app
