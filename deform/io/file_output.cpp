#include "deform/io/file_output.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <system_error>

namespace deform {
namespace {

base::Error IoError(const std::string& path, const std::string& why) {
  return base::MakeError(base::ErrorCode::kIo, {path, 0, 0, {}}, why);
}

}  // namespace

std::string TemporaryOutputPath(const std::string& final_path) {
  const std::filesystem::path p(final_path);
  std::filesystem::path dir = p.parent_path();
  if (dir.empty()) dir = ".";
  std::string name(".");
  name += p.filename().string();
  name += ".tmp-";
  name += std::to_string(::getpid());
  return (dir / name).string();
}

base::Status WriteFileAtomic(const std::string& path, std::string_view bytes) {
  const std::string temp = TemporaryOutputPath(path);
  std::FILE* f = std::fopen(temp.c_str(), "wb");
  if (f == nullptr) {
    return IoError(path, "cannot create '" + temp + "': " +
                             std::error_code(errno, std::generic_category()).message());
  }
  const std::size_t written = std::fwrite(bytes.data(), 1, bytes.size(), f);
  const int write_errno = errno;
  const bool closed = std::fclose(f) == 0;
  std::error_code ec;
  if (written != bytes.size() || !closed) {
    std::filesystem::remove(temp, ec);
    return IoError(path, "writing failed: " +
                             std::error_code(write_errno, std::generic_category()).message());
  }
  std::filesystem::rename(temp, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(temp, ignored);
    return IoError(path, "cannot rename the finished temporary file into place: " + ec.message());
  }
  return base::Status::Ok();
}

}  // namespace deform
