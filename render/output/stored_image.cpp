#include "render/output/stored_image.h"

#include <cstdint>
#include <vector>

#include <OpenImageIO/imageio.h>

namespace render {

Result<Image> AsStored(const Image& image, ImageFormat format, const WriteOptions& options) {
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
      Srgb8Image bytes;
      EncodeSrgb8(image, &bytes);
      return DecodeSrgb8(bytes);
    }
    case ImageFormat::kExr: {
      const std::size_t n = image.rgba.size();
      Image out(image.width, image.height);
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
