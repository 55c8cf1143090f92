#include "render/output/image_file_compare.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include "render/output/image_io.h"

namespace render {
namespace {

using base::ErrorCode;
using base::FileLoc;
using base::MakeError;

// Reads the first subimage of `path` as float, as idiff does (no colour
// conversion, OIIO's default alpha handling).
base::Result<OIIO::ImageBuf> ReadFloat(const std::string& path) {
  const FileLoc loc{path, 0, 0, {}};
  if (!std::filesystem::is_regular_file(path)) {
    return MakeError(ErrorCode::kIo, loc, "no such image file");
  }
  OIIO::ImageBuf buf(path);
  if (!buf.init_spec(path, 0, 0)) {
    return MakeError(ErrorCode::kIo, loc, "cannot read image: " + buf.geterror());
  }
  const OIIO::ImageSpec& spec = buf.spec();
  const std::int64_t samples = std::int64_t{spec.width} * spec.height * spec.depth * spec.nchannels;
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || samples > kMaxReadSamples) {
    return MakeError(ErrorCode::kLimitExceeded, loc,
                     "expected at most " + std::to_string(kMaxReadSamples) +
                         " samples (pixels x channels), found " + std::to_string(spec.width) + "x" +
                         std::to_string(spec.height) + "x" + std::to_string(spec.nchannels));
  }
  if (!buf.read(0, 0, /*force=*/true, OIIO::TypeDesc::FLOAT)) {
    return MakeError(ErrorCode::kIo, loc, "cannot decode image: " + buf.geterror());
  }
  return buf;
}

// `buf`'s values over `roi` (zero where it has no pixel or channel),
// roi.nchannels() per pixel.
std::vector<float> ValuesOver(const OIIO::ImageBuf& buf, const OIIO::ROI& roi) {
  std::vector<float> v(static_cast<std::size_t>(roi.npixels()) *
                           static_cast<std::size_t>(roi.nchannels()),
                       0.0f);
  OIIO::ROI own = roi;
  own.chend = std::min(roi.chend, buf.nchannels());
  // get_pixels leaves the channels beyond `own` alone: fetch into a narrower
  // buffer and spread it out.
  std::vector<float> narrow(static_cast<std::size_t>(roi.npixels()) *
                            static_cast<std::size_t>(own.nchannels()));
  buf.get_pixels(own, OIIO::TypeDesc::FLOAT, narrow.data());
  const auto wide = static_cast<std::size_t>(roi.nchannels());
  const auto n = static_cast<std::size_t>(own.nchannels());
  for (std::size_t p = 0; p < static_cast<std::size_t>(roi.npixels()); ++p) {
    std::copy_n(&narrow[p * n], n, &v[p * wide]);
  }
  return v;
}

std::vector<float> PixelValues(const OIIO::ImageBuf& buf, int x, int y) {
  std::vector<float> v(static_cast<std::size_t>(buf.nchannels()));
  buf.getpixel(x, y, v.data(), static_cast<int>(v.size()));
  return v;
}

CompareVerdict Verdict(const FileCompareResult& r, const IdiffThresholds& t) {
  // At most `allow_failures` failing pixels pass whatever else holds: with the
  // default 0, a comparison without failing pixels never warns (idiff 2.4).
  if (r.num_fail <= t.allow_failures) return CompareVerdict::kPass;
  const auto pixels = static_cast<double>(r.num_pixels);
  if (static_cast<double>(r.num_fail) > t.fail_percent / 100.0 * pixels ||
      r.max_error > t.hard_fail) {
    return CompareVerdict::kFailure;
  }
  if (static_cast<double>(r.num_warn) > t.warn_percent / 100.0 * pixels ||
      r.max_error > t.hard_warn) {
    return CompareVerdict::kWarning;
  }
  return CompareVerdict::kPass;
}

}  // namespace

const char* VerdictName(CompareVerdict v) {
  switch (v) {
    case CompareVerdict::kPass: return "PASS";
    case CompareVerdict::kWarning: return "WARNING";
    case CompareVerdict::kFailure: return "FAILURE";
  }
  return "?";
}

base::Result<FileCompareResult> CompareImageFiles(const std::string& path_a,
                                                  const std::string& path_b,
                                                  const IdiffThresholds& t) {
  base::Result<OIIO::ImageBuf> a = ReadFloat(path_a);
  if (!a.ok()) return a.error();
  base::Result<OIIO::ImageBuf> b = ReadFloat(path_b);
  if (!b.ok()) return b.error();
  const OIIO::ImageSpec& sa = a->spec();
  const OIIO::ImageSpec& sb = b->spec();

  FileCompareResult r;
  r.width_a = sa.width;
  r.height_a = sa.height;
  r.width_b = sb.width;
  r.height_b = sb.height;
  r.same_size = sa.width == sb.width && sa.height == sb.height && sa.x == sb.x && sa.y == sb.y;
  r.channels_a = sa.nchannels;
  r.channels_b = sb.nchannels;
  r.channels = sa.channelnames;
  for (int c = sa.nchannels; c < sb.nchannels; ++c) {
    r.channels.push_back(sb.channelnames[static_cast<std::size_t>(c)]);
  }

  // One thread: the sums then accumulate in one fixed order (same figures on
  // any machine); the default ROI is idiff's, the union of the two windows.
  const OIIO::ImageBufAlgo::CompareResults cr =
      OIIO::ImageBufAlgo::compare(*a, *b, t.fail, t.warn, 0.0f, 0.0f, OIIO::ROI(), 1);
  // OIIO 2.4 also sets `error` whenever a value fails; a real error counts nothing.
  if (cr.error && cr.nfail == 0 && cr.nwarn == 0) {
    return MakeError(ErrorCode::kInternal, FileLoc{path_a, 0, 0, {}},
                     "OpenImageIO compare failed: " + OIIO::geterror());
  }
  const OIIO::ROI roi = OIIO::roi_union(a->roi(), b->roi());
  r.num_pixels = static_cast<std::int64_t>(roi.npixels());
  r.mean_error = cr.meanerror;
  r.rms_error = cr.rms_error;
  r.psnr_db = cr.rms_error > 0.0 ? cr.PSNR : INFINITY;
  r.max_error = cr.maxerror;
  r.max_x = cr.maxx;
  r.max_y = cr.maxy;
  r.max_channel = cr.maxc;
  r.num_warn = static_cast<std::int64_t>(cr.nwarn);
  r.num_fail = static_cast<std::int64_t>(cr.nfail);
  r.values_a = PixelValues(*a, cr.maxx, cr.maxy);
  r.values_b = PixelValues(*b, cr.maxx, cr.maxy);

  // The largest error of each channel (idiff reports only the overall one).
  const std::vector<float> va = ValuesOver(*a, roi);
  const std::vector<float> vb = ValuesOver(*b, roi);
  const auto nc = static_cast<std::size_t>(roi.nchannels());
  r.channel_max_error.assign(nc, 0.0);
  for (std::size_t i = 0; i < va.size(); ++i) {
    double& m = r.channel_max_error[i % nc];
    m = std::max(m, static_cast<double>(std::fabs(va[i] - vb[i])));
  }
  r.verdict = Verdict(r, t);
  return r;
}

}  // namespace render
