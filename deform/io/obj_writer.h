#pragma once
// Wavefront OBJ output of deformed meshes, one file per frame.
//
// Each file holds, in this order: comment lines ("# ..."), "mtllib FILE" (when
// a material library is named), one object "o NAME", #V "v x y z" lines, #V
// "vn x y z" lines (when normals are given), #V "vt u v" lines (when uvs are
// given; OBJ's v runs up the image, so it is 1 - the glTF v) and #T
// "f a/a/a b/b/b c/c/c" lines (1-based indices, counter-clockwise seen from
// outside; "f a//a ..." without uvs, "f a/a ..." without normals, "f a b c"
// with neither), with "usemtl NAME" before the faces of each material run. Every frame of a sequence has the same
// vertex order and the same faces, so tools can treat the files as one
// animated mesh. Floats are written with the shortest decimal text that reads
// back to the same float (std::to_chars), so parsing a file gives the written
// positions bit for bit. Writes are atomic (deform/io/file_output.h).

#include <cstdint>
#include <span>
#include <string>

#include <glm/glm.hpp>

#include "base/error.h"

namespace deform {

// The geometry of one frame. positions and normals are #V (normals may be
// empty), triangles #T with indices < #V.
struct ObjFrame {
  std::span<const glm::vec3> positions{}; // #V, any space (the exporter writes world space)
  std::span<const glm::vec3> normals{};   // #V unit normals, or empty
  std::span<const glm::uvec3> triangles{}; // #T
  std::string comment{};                  // written as "# " lines (newlines split lines); may be empty
  std::string object_name = "mesh";       // the "o" line; no whitespace
  std::span<const glm::vec2> uvs{};       // #V glTF-convention uvs (v down the image), or empty
  std::string material_library{};         // the "mtllib" file, or empty; no whitespace
  std::span<const std::string> material_names{};   // names for "usemtl"; no whitespace
  std::span<const std::int32_t> triangle_material{};  // #T index into material_names (-1:
                                                      // none), or empty: no usemtl lines
};

// An OBJ material library (.mtl) for the materials of an exported mesh: per
// material "newmtl NAME", "Kd r g b" (the base colour factor, linear) and, for
// a textured one, "map_Kd FILE". `texture_files[k]` is material k's texture
// file name relative to the .mtl (empty: none). Writes atomically.
base::Status WriteObjMaterials(const std::string& path, std::span<const std::string> names,
                               std::span<const glm::vec3> diffuse,
                               std::span<const std::string> texture_files);

// Appends the OBJ text of `frame` to `out` (out is not cleared). Errors:
// kInvalidArgument when sizes disagree, an index is out of range or a value
// is not finite (nothing is appended then).
base::Status AppendObj(const ObjFrame& frame, std::string& out);

// Writes frames to files one at a time, reusing one text buffer: memory held
// is one frame's text, whatever the number of frames.
class ObjSequenceWriter {
 public:
  // Formats `frame` and writes it atomically to `path` (the folder must exist).
  base::Status Write(const ObjFrame& frame, const std::string& path);
  // Bytes of the reused text buffer (its capacity): one frame's worth.
  std::size_t buffer_bytes() const { return buffer_.capacity(); }

 private:
  std::string buffer_;
};

}  // namespace deform
