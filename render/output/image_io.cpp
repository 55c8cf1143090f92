#include "render/output/image_io.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <system_error>
#include <type_traits>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <OpenImageIO/strutil.h>

namespace render {
namespace {

using base::ErrorCode;
using base::FileLoc;
using base::MakeError;

constexpr const char* kSoftware = "patchskin " PATCHSKIN_VERSION;

// Decision thresholds for 8-bit encoding: code c is chosen for linear values in
// [threshold[c-1], threshold[c]), threshold[c] = SrgbToLinear((c + 0.5) / 255) in
// double. A coarse bucket table gives a starting code so that at most a couple of
// comparisons remain; the result is exactly "nearest code in encoded space".
struct Srgb8Tables {
  static constexpr int kBuckets = 4096;
  std::array<float, 255> threshold{};
  std::array<std::uint8_t, kBuckets + 1> bucket_start{};
  std::array<float, 256> to_linear{};
  std::array<float, 256> alpha_to_float{};  // as OpenImageIO reads an 8-bit alpha code

  Srgb8Tables() {
    auto decode = [](double c) {
      return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
    };
    for (int c = 0; c < 255; ++c) {
      threshold[static_cast<std::size_t>(c)] = static_cast<float>(decode((c + 0.5) / 255.0));
    }
    for (int c = 0; c < 256; ++c) {
      to_linear[static_cast<std::size_t>(c)] = static_cast<float>(decode(c / 255.0));
      const auto code = static_cast<std::uint8_t>(c);
      OIIO::convert_pixel_values(OIIO::TypeDesc::UINT8, &code, OIIO::TypeDesc::FLOAT,
                                 &alpha_to_float[static_cast<std::size_t>(c)], 1);
    }
    int code = 0;
    for (int b = 0; b <= kBuckets; ++b) {
      const float x = static_cast<float>(b) / kBuckets;
      while (code < 255 && x >= threshold[static_cast<std::size_t>(code)]) ++code;
      bucket_start[static_cast<std::size_t>(b)] = static_cast<std::uint8_t>(code);
    }
  }
};

const Srgb8Tables& Tables() {
  static const Srgb8Tables tables;  // C++11 guarantees thread-safe initialization
  return tables;
}

std::string Lower(std::string s) {
  for (char& ch : s) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return s;
}

Status CheckImage(const Image& image, const std::string& path) {
  const auto pixels = static_cast<std::size_t>(std::max(image.width, 0)) *
                      static_cast<std::size_t>(std::max(image.height, 0));
  if (image.width <= 0 || image.height <= 0) {
    return base::InvalidArgument(base::InFile(path), "cannot write an empty image (" +
                                                         std::to_string(image.width) + "x" +
                                                         std::to_string(image.height) + ")");
  }
  if (image.rgba.size() != pixels || (!image.depth.empty() && image.depth.size() != pixels)) {
    return base::InvalidArgument(base::InFile(path), "image buffers do not match its size " +
                                                         std::to_string(image.width) + "x" +
                                                         std::to_string(image.height));
  }
  return Status::Ok();
}

Status CheckOptions(const WriteOptions& o, const std::string& path) {
  auto bad = [&](const std::string& what) {
    return Status(base::InvalidArgument(base::InFile(path), what));
  };
  if (o.png_compression < 0 || o.png_compression > 9) {
    return bad("PNG compression must be 0..9, found " + std::to_string(o.png_compression));
  }
  if (o.jpeg_quality < 1 || o.jpeg_quality > 100) {
    return bad("JPEG quality must be 1..100, found " + std::to_string(o.jpeg_quality));
  }
  if (o.tiff_bits != 8 && o.tiff_bits != 16) {
    return bad("TIFF bits must be 8 or 16, found " + std::to_string(o.tiff_bits));
  }
  return Status::Ok();
}

// Interleaved sample buffer in the file's layout plus its OIIO description.
struct Encoded {
  OIIO::ImageSpec spec;
  std::vector<std::uint8_t> bytes;     // 8-bit formats
  std::vector<std::uint16_t> shorts;   // 16-bit TIFF
  std::vector<float> floats;           // EXR (converted to half by the writer)
  const void* data = nullptr;
  OIIO::TypeDesc data_type;
  OIIO::stride_t xstride = OIIO::AutoStride;  // bytes between pixels in data
};

// LinearToSrgb8 with the tables passed in (no static-guard check per call).
inline std::uint8_t ToSrgb8(const Srgb8Tables& t, float linear) {
  if (!(linear > 0.0f)) return 0;  // also NaN
  if (linear >= 1.0f) return 255;
  const auto bucket = static_cast<std::size_t>(linear * Srgb8Tables::kBuckets);
  int code = t.bucket_start[bucket];
  while (code < 255 && linear >= t.threshold[static_cast<std::size_t>(code)]) ++code;
  return static_cast<std::uint8_t>(code);
}

inline std::uint8_t AlphaToByte(float a) {
  if (a == 1.0f) return 255;  // opaque frames: skip the libm call
  const float clamped = std::isnan(a) ? 0.0f : std::clamp(a, 0.0f, 1.0f);
  return static_cast<std::uint8_t>(std::lround(clamped * 255.0f));
}

void EncodeSrgb8(const Image& image, int channels, std::vector<std::uint8_t>* out) {
  out->resize(image.rgba.size() * static_cast<std::size_t>(channels));
  std::uint8_t* dst = out->data();
  const Srgb8Tables& t = Tables();
  // Runs of equal pixels (background rows, flat ground) reuse the previous
  // pixel's bytes. NaN never compares equal, so it is always converted.
  auto encode = [&](auto channel_count) {
    constexpr int kChannels = decltype(channel_count)::value;
    glm::vec4 last(std::numeric_limits<float>::quiet_NaN());
    std::uint8_t bytes[4] = {};
    for (const glm::vec4& p : image.rgba) {
      if (!(p == last)) {
        bytes[0] = ToSrgb8(t, p.r);
        bytes[1] = ToSrgb8(t, p.g);
        bytes[2] = ToSrgb8(t, p.b);
        bytes[3] = AlphaToByte(p.a);
        last = p;
      }
      std::memcpy(dst, bytes, kChannels);  // one store, not one per byte
      dst += kChannels;
    }
  };
  if (channels == 4) {
    encode(std::integral_constant<int, 4>());
  } else {
    encode(std::integral_constant<int, 3>());
  }
}

// The format's compression settings and the metadata every frame file carries.
void SetFileAttributes(ImageFormat format, const WriteOptions& o, OIIO::ImageSpec& spec) {
  if (format == ImageFormat::kPng) {
    spec.attribute("png:compressionLevel", o.png_compression);
    spec.attribute("png:filter", static_cast<int>(o.png_filter));
    spec.attribute("compression", "zip:" + std::to_string(std::max(o.png_compression, 1)));
  } else if (format == ImageFormat::kJpeg) {
    spec.attribute("compression", "jpeg:" + std::to_string(o.jpeg_quality));
    spec.attribute("CompressionQuality", o.jpeg_quality);
  } else if (format == ImageFormat::kTiff) {
    spec.attribute("compression", "zip");
  }
  // Our colour is straight (not premultiplied); without this the PNG and TIFF
  // writers would divide it by alpha once more.
  spec.attribute("oiio:UnassociatedAlpha", 1);
  spec.attribute("Software", kSoftware);
  // The EXR and TIFF writers stamp the current time when DateTime is unset, so
  // the same frame written twice would differ; a fixed stamp keeps output a
  // function of the inputs alone.
  spec.attribute("DateTime", "1970:01:01 00:00:00");
  // A string: PNG text chunks hold only strings, and all formats should agree.
  if (o.frame >= 0) spec.attribute("patchskin:frame", std::to_string(o.frame));
  if (!o.source_file.empty()) spec.attribute("patchskin:source", o.source_file);
  // TIFF keeps only its own tags: the description carries the same facts everywhere.
  std::string description;
  if (o.frame >= 0) description = "frame " + std::to_string(o.frame);
  if (!o.source_file.empty()) {
    description += (description.empty() ? "source " : ", source ") + o.source_file;
  }
  if (!description.empty()) spec.attribute("ImageDescription", description);
}

Encoded Encode(const Image& image, ImageFormat format, const WriteOptions& o) {
  Encoded e;
  const int channels = format == ImageFormat::kJpeg ? 3 : 4;
  switch (format) {
    case ImageFormat::kPng:
    case ImageFormat::kJpeg:
    case ImageFormat::kTiff:
      if (format != ImageFormat::kTiff || o.tiff_bits == 8) {
        e.spec = OIIO::ImageSpec(image.width, image.height, channels, OIIO::TypeDesc::UINT8);
        EncodeSrgb8(image, channels, &e.bytes);
        e.data = e.bytes.data();
        e.data_type = OIIO::TypeDesc::UINT8;
      } else {
        e.spec = OIIO::ImageSpec(image.width, image.height, 4, OIIO::TypeDesc::UINT16);
        e.shorts.reserve(image.rgba.size() * 4);
        for (const glm::vec4& p : image.rgba) {
          for (int c = 0; c < 4; ++c) {
            const float v = std::isnan(p[c]) ? 0.0f : p[c];
            const float enc = c < 3 ? LinearToSrgb(v) : std::clamp(v, 0.0f, 1.0f);
            e.shorts.push_back(static_cast<std::uint16_t>(std::lround(enc * 65535.0f)));
          }
        }
        e.data = e.shorts.data();
        e.data_type = OIIO::TypeDesc::UINT16;
      }
      e.spec.attribute("oiio:ColorSpace", "sRGB");
      break;
    case ImageFormat::kExr: {
      const bool with_z = o.exr_write_depth && !image.depth.empty();
      e.spec = OIIO::ImageSpec(image.width, image.height, with_z ? 5 : 4, OIIO::TypeDesc::HALF);
      e.spec.attribute("oiio:ColorSpace", "Linear");
      e.spec.attribute("compression", o.exr_compression);
      if (with_z) {
        // Depth needs float precision: half has 11 bits of mantissa.
        e.spec.channelnames = {"R", "G", "B", "A", "Z"};
        e.spec.z_channel = 4;
        e.spec.channelformats = {OIIO::TypeDesc::HALF, OIIO::TypeDesc::HALF,
                                 OIIO::TypeDesc::HALF, OIIO::TypeDesc::HALF,
                                 OIIO::TypeDesc::FLOAT};
        e.floats.reserve(image.rgba.size() * 5);
        for (std::size_t i = 0; i < image.rgba.size(); ++i) {
          const glm::vec4& p = image.rgba[i];
          e.floats.insert(e.floats.end(), {p.r, p.g, p.b, p.a, image.depth[i]});
        }
        e.data = e.floats.data();
      } else {
        e.data = image.rgba.data();  // vec4 is 4 tightly packed floats
      }
      e.data_type = OIIO::TypeDesc::FLOAT;
      break;
    }
  }
  SetFileAttributes(format, o, e.spec);
  return e;
}

// The file's samples straight from bytes EncodeSrgb8 made (JPEG skips alpha).
Encoded Encode(const Srgb8Image& image, ImageFormat format, const WriteOptions& o) {
  Encoded e;
  e.spec = OIIO::ImageSpec(image.width, image.height, format == ImageFormat::kJpeg ? 3 : 4,
                           OIIO::TypeDesc::UINT8);
  e.data = image.rgba.data();
  e.data_type = OIIO::TypeDesc::UINT8;
  e.xstride = 4;
  e.spec.attribute("oiio:ColorSpace", "sRGB");
  SetFileAttributes(format, o, e.spec);
  return e;
}

const char* OiioFormatName(ImageFormat format) {
  switch (format) {
    case ImageFormat::kPng: return "png";
    case ImageFormat::kExr: return "openexr";
    case ImageFormat::kTiff: return "tiff";
    case ImageFormat::kJpeg: return "jpeg";
  }
  return "png";
}

Status IoError(const std::string& path, const std::string& what) {
  return MakeError(ErrorCode::kIo, base::InFile(path), what);
}

}  // namespace

std::string TemporaryPathFor(const std::string& final_path, const std::string& suffix) {
  const std::filesystem::path p(final_path);
  std::filesystem::path dir = p.parent_path();
  if (dir.empty()) dir = ".";
  // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on "." + string.
  std::string name(".");
  name += p.filename().string();
  name += ".tmp-";
  name += std::to_string(::getpid());
  name += suffix;
  return (dir / name).string();
}

Result<ImageFormat> ImageFormatFromPath(const std::string& path) {
  const std::string ext = Lower(std::filesystem::path(path).extension().string());
  if (ext == ".png") return ImageFormat::kPng;
  if (ext == ".exr") return ImageFormat::kExr;
  if (ext == ".tif" || ext == ".tiff") return ImageFormat::kTiff;
  if (ext == ".jpg" || ext == ".jpeg") return ImageFormat::kJpeg;
  return MakeError(
      ErrorCode::kUnsupported, base::InFile(path),
      "expected an image extension .png, .exr, .tif, .tiff, .jpg or .jpeg, found '" + ext + "'");
}

float LinearToSrgb(float linear) {
  if (!(linear > 0.0f)) return 0.0f;  // also maps NaN to 0
  if (linear >= 1.0f) return 1.0f;
  return linear <= 0.0031308f ? 12.92f * linear
                              : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

float SrgbToLinear(float encoded) {
  if (!(encoded > 0.0f)) return 0.0f;
  if (encoded >= 1.0f) return 1.0f;
  return encoded <= 0.04045f ? encoded / 12.92f : std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

std::uint8_t LinearToSrgb8(float linear) { return ToSrgb8(Tables(), linear); }

float Srgb8ToLinear(std::uint8_t code) { return Tables().to_linear[code]; }

namespace {

// Writes `encoded` to a temporary file beside `path` and renames it into place.
Status WriteEncoded(const Encoded& encoded, ImageFormat format, const std::string& path) {
  const std::filesystem::path final_path(path);
  const std::filesystem::path temp_path = TemporaryPathFor(path);
  // Created by format name: the temporary name's extension says nothing.
  std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(OiioFormatName(format));
  if (!out) return IoError(path, "OpenImageIO has no writer: " + OIIO::geterror());
  std::error_code ec;
  if (!out->open(temp_path.string(), encoded.spec)) {
    const std::string why = out->geterror();
    std::filesystem::remove(temp_path, ec);
    return IoError(path, "cannot create '" + temp_path.string() + "': " + why);
  }
  const bool written = out->write_image(encoded.data_type, encoded.data, encoded.xstride);
  const bool closed = out->close();
  if (!written || !closed) {
    const std::string why = out->geterror();
    std::filesystem::remove(temp_path, ec);
    return IoError(path, "writing failed: " + why);
  }
  std::filesystem::rename(temp_path, final_path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(temp_path, ignored);
    return IoError(path, "cannot rename the finished temporary file into place: " + ec.message());
  }
  return Status::Ok();
}

}  // namespace

Status WriteImage(const Image& image, const std::string& path, const WriteOptions& options) {
  if (Status s = CheckImage(image, path); !s) return s;
  if (Status s = CheckOptions(options, path); !s) return s;
  Result<ImageFormat> format = ImageFormatFromPath(path);
  if (!format) return format.error();
  return WriteEncoded(Encode(image, *format, options), *format, path);
}

Status WriteImage(const Srgb8Image& image, const std::string& path, const WriteOptions& options) {
  const auto pixels = static_cast<std::size_t>(std::max(image.width, 0)) *
                      static_cast<std::size_t>(std::max(image.height, 0));
  if (image.width <= 0 || image.height <= 0 || image.rgba.size() != 4 * pixels) {
    return base::InvalidArgument(
        base::InFile(path), "expected 4 bytes per pixel of a non-empty " +
                                std::to_string(image.width) + "x" + std::to_string(image.height) +
                                " image, found " + std::to_string(image.rgba.size()) + " bytes");
  }
  if (Status s = CheckOptions(options, path); !s) return s;
  Result<ImageFormat> format = ImageFormatFromPath(path);
  if (!format) return format.error();
  if (*format == ImageFormat::kExr || (*format == ImageFormat::kTiff && options.tiff_bits != 8)) {
    return base::InvalidArgument(base::InFile(path),
                                 "an 8-bit frame cannot be written as EXR or 16-bit TIFF: "
                                 "those store the linear values");
  }
  return WriteEncoded(Encode(image, *format, options), *format, path);
}

void EncodeSrgb8(const Image& image, Srgb8Image* out) {
  out->width = image.width;
  out->height = image.height;
  EncodeSrgb8(image, 4, &out->rgba);
}

Image DecodeSrgb8(const Srgb8Image& image) {
  const Srgb8Tables& t = Tables();
  Image out(image.width, image.height);
  const std::uint8_t* p = image.rgba.data();
  for (glm::vec4& q : out.rgba) {
    q = {t.to_linear[p[0]], t.to_linear[p[1]], t.to_linear[p[2]], t.alpha_to_float[p[3]]};
    p += 4;
  }
  return out;
}

Result<Image> ReadImage(const std::string& path, ReadInfo* info) {
  const FileLoc loc = base::InFile(path);
  if (!std::filesystem::is_regular_file(path)) {
    return MakeError(ErrorCode::kIo, loc, "no such image file");
  }
  // Keep straight alpha as stored (OIIO would premultiply PNG/TIFF colour by it).
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(path, &config);
  if (!in) return MakeError(ErrorCode::kIo, loc, "cannot read image: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.nchannels <= 0 || spec.nchannels > 64) {
    return MakeError(ErrorCode::kUnsupported, loc,
                     "expected 1..64 channels, found " + std::to_string(spec.nchannels));
  }
  if (spec.depth > 1) return MakeError(ErrorCode::kUnsupported, loc, "volume images are not read");
  const std::int64_t pixels = std::int64_t{spec.width} * spec.height;
  if (spec.width <= 0 || spec.height <= 0 || pixels * spec.nchannels > kMaxReadSamples) {
    return MakeError(ErrorCode::kLimitExceeded, loc,
                     "expected at most " + std::to_string(kMaxReadSamples) +
                         " samples (pixels x channels), found " + std::to_string(spec.width) +
                         "x" + std::to_string(spec.height) + "x" +
                         std::to_string(spec.nchannels));
  }
  const bool integer = spec.format.basetype != OIIO::TypeDesc::FLOAT &&
                       spec.format.basetype != OIIO::TypeDesc::HALF &&
                       spec.format.basetype != OIIO::TypeDesc::DOUBLE;
  const bool srgb = integer && !OIIO::Strutil::iequals(
                                   spec.get_string_attribute("oiio:ColorSpace"), "Linear");
  const auto n = static_cast<std::size_t>(spec.nchannels);
  std::vector<float> samples(static_cast<std::size_t>(pixels) * n);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, samples.data())) {
    return MakeError(ErrorCode::kIo, loc, "cannot decode image: " + in->geterror());
  }

  // Which file channels feed R, G, B, A and depth.
  const int z = spec.z_channel >= 0 ? spec.z_channel : -1;
  std::vector<int> colour;
  for (int c = 0; c < spec.nchannels && colour.size() < 4; ++c) {
    if (c != z) colour.push_back(c);
  }
  const int alpha = spec.alpha_channel >= 0 && spec.alpha_channel != z
                        ? spec.alpha_channel
                        : (colour.size() == 2 || colour.size() == 4 ? colour.back() : -1);
  std::vector<int> rgb;
  for (int c : colour) {
    if (c != alpha) rgb.push_back(c);
  }
  if (rgb.empty()) return MakeError(ErrorCode::kUnsupported, loc, "no colour channel found");
  const float code_max = spec.format.basetype == OIIO::TypeDesc::UINT8 ? 255.0f : 0.0f;

  Image image(spec.width, spec.height);
  if (z >= 0) image.depth.resize(static_cast<std::size_t>(pixels));
  for (std::size_t i = 0; i < static_cast<std::size_t>(pixels); ++i) {
    const float* s = &samples[i * n];
    glm::vec4 p(0.0f, 0.0f, 0.0f, 1.0f);
    for (int c = 0; c < 3; ++c) {
      // Grey files repeat their one colour channel.
      float v = s[rgb[std::min<std::size_t>(static_cast<std::size_t>(c), rgb.size() - 1)]];
      if (srgb) {
        v = code_max > 0.0f ? Srgb8ToLinear(static_cast<std::uint8_t>(std::lround(
                                  std::clamp(v, 0.0f, 1.0f) * code_max)))
                            : SrgbToLinear(v);
      }
      p[c] = v;
    }
    if (alpha >= 0) p.a = s[alpha];
    image.rgba[i] = p;
    if (z >= 0) image.depth[i] = s[z];
  }
  if (info != nullptr) {
    info->srgb_encoded = srgb;
    info->bits = static_cast<int>(spec.format.size()) * 8;
    info->channels = spec.nchannels;
    info->format_name = in->format_name();
  }
  return image;
}

namespace {

// One placeholder found in a pattern: [begin, end) and its zero-pad width.
struct Placeholder {
  std::size_t begin = 0;
  std::size_t end = 0;
  int width = 0;
};

std::vector<Placeholder> FindPlaceholders(const std::string& p) {
  std::vector<Placeholder> found;
  for (std::size_t i = 0; i < p.size();) {
    if (p[i] == '#') {
      std::size_t j = i;
      while (j < p.size() && p[j] == '#') ++j;
      found.push_back({i, j, static_cast<int>(j - i)});
      i = j;
    } else if (p[i] == '%') {
      std::size_t j = i + 1;
      int width = 0;
      bool zero = false;
      if (j < p.size() && p[j] == '0') {
        zero = true;
        ++j;
      }
      while (j < p.size() && std::isdigit(static_cast<unsigned char>(p[j])) && width < 100) {
        width = width * 10 + (p[j] - '0');
        ++j;
      }
      if (j < p.size() && p[j] == 'd' && (zero || width == 0)) {
        found.push_back({i, j + 1, width});
        i = j + 1;
      } else {
        ++i;
      }
    } else {
      ++i;
    }
  }
  return found;
}

}  // namespace

bool HasFramePlaceholder(const std::string& pattern) {
  return FindPlaceholders(pattern).size() == 1;
}

Result<std::string> ExpandFramePattern(const std::string& pattern, int frame) {
  const std::vector<Placeholder> found = FindPlaceholders(pattern);
  if (found.size() != 1) {
    return base::InvalidArgument(
        base::InFile(pattern),
        "expected exactly one frame placeholder ('####' or '%04d') in the output "
        "pattern, found " +
            std::to_string(found.size()));
  }
  char digits[128];
  std::snprintf(digits, sizeof(digits), "%0*d", found[0].width, frame);
  return pattern.substr(0, found[0].begin) + digits + pattern.substr(found[0].end);
}

}  // namespace render
