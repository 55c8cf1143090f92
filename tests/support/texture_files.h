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

#include <unistd.h>

#include <OpenImageIO/imageio.h>

namespace testsupport {

// The linear value of 8-bit sRGB code `code`, in double, written out
// independently of the importer's decoding.
inline double SrgbCodeToLinear(int code) {
  const double c = code / 255.0;
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

// `codes`: width x height x channels 8-bit values, row 0 first (the top).
// The file is written under a name of this process's and renamed into place:
// test processes running in parallel share the folder, and one must never
// read another's half-written image.
inline std::vector<unsigned char> EncodeImage(const std::filesystem::path& path, int width, int height,
                                              int channels, const std::vector<std::uint8_t>& codes) {
  std::filesystem::path scratch = path;
  scratch += "." + std::to_string(::getpid()) + path.extension().string();
  auto out = OIIO::ImageOutput::create(scratch.string());
  if (!out) return {};
  OIIO::ImageSpec spec(width, height, channels, OIIO::TypeDesc::UINT8);
  if (path.extension() == ".jpg") spec.attribute("Compression", "jpeg:100");
  if (!out->open(scratch.string(), spec) || !out->write_image(OIIO::TypeDesc::UINT8, codes.data()) ||
      !out->close()) {
    return {};
  }
  std::vector<unsigned char> bytes;
  {
    std::ifstream in(scratch, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  std::error_code ec;
  std::filesystem::rename(scratch, path, ec);
  return bytes;
}

}  // namespace testsupport
