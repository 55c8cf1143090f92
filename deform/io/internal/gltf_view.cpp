#include "deform/io/internal/gltf_view.h"

#include <tiny_gltf.h>

#include <algorithm>

namespace deform::internal {
namespace {

using base::ErrorCode;
using base::Result;

// The byte range [offset, offset + (count-1)*stride + element) of a buffer
// view, checked against the view and the view against its buffer. `at` names
// the object holding the offset (an accessor or its sparse part).
Result<AccessorView> CheckedRange(const tinygltf::Model& m, const std::string& path, int buffer_view,
                                  std::size_t offset, std::size_t count, int components,
                                  int component_type, const std::string& at) {
  if (buffer_view < 0 || buffer_view >= static_cast<int>(m.bufferViews.size())) {
    return GltfError(path, ErrorCode::kNotFound, at + ".bufferView",
                     "buffer view " + std::to_string(buffer_view) + " out of range");
  }
  const tinygltf::BufferView& bv = m.bufferViews[static_cast<std::size_t>(buffer_view)];
  const std::string bv_at = Indexed("bufferViews", buffer_view);
  if (bv.buffer < 0 || bv.buffer >= static_cast<int>(m.buffers.size())) {
    return GltfError(path, ErrorCode::kNotFound, bv_at + ".buffer",
                     "buffer " + std::to_string(bv.buffer) + " out of range");
  }
  const std::vector<unsigned char>& buffer = m.buffers[static_cast<std::size_t>(bv.buffer)].data;
  if (bv.byteOffset > buffer.size() || bv.byteLength > buffer.size() - bv.byteOffset) {
    return GltfError(path, ErrorCode::kCountMismatch, bv_at + ".byteLength",
                     "view of " + std::to_string(bv.byteLength) + " bytes at offset " +
                         std::to_string(bv.byteOffset) + " runs past the " +
                         std::to_string(buffer.size()) + " bytes of its buffer");
  }
  const std::size_t element = static_cast<std::size_t>(components * ComponentBytes(component_type));
  const std::size_t stride = bv.byteStride == 0 ? element : bv.byteStride;
  if (stride < element || stride > 252) {
    return GltfError(
        path, ErrorCode::kCountMismatch, bv_at + ".byteStride",
        "stride " + std::to_string(stride) + " must be in " + std::to_string(element) + "..252");
  }
  const std::size_t available = bv.byteLength;
  const bool fits = offset <= available &&
                    (count == 0 || (count - 1 <= available / stride &&
                                    (count - 1) * stride + element <= available - offset));
  if (!fits) {
    return GltfError(path, ErrorCode::kCountMismatch, at + ".count",
                     std::to_string(count) + " elements of " + std::to_string(element) +
                         " bytes at offset " + std::to_string(offset) + " do not fit in the " +
                         std::to_string(available) + " bytes of " + bv_at);
  }
  AccessorView v;
  v.data = buffer.data() + bv.byteOffset + offset;
  v.stride = stride;
  v.count = count;
  v.components = components;
  v.component_type = component_type;
  return v;
}

// Index, type and component type of accessors[index].
Result<const tinygltf::Accessor*> CheckedAccessor(const tinygltf::Model& m, const std::string& path,
                                                  int index, const std::string& user, int type,
                                                  std::initializer_list<int> component_types) {
  if (index < 0 || index >= static_cast<int>(m.accessors.size())) {
    return GltfError(path, ErrorCode::kNotFound, user,
                     "accessor index " + std::to_string(index) + " out of range (" +
                         std::to_string(m.accessors.size()) + " accessors)");
  }
  const tinygltf::Accessor& a = m.accessors[static_cast<std::size_t>(index)];
  const std::string at = Indexed("accessors", index);
  if (a.type != type) {
    return GltfError(path, ErrorCode::kUnsupported, at + ".type",
                     std::string("expected ") + GltfTypeName(type) + " for " + user + ", found " +
                         GltfTypeName(a.type));
  }
  if (std::find(component_types.begin(), component_types.end(), a.componentType) ==
      component_types.end()) {
    return GltfError(
        path, ErrorCode::kUnsupported, at + ".componentType",
        "component type " + std::to_string(a.componentType) + " not allowed for " + user);
  }
  return &a;
}

}  // namespace

base::Error GltfError(const std::string& path, base::ErrorCode code, std::string field,
                      std::string message) {
  return base::MakeError(code, {path, 0, 0, std::move(field)}, std::move(message));
}

std::string Indexed(const char* array, int i) { return std::string(array) + "[" + std::to_string(i) + "]"; }

const char* GltfTypeName(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return "SCALAR";
    case TINYGLTF_TYPE_VEC2:
      return "VEC2";
    case TINYGLTF_TYPE_VEC3:
      return "VEC3";
    case TINYGLTF_TYPE_VEC4:
      return "VEC4";
    case TINYGLTF_TYPE_MAT4:
      return "MAT4";
    default:
      return "other";
  }
}

