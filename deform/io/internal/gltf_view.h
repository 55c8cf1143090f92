#pragma once
// Checked access to the accessors of a parsed glTF document: the only way the
// import reads vertex, index, matrix and key data. tinygltf only partly
// validates, so every index, bound, type and count is checked here before a
// byte is read. The tinygltf types stay forward-declared: only the import's
// .cpp files include tiny_gltf.h.

#include <cstddef>
#include <initializer_list>
#include <string>
#include <vector>

#include "deform/io/internal/gltf_accessor.h"
#include "base/error.h"

namespace tinygltf {
class Model;
}

namespace deform::internal {

// The error of a glTF reader: `message` about `field` of the file at `path`.
base::Error GltfError(const std::string& path, base::ErrorCode code, std::string field,
                      std::string message);

// "accessors[3]"-style field names.
std::string Indexed(const char* array, int index);

// "SCALAR", "VEC3", ... for TINYGLTF_TYPE_* values ("other" for the rest).
const char* GltfTypeName(int type);

// The dense view of accessors[index] after checking that the index exists,
// that the type is `type` and the component type one of `component_types`,
// that it has a buffer view whose range lies in its buffer, and that `count`
// elements at the accessor's offset and stride lie in that view. `user` names
// the field that refers to the accessor (for messages), `path` the file.
// Sparse accessors and accessors without a buffer view are refused
// (kUnsupported, kNotFound): use ReadFloatsAllowingSparse where the
// specification allows them.
base::Result<AccessorView> CheckedView(const tinygltf::Model& model, const std::string& path,
                                       int index, const std::string& user, int type,
                                       std::initializer_list<int> component_types);

// All components of accessors[index] as floats (integer types normalized when
// `normalize`), with the two forms glTF allows for morph-target data:
//  * no buffer view: the base values are zeros (glTF 2.0, "Accessors");
//  * `sparse`: `sparse.count` (1..count) indices (unsigned byte/short/int,
//    strictly increasing, each < count) and as many values of the accessor's
//    type replace elements of the base.
// Same checks as CheckedView for every view involved; values must be finite.
// The caller bounds count * components before calling (no buffer view means
// the file's size does not bound the allocation).
base::Result<std::vector<float>> ReadFloatsAllowingSparse(
    const tinygltf::Model& model, const std::string& path, int index, const std::string& user,
    int type, std::initializer_list<int> component_types, bool normalize);

}  // namespace deform::internal
