#include "deform/io/obj_writer.h"

#include <charconv>
#include <cmath>

#include "deform/io/file_output.h"
#include "deform/internal/checks.h"

namespace deform {
namespace {

base::Error ObjError(const std::string& what) {
  return base::InvalidArgument({"obj", 0, 0, {}}, what);
}

using internal::AllFinite;

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

bool HasSpace(const std::string& s) {
  return s.find_first_of(" \t\n\r") != std::string::npos;
}

}  // namespace

base::Status AppendObj(const ObjFrame& frame, std::string& out) {
  const std::size_t nv = frame.positions.size();
  if (!frame.normals.empty() && frame.normals.size() != nv) {
    return ObjError("normals must be empty or one per vertex: " + std::to_string(nv) +
                    " positions, " + std::to_string(frame.normals.size()) + " normals");
  }
  if (!AllFinite(frame.positions) || !AllFinite(frame.normals)) {
    return ObjError("positions and normals must be finite");
  }
  for (std::size_t t = 0; t < frame.triangles.size(); ++t) {
    const glm::uvec3& tri = frame.triangles[t];
    if (tri.x >= nv || tri.y >= nv || tri.z >= nv) {
      return ObjError("triangle " + std::to_string(t) + " has a vertex index outside 0.." +
                      std::to_string(nv) + "-1");
    }
  }
  if (HasSpace(frame.object_name))
    return ObjError("object name '" + frame.object_name + "' holds whitespace");
  if (HasSpace(frame.material_library)) {
    return ObjError("material library '" + frame.material_library + "' holds whitespace");
  }
  for (const std::string& name : frame.material_names) {
    if (name.empty() || HasSpace(name))
      return ObjError("material name '" + name + "' is empty or holds whitespace");
  }
  if (!frame.uvs.empty() && frame.uvs.size() != nv) {
    return ObjError("uvs must be empty or one per vertex: " + std::to_string(nv) + " positions, " +
                    std::to_string(frame.uvs.size()) + " uvs");
  }
  for (const glm::vec2& uv : frame.uvs) {
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return ObjError("uvs must be finite");
  }
  if (!frame.triangle_material.empty()) {
    if (frame.triangle_material.size() != frame.triangles.size()) {
      return ObjError("triangle_material must be empty or one per triangle");
    }
    for (const std::int32_t k : frame.triangle_material) {
      if (k < -1 || k >= static_cast<std::int32_t>(frame.material_names.size())) {
        return ObjError("triangle material " + std::to_string(k) + " has no name");
      }
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
  if (!frame.material_library.empty()) out += "mtllib " + frame.material_library + "\n";
  out += "o ";
  out += frame.object_name.empty() ? std::string("mesh") : frame.object_name;
  out += '\n';
  AppendVectors("v", frame.positions, out);
  AppendVectors("vn", frame.normals, out);
  for (const glm::vec2& uv : frame.uvs) {
    out += "vt ";
    AppendFloat(uv.x, out);
    out += ' ';
    AppendFloat(1.0f - uv.y, out);
    out += '\n';
  }
  const bool with_normals = !frame.normals.empty();
  const bool with_uvs = !frame.uvs.empty();
  std::int32_t material = -2;  // the current usemtl run
  for (std::size_t t = 0; t < frame.triangles.size(); ++t) {
    const glm::uvec3& tri = frame.triangles[t];
    if (!frame.triangle_material.empty() && frame.triangle_material[t] != material) {
      material = frame.triangle_material[t];
      // "usemtl" with no name is not OBJ; -1 (no material) falls back to the default one.
      out += material >= 0 ? "usemtl " + frame.material_names[static_cast<std::size_t>(material)] + "\n"
                           : std::string("usemtl default\n");
    }
    out += 'f';
    for (int c = 0; c < 3; ++c) {
      const std::uint64_t index = std::uint64_t{tri[c]} + 1;
      out += ' ';
      AppendUint(index, out);
      if (with_uvs) {
        out += '/';
        AppendUint(index, out);
      }
      if (with_normals) {
        out += with_uvs ? "/" : "//";
        AppendUint(index, out);
      }
    }
    out += '\n';
  }
  return base::Status::Ok();
}

base::Status ObjSequenceWriter::Write(const ObjFrame& frame, const std::string& path) {
  buffer_.clear();  // keeps the capacity: one frame's text is reused for the next
  if (base::Status s = AppendObj(frame, buffer_); !s) {
    base::Error e = s.error();
    e.loc.file = path;
    return e;
  }
  return WriteFileAtomic(path, buffer_);
}

base::Status WriteObjMaterials(const std::string& path, std::span<const std::string> names,
                               std::span<const glm::vec3> diffuse,
                               std::span<const std::string> texture_files) {
  if (diffuse.size() != names.size() || texture_files.size() != names.size()) {
    return base::InvalidArgument(
        {path, 0, 0, {}}, "expected a colour and a texture file (or none) per material name");
  }
  std::string out = "# patchskin materials: Kd is the linear base colour factor\n";
  for (std::size_t k = 0; k < names.size(); ++k) {
    if (names[k].empty() || HasSpace(names[k]) || HasSpace(texture_files[k])) {
      return base::InvalidArgument(
          {path, 0, 0, {}}, "material '" + names[k] + "': names and files must be non-empty words");
    }
    out += "newmtl " + names[k] + "\nKd";
    for (int c = 0; c < 3; ++c) {
      out += ' ';
      AppendFloat(diffuse[k][c], out);
    }
    out += '\n';
    if (!texture_files[k].empty()) out += "map_Kd " + texture_files[k] + "\n";
  }
  return WriteFileAtomic(path, out);
}

}  // namespace deform
