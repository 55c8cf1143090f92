#pragma once
// Test-only writer of small glTF files: binary data goes into one buffer
// embedded as a base64 data: URI; the test fills nodes, skins, meshes and
// animations of `doc` by hand. Lets tests build inputs the real files lack
// (STEP, CUBICSPLINE, 8 influences, missing normals).

#include <cstdint>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace testsupport {

inline std::string Base64(const std::vector<unsigned char>& bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::uint32_t b0 = bytes[i];
    const std::uint32_t b1 = i + 1 < bytes.size() ? bytes[i + 1] : 0u;
    const std::uint32_t b2 = i + 2 < bytes.size() ? bytes[i + 2] : 0u;
    const std::uint32_t word = b0 << 16 | b1 << 8 | b2;
    out += kAlphabet[word >> 18 & 63];
    out += kAlphabet[word >> 12 & 63];
    out += i + 1 < bytes.size() ? kAlphabet[word >> 6 & 63] : '=';
    out += i + 2 < bytes.size() ? kAlphabet[word & 63] : '=';
  }
  return out;
}

class GltfWriter {
 public:
  static constexpr int kFloat = 5126;
  static constexpr int kUnsignedShort = 5123;
  static constexpr int kUnsignedByte = 5121;

  GltfWriter() { doc["asset"] = {{"version", "2.0"}}; }

  // Appends `count` elements (tightly packed) as a new bufferView + accessor;
  // returns the accessor index.
  template <typename T>
  int Accessor(const std::vector<T>& values, int component_type, const std::string& type, std::size_t count) {
    while (bytes_.size() % 4 != 0) bytes_.push_back(0);
    const std::size_t offset = bytes_.size();
    const std::size_t size = values.size() * sizeof(T);
    bytes_.resize(offset + size);
    std::memcpy(bytes_.data() + offset, values.data(), size);
    const int view = static_cast<int>(doc["bufferViews"].size());
    doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", size}});
    doc["accessors"].push_back(
        {{"bufferView", view}, {"componentType", component_type}, {"type", type}, {"count", count}});
    return view;
  }

  // Writes the document with its buffer embedded; returns the path.
  std::string Write(const std::string& path) {
    doc["buffers"] = nlohmann::json::array(
        {{{"byteLength", bytes_.size()}, {"uri", "data:application/octet-stream;base64," + Base64(bytes_)}}});
    std::ofstream(path) << doc.dump(1);
    return path;
  }

  nlohmann::json doc;

 private:
  std::vector<unsigned char> bytes_;
};

}  // namespace testsupport
