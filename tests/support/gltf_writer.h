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
  // returns the bufferView's index, which is also the accessor's as long as
  // no BufferView() call came first (tests add raw views last).
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

  // Appends raw bytes (e.g. an encoded image) as a new bufferView without an
  // accessor; returns its index. Call it after the last Accessor().
  int BufferView(const std::vector<unsigned char>& bytes) {
    while (bytes_.size() % 4 != 0) bytes_.push_back(0);
    const std::size_t offset = bytes_.size();
    bytes_.insert(bytes_.end(), bytes.begin(), bytes.end());
    doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes.size()}});
    return static_cast<int>(doc["bufferViews"].size()) - 1;
  }

  // Writes a .glb: the JSON chunk, then the buffer as the BIN chunk (glTF 2.0, "GLB").
  std::string WriteGlb(const std::string& path) {
    while (bytes_.size() % 4 != 0) bytes_.push_back(0);
    doc["buffers"] = nlohmann::json::array({{{"byteLength", bytes_.size()}}});
    std::string json = doc.dump();
    while (json.size() % 4 != 0) json += ' ';
    std::vector<unsigned char> out;
    auto u32 = [&out](std::uint32_t v) {
      for (int i = 0; i < 4; ++i) out.push_back(static_cast<unsigned char>(v >> (8 * i)));
    };
    out.insert(out.end(), {'g', 'l', 'T', 'F'});
    u32(2);
    u32(static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + bytes_.size()));
    u32(static_cast<std::uint32_t>(json.size()));
    u32(0x4E4F534Au);  // "JSON"
    out.insert(out.end(), json.begin(), json.end());
    u32(static_cast<std::uint32_t>(bytes_.size()));
    u32(0x004E4942u);  // "BIN"
    out.insert(out.end(), bytes_.begin(), bytes_.end());
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(out.data()),
                                                static_cast<std::streamsize>(out.size()));
    return path;
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
