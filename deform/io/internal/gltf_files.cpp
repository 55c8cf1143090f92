#include "deform/io/internal/gltf_files.h"

#include <cctype>
#include <cstdint>
#include <fstream>
#include <nlohmann/json.hpp>

namespace deform::internal {

namespace fs = std::filesystem;
using base::ErrorCode;
using base::Result;

Result<std::vector<unsigned char>> ReadFileBounded(const std::string& path, std::size_t max_bytes) {
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  if (ec)
    return base::MakeError(ErrorCode::kIo, base::FileLoc{path, 0, 0, {}},
                           "cannot open file: " + ec.message());
  if (size > max_bytes) {
    return base::MakeError(ErrorCode::kLimitExceeded, base::FileLoc{path, 0, 0, {}},
                           "file has " + std::to_string(size) + " bytes, more than the limit of " +
                               std::to_string(max_bytes));
  }
  std::ifstream in(path, std::ios::binary);
  if (!in)
    return base::MakeError(ErrorCode::kIo, base::FileLoc{path, 0, 0, {}}, "cannot open file");
  std::vector<unsigned char> bytes(static_cast<std::size_t>(size));
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size));
  if (static_cast<std::uintmax_t>(in.gcount()) != size) {
    return base::MakeError(ErrorCode::kIo, base::FileLoc{path, 0, 0, {}}, "short read");
  }
  return bytes;
}

static std::string PercentDecode(const std::string& uri) {
  std::string out;
  for (std::size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(static_cast<unsigned char>(uri[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(uri[i + 2]))) {
      out += static_cast<char>(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

// Why a URI may not be read, or empty when it is a relative path that stays in
// the folder (symlinks are checked again when the file is opened).
std::string UriProblem(const std::string& raw_uri) {
  if (raw_uri.rfind("data:", 0) == 0) return {};
  const std::string uri = PercentDecode(raw_uri);
  if (uri.find("://") != std::string::npos) return "is a URL; only files in the model's folder are read";
  if (uri.empty()) return "is empty";
  if (uri[0] == '/' || uri[0] == '\\' || (uri.size() > 1 && uri[1] == ':')) {
    return "is an absolute path; only files in the model's folder are read";
  }
  std::size_t start = 0;
  while (start <= uri.size()) {
    std::size_t end = uri.find_first_of("/\\", start);
    if (end == std::string::npos) end = uri.size();
    if (uri.compare(start, end - start, "..") == 0) {
      return "leaves the model's folder ('..'); only files inside it are read";
    }
    start = end + 1;
  }
  return {};
}

// True when `path` (after resolving symlinks) lies inside `folder`.
bool InsideFolder(const fs::path& folder, const std::string& path) {
  std::error_code ec;
  const fs::path root = fs::weakly_canonical(folder, ec);
  if (ec) return false;
  const fs::path target = fs::weakly_canonical(fs::path(path), ec);
  if (ec) return false;
  const fs::path rel = target.lexically_relative(root);
  return !rel.empty() && *rel.begin() != ".." && !rel.is_absolute();
}

static std::uint32_t ReadU32(const unsigned char* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}

// Checks the GLB container before tinygltf sees it and returns its JSON chunk.
Result<std::string> GlbJson(const std::string& path, const std::vector<unsigned char>& bytes) {
  auto fail = [&](const char* field, std::string message) {
    return base::MakeError(ErrorCode::kCountMismatch, {path, 0, 0, field}, std::move(message));
  };
  if (bytes.size() < 20) {
    return fail("glb header", "expected at least 20 bytes (header and JSON chunk header), found " +
                                  std::to_string(bytes.size()));
  }
  const std::uint32_t version = ReadU32(bytes.data() + 4);
  const std::uint32_t length = ReadU32(bytes.data() + 8);
  if (version != 2) {
    return base::MakeError(ErrorCode::kUnsupported, {path, 0, 0, "glb header.version"},
                           "expected GLB version 2, found " + std::to_string(version));
  }
  if (length != bytes.size()) {
    return fail("glb header.length", "header declares " + std::to_string(length) + " bytes, file has " +
                                         std::to_string(bytes.size()) +
                                         (length > bytes.size() ? " (truncated file)" : ""));
  }
  const std::uint32_t json_length = ReadU32(bytes.data() + 12);
  if (ReadU32(bytes.data() + 16) != 0x4E4F534Au) {
    return base::MakeError(ErrorCode::kSyntax, {path, 0, 0, "glb chunks[0].type"},
                           "expected the JSON chunk first");
  }
  if (json_length > bytes.size() - 20) {
    return fail("glb chunks[0].length",
                "JSON chunk of " + std::to_string(json_length) + " bytes runs past the end of the file");
  }
  std::size_t next = 20 + static_cast<std::size_t>(json_length);
  if (next < bytes.size()) {
    if (bytes.size() - next < 8) return fail("glb chunks[1]", "truncated chunk header");
    const std::uint32_t bin_length = ReadU32(bytes.data() + next);
    if (bin_length > bytes.size() - next - 8) {
      return fail("glb chunks[1].length",
                  "BIN chunk of " + std::to_string(bin_length) + " bytes runs past the end of the file");
    }
  }
  return std::string(reinterpret_cast<const char*>(bytes.data()) + 20, json_length);
}

// Rejects buffer and image URIs that leave the folder, naming the JSON field.
base::Status CheckUris(const std::string& path, const std::string& json_text) {
  const nlohmann::json doc = nlohmann::json::parse(json_text, nullptr, false);
  if (doc.is_discarded() || !doc.is_object()) return base::Status::Ok();  // tinygltf reports it
  for (const char* array : {"buffers", "images"}) {
    const auto it = doc.find(array);
    if (it == doc.end() || !it->is_array()) continue;
    for (std::size_t i = 0; i < it->size(); ++i) {
      const auto& item = (*it)[i];
      if (!item.is_object() || !item.contains("uri") || !item["uri"].is_string()) continue;
      const std::string uri = item["uri"].get<std::string>();
      const std::string problem = UriProblem(uri);
      if (!problem.empty()) {
        return base::MakeError(ErrorCode::kUnsupported,
                               {path, 0, 0, std::string(array) + "[" + std::to_string(i) + "].uri"},
                               "URI '" + uri.substr(0, 200) + "' " + problem);
      }
    }
  }
  return base::Status::Ok();
}

}  // namespace deform::internal
