#include "render/output/image_compare.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include "render/output/image_io.h"

namespace render {
namespace {

using base::ErrorCode;
using base::FileLoc;
using base::MakeError;

base::Error SizeError(const Image& a, const Image& b) {
  return base::InvalidArgument(FileLoc{}, "images differ in size: " + std::to_string(a.width) +
                                              "x" + std::to_string(a.height) + " and " +
                                              std::to_string(b.width) + "x" +
                                              std::to_string(b.height));
}

bool Consistent(const Image& img) {
  return img.width > 0 && img.height > 0 &&
         img.rgba.size() ==
             static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.height);
}

base::Status CheckPair(const Image& a, const Image& b) {
  if (!Consistent(a) || !Consistent(b)) {
    return base::InvalidArgument(FileLoc{}, "cannot compare an empty or inconsistent image");
  }
  if (a.width != b.width || a.height != b.height) return SizeError(a, b);
  return base::Status::Ok();
}

// The values compared, interleaved RGBA floats.
std::vector<float> Values(const Image& img, CompareSpace space) {
  std::vector<float> v(img.rgba.size() * 4);
  for (std::size_t i = 0; i < img.rgba.size(); ++i) {
    const glm::vec4& p = img.rgba[i];
    for (int c = 0; c < 4; ++c) {
      const bool encode = space == CompareSpace::kSrgbEncoded && c < 3;
      v[i * 4 + static_cast<std::size_t>(c)] = encode ? LinearToSrgb(p[c]) : p[c];
    }
  }
  return v;
}

}  // namespace

Result<CompareResult> Compare(const Image& a, const Image& b,
                              const CompareThresholds& thresholds) {
  if (base::Status s = CheckPair(a, b); !s) return s.error();
  std::vector<float> va = Values(a, thresholds.space);
  std::vector<float> vb = Values(b, thresholds.space);
  const OIIO::ImageSpec spec(a.width, a.height, 4, OIIO::TypeDesc::FLOAT);
  const OIIO::ImageBuf buf_a(spec, va.data());  // wraps our memory, no copy
  const OIIO::ImageBuf buf_b(spec, vb.data());
  // Warnings are not used: the warn threshold equals the fail threshold.
  // nthreads=1: the sums are then accumulated in one fixed order.
  const OIIO::ImageBufAlgo::CompareResults cr = OIIO::ImageBufAlgo::compare(
      buf_a, buf_b, thresholds.fail_thresh, thresholds.fail_thresh, OIIO::ROI(), 1);
  // OIIO 2.4 also sets `error` whenever some value fails; a real error has none.
  if (cr.error && cr.nfail == 0 && cr.nwarn == 0) {
    return MakeError(ErrorCode::kInternal, FileLoc{},
                     "OpenImageIO compare failed: " + OIIO::geterror());
  }
  CompareResult r;
  r.max_error = cr.maxerror;
  r.max_x = cr.maxx;
  r.max_y = cr.maxy;
  r.max_channel = cr.maxc;
  r.mean_error = cr.meanerror;
  r.rms_error = cr.rms_error;
  r.psnr_db = cr.rms_error > 0.0 ? cr.PSNR : INFINITY;
  r.num_pixels = std::int64_t{a.width} * a.height;
  r.num_failing = static_cast<std::int64_t>(cr.nfail);
  r.failing_percent = 100.0 * static_cast<double>(r.num_failing) / static_cast<double>(r.num_pixels);
  // The float percentage (0.02f is 0.0199999996) must not turn "2 of 10000
  // allowed" into 1.99999: counts within rounding of the limit are allowed.
  const double allowed = static_cast<double>(thresholds.fail_percent) / 100.0 *
                         static_cast<double>(r.num_pixels) * (1.0 + 1e-6);
  r.passed = !(static_cast<double>(r.num_failing) > allowed || r.max_error > thresholds.hard_fail);
  return r;
}

Result<Image> MakeDiffImage(const Image& a, const Image& b, float scale, CompareSpace space) {
  if (base::Status s = CheckPair(a, b); !s) return s.error();
  const std::vector<float> va = Values(a, space);
  const std::vector<float> vb = Values(b, space);
  Image diff(a.width, a.height, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  for (std::size_t i = 0; i < diff.rgba.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      const std::size_t k = i * 4 + static_cast<std::size_t>(c);
      diff.rgba[i][c] = std::min(1.0f, scale * std::fabs(va[k] - vb[k]));
    }
  }
  return diff;
}

}  // namespace render
