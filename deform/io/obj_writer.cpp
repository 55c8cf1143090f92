#include "deform/io/obj_writer.h"

#include <charconv>
#include <cmath>

#include "deform/io/file_output.h"

namespace deform {
namespace {

mocap::Error Invalid(const std::string& what) {
  return mocap::MakeError(mocap::ErrorCode::kInvalidArgument, {"obj", 0, 0, {}}, what);
}

bool AllFinite(std::span<const glm::vec3> v) {
  for (const glm::vec3& p : v) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return false;
  }
  return true;
}

void AppendFloat(float value, std::string& out) {
  char buf[32];
  const std::to_chars_result r = std::to_chars(buf, buf + sizeof(buf), value);
  out.append(buf, r.ptr);
}

void AppendUint(std::uint64_t value, std::string& out) {
  char buf[24];
  const std::to_chars_result r = std::to_chars(buf, buf + sizeof(buf), value);
  out.append(buf, r.ptr);
}

void AppendVectors(const char* tag, std::span<const glm::vec3> v, std::string& out) {
  for (const glm::vec3& p : v) {
    out += tag;
    for (int c = 0; c < 3; ++c) {
      out += ' ';
      AppendFloat(p[c], out);
    }
    out += '\n';
  }
}

}  // namespace

mocap::Status AppendObj(const ObjFrame& frame, std::string& out) {
  const std::size_t nv = frame.positions.size();
  if (!frame.normals.empty() && frame.normals.size() != nv) {
    return Invalid("normals must be empty or one per vertex: " + std::to_string(nv) +
                   " positions, " + std::to_string(frame.normals.size()) + " normals");
  }
  if (!AllFinite(frame.positions) || !AllFinite(frame.normals)) {
    return Invalid("positions and normals must be finite");
  }
  for (std::size_t t = 0; t < frame.triangles.size(); ++t) {
    const glm::uvec3& tri = frame.triangles[t];
    if (tri.x >= nv || tri.y >= nv || tri.z >= nv) {
      return Invalid("triangle " + std::to_string(t) + " has a vertex index outside 0.." +
                     std::to_string(nv) + "-1");
    }
  }
  for (char c : frame.object_name) {
    if (c == ' ' || c == '\t' || c == '\n' || c == '\r') {
      return Invalid("object name '" + frame.object_name + "' holds whitespace");
    }
  }

  if (!frame.comment.empty()) {
    std::size_t begin = 0;
    while (begin <= frame.comment.size()) {
      std::size_t end = frame.comment.find('\n', begin);
      if (end == std::string::npos) end = frame.comment.size();
      out += "# ";
      out.append(frame.comment, begin, end - begin);
      out += '\n';
      begin = end + 1;
    }
  }
  out += "o ";
  out += frame.object_name.empty() ? std::string("mesh") : frame.object_name;
  out += '\n';
  AppendVectors("v", frame.positions, out);
  AppendVectors("vn", frame.normals, out);
  const bool with_normals = !frame.normals.empty();
  for (const glm::uvec3& tri : frame.triangles) {
    out += 'f';
    for (int c = 0; c < 3; ++c) {
      out += ' ';
      AppendUint(std::uint64_t{tri[c]} + 1, out);
      if (with_normals) {
        out += "//";
        AppendUint(std::uint64_t{tri[c]} + 1, out);
      }
    }
    out += '\n';
  }
  return mocap::Status::Ok();
}

mocap::Status ObjSequenceWriter::Write(const ObjFrame& frame, const std::string& path) {
  buffer_.clear();  // keeps the capacity: one frame's text is reused for the next
  if (mocap::Status s = AppendObj(frame, buffer_); !s) {
    mocap::Error e = s.error();
    e.loc.file = path;
    return e;
  }
  return WriteFileAtomic(path, buffer_);
}

}  // namespace deform
