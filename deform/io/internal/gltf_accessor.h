#pragma once
// Decoding of glTF accessor elements once the accessor has been checked to lie
// inside its buffer (gltf_import.cpp builds the AccessorView). Component types
// are the glTF 2.0 numbers (5120 BYTE .. 5126 FLOAT).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "base/error.h"

namespace deform::internal {

// A checked view of an accessor: every element lies inside its buffer.
struct AccessorView {
  int index = -1;                       // accessors[index], for error messages
  const unsigned char* data = nullptr;  // first element
  std::size_t stride = 0;               // bytes between elements
  std::size_t count = 0;                // elements
  int components = 0;                   // 1 (SCALAR) .. 16 (MAT4)
  int component_type = 0;               // 5120 .. 5126
};

// Bytes of one component of a glTF component type, 0 for an unknown type.
int ComponentBytes(int component_type);

// All components as floats; integer types are normalized to [0,1] / [-1,1]
// when `normalize` (glTF's normalized-integer rule). NaN/inf give kNonFinite
// naming "accessors[i]" of file `path`.
base::Result<std::vector<float>> ReadFloats(const AccessorView& view, bool normalize,
                                            const std::string& path);

// All components as unsigned integers, each below `limit` (else
// kCountMismatch: "<what> 5 at element 3 past the 2 joints of the skin").
// `what` is "joint index" or "index".
base::Result<std::vector<std::uint32_t>> ReadUints(const AccessorView& view, std::uint64_t limit,
                                                   const std::string& what,
                                                   const std::string& path);

}  // namespace deform::internal
