#include "render/output/stored_image.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include <OpenImageIO/imageio.h>

namespace render {
namespace {

// OpenImageIO's own conversions, so the values match what read_image gives.
float Uint8ToFloat(std::uint8_t code) {
  float out = 0.0f;
  OIIO::convert_pixel_values(OIIO::TypeDesc::UINT8, &code, OIIO::TypeDesc::FLOAT, &out, 1);
  return out;
}

}  // namespace

Result<Image> AsStored(const Image& image, ImageFormat format, const WriteOptions& options) {
  const auto n = image.rgba.size();
  Image out(image.width, image.height);
  switch (format) {
    case ImageFormat::kJpeg:
      return base::MakeError(base::ErrorCode::kUnsupported, {},
                             "JPEG is lossy: a frame read back differs from the one written");
    case ImageFormat::kTiff:
      if (options.tiff_bits != 8) {
        return base::MakeError(base::ErrorCode::kUnsupported, {},
                               "16-bit TIFF round trip is not modelled");
      }
      [[fallthrough]];
    case ImageFormat::kPng: {
      std::array<float, 256> alpha{};
      for (int c = 0; c < 256; ++c) {
        alpha[static_cast<std::size_t>(c)] = Uint8ToFloat(static_cast<std::uint8_t>(c));
      }
      for (std::size_t i = 0; i < n; ++i) {
        const glm::vec4& p = image.rgba[i];
        // The encoder's alpha code (image_io.cpp EncodeSrgb8).
        const float a = std::isnan(p.a) ? 0.0f : std::clamp(p.a, 0.0f, 1.0f);
        out.rgba[i] = {Srgb8ToLinear(LinearToSrgb8(p.r)), Srgb8ToLinear(LinearToSrgb8(p.g)),
                       Srgb8ToLinear(LinearToSrgb8(p.b)),
                       alpha[static_cast<std::size_t>(std::lround(a * 255.0f))]};
      }
      return out;
    }
    case ImageFormat::kExr: {
      std::vector<std::uint16_t> half(4 * n);
      OIIO::convert_pixel_values(OIIO::TypeDesc::FLOAT, image.rgba.data(), OIIO::TypeDesc::HALF,
                                 half.data(), static_cast<int>(4 * n));
      OIIO::convert_pixel_values(OIIO::TypeDesc::HALF, half.data(), OIIO::TypeDesc::FLOAT,
                                 out.rgba.data(), static_cast<int>(4 * n));
      if (options.exr_write_depth) out.depth = image.depth;
      return out;
    }
  }
  return base::MakeError(base::ErrorCode::kUnsupported, {}, "unknown image format");
}

}  // namespace render
