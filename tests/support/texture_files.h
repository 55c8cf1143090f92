#pragma once
// Test-only image encoding for texture tests: 8-bit PNG or JPEG bytes of a
// small image, written with OpenImageIO through a file in the test's folder.

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>

namespace testsupport {

// The linear value of 8-bit sRGB code `code`, in double, written out
// independently of the importer's decoding.
inline double SrgbCodeToLinear(int code) {
  const double c = code / 255.0;
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

// `codes`: width x height x channels 8-bit values, row 0 first (the top).
inline std::vector<unsigned char> EncodeImage(const std::filesystem::path& path, int width, int height,
                                              int channels, const std::vector<std::uint8_t>& codes) {
  auto out = OIIO::ImageOutput::create(path.string());
  if (!out) return {};
  OIIO::ImageSpec spec(width, height, channels, OIIO::TypeDesc::UINT8);
  if (path.extension() == ".jpg") spec.attribute("Compression", "jpeg:100");
  if (!out->open(path.string(), spec) || !out->write_image(OIIO::TypeDesc::UINT8, codes.data()) ||
      !out->close()) {
    return {};
  }
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace testsupport
