#pragma once
// File-level helpers of the glTF import that do not need tinygltf: bounded
// file reads, the URI confinement rules, and the GLB container check.

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "base/error.h"

namespace deform::internal {

// The whole file, refusing files larger than max_bytes (kIo, kLimitExceeded).
base::Result<std::vector<unsigned char>> ReadFileBounded(const std::string& path,
                                                         std::size_t max_bytes);

// Why a buffer/image URI may not be read ("is an absolute path; ..."), or empty
// when it is a data: URI or a relative path without ".." segments (after
// percent-decoding). Symlinks are checked separately by InsideFolder.
std::string UriProblem(const std::string& raw_uri);

// True when `path`, with symlinks resolved, lies inside `folder`.
bool InsideFolder(const std::filesystem::path& folder, const std::string& path);

// Checks a GLB container (header, version 2, declared length == file size,
// chunk lengths within the file) and returns its JSON chunk. Errors name the
// part, e.g. field "glb header.length".
base::Result<std::string> GlbJson(const std::string& path, const std::vector<unsigned char>& bytes);

// Rejects buffers[i].uri / images[i].uri that UriProblem refuses, naming the
// field. Unparsable JSON is left for tinygltf to report.
base::Status CheckUris(const std::string& path, const std::string& json_text);

}  // namespace deform::internal