Result<AccessorView> CheckedView(const tinygltf::Model& m, const std::string& path, int index,
                                 const std::string& user, int type,
                                 std::initializer_list<int> component_types) {
  auto accessor = CheckedAccessor(m, path, index, user, type, component_types);
  if (!accessor.ok()) return std::move(accessor).error();
  const tinygltf::Accessor& a = **accessor;
  const std::string at = Indexed("accessors", index);
  if (a.sparse.isSparse) {
    return GltfError(path, ErrorCode::kUnsupported, at + ".sparse",
                     "sparse accessors are not supported for " + user);
  }
  const int components = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(a.type));
  auto v = CheckedRange(m, path, a.bufferView, a.byteOffset, a.count, components, a.componentType, at);
  if (v.ok()) v->index = index;
  return v;
}

Result<std::vector<float>> ReadFloatsAllowingSparse(const tinygltf::Model& m, const std::string& path,
                                                    int index, const std::string& user, int type,
                                                    std::initializer_list<int> component_types,
                                                    bool normalize) {
  auto accessor = CheckedAccessor(m, path, index, user, type, component_types);
  if (!accessor.ok()) return std::move(accessor).error();
  const tinygltf::Accessor& a = **accessor;
  const std::string at = Indexed("accessors", index);
  const int components = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(a.type));
  const auto width = static_cast<std::size_t>(components);
  std::vector<float> out;
  if (a.bufferView >= 0) {
    auto v = CheckedRange(m, path, a.bufferView, a.byteOffset, a.count, components, a.componentType, at);
    if (!v.ok()) return std::move(v).error();
    v->index = index;
    auto dense = ReadFloats(*v, normalize, path);
    if (!dense.ok()) return std::move(dense).error();
    out = std::move(dense).value();
  } else {
    out.assign(a.count * width, 0.0f);  // no buffer view: zeros
  }
  if (!a.sparse.isSparse) return out;

  const std::string sat = at + ".sparse";
  if (a.sparse.count < 1 || static_cast<std::size_t>(a.sparse.count) > a.count) {
    return GltfError(path, ErrorCode::kCountMismatch, sat + ".count",
                     "expected 1.." + std::to_string(a.count) + " replaced elements, found " +
                         std::to_string(a.sparse.count));
  }
  const auto n = static_cast<std::size_t>(a.sparse.count);
  const int index_type = a.sparse.indices.componentType;
  if (index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
      index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
      index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
    return GltfError(
        path, ErrorCode::kUnsupported, sat + ".indices.componentType",
        "expected an unsigned byte, short or int type, found " + std::to_string(index_type));
  }
  if (a.sparse.indices.byteOffset < 0 || a.sparse.values.byteOffset < 0) {
    return GltfError(path, ErrorCode::kCountMismatch, sat, "negative byteOffset");
  }
  auto iv = CheckedRange(m, path, a.sparse.indices.bufferView,
                         static_cast<std::size_t>(a.sparse.indices.byteOffset), n, 1, index_type,
                         sat + ".indices");
  if (!iv.ok()) return std::move(iv).error();
  iv->index = index;
  auto indices = ReadUints(*iv, a.count, "index", path);
  if (!indices.ok()) return std::move(indices).error();
  for (std::size_t k = 1; k < n; ++k) {
    if ((*indices)[k] <= (*indices)[k - 1]) {
      return GltfError(path, ErrorCode::kBadNumber, sat + ".indices",
                       "indices must increase strictly; element " + std::to_string(k) + " is " +
                           std::to_string((*indices)[k]) + " after " +
                           std::to_string((*indices)[k - 1]));
    }
  }
  auto vv = CheckedRange(m, path, a.sparse.values.bufferView,
                         static_cast<std::size_t>(a.sparse.values.byteOffset), n, components,
                         a.componentType, sat + ".values");
  if (!vv.ok()) return std::move(vv).error();
  vv->index = index;
  auto values = ReadFloats(*vv, normalize, path);
  if (!values.ok()) return std::move(values).error();
  for (std::size_t k = 0; k < n; ++k) {
    std::copy_n(values->begin() + static_cast<std::ptrdiff_t>(k * width), width,
                out.begin() + static_cast<std::ptrdiff_t>((*indices)[k] * width));
  }
  return out;
}

}  // namespace deform::internal
