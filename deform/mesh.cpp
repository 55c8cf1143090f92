#include "deform/mesh.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace deform {

base::Status Mesh::Check() const {
  using base::ErrorCode;
  const std::size_t n = positions.size();
  if (!normals.empty() && normals.size() != n) {
    return base::MakeError(ErrorCode::kCountMismatch, {},
                           "mesh has " + std::to_string(n) + " positions but " +
                               std::to_string(normals.size()) + " normals");
  }
  if (!colors.empty() && colors.size() != n) {
    return base::MakeError(ErrorCode::kCountMismatch, {},
                           "mesh has " + std::to_string(n) + " positions but " +
                               std::to_string(colors.size()) + " colors");
  }
  if (!uvs.empty() && uvs.size() != n) {
    return base::MakeError(ErrorCode::kCountMismatch, {},
                           "mesh has " + std::to_string(n) + " positions but " +
                               std::to_string(uvs.size()) + " texture coordinates");
  }
  for (const glm::vec2& uv : uvs) {
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) {
      return base::MakeError(ErrorCode::kNonFinite, {}, "mesh has a non-finite texture coordinate");
    }
  }
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const glm::uvec3& tri = triangles[t];
    if (tri.x >= n || tri.y >= n || tri.z >= n) {
      return base::MakeError(
          ErrorCode::kCountMismatch, {},
          "triangle " + std::to_string(t) + " indexes past the " + std::to_string(n) + " vertices");
    }
  }
  for (const glm::vec3& p : positions) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      return base::MakeError(ErrorCode::kNonFinite, {}, "mesh has a non-finite position");
    }
  }
  return base::Status::Ok();
}

void ComputeVertexNormals(std::span<const glm::vec3> positions,
                          std::span<const glm::uvec3> triangles, std::span<glm::vec3> normals) {
  for (glm::vec3& n : normals) n = glm::vec3(0.0f);
  for (const glm::uvec3& t : triangles) {
    const glm::vec3 a = positions[t.x];
    const glm::vec3 b = positions[t.y];
    const glm::vec3 c = positions[t.z];
    const glm::vec3 area_normal = glm::cross(b - a, c - a);  // length = 2 x area
    normals[t.x] += area_normal;
    normals[t.y] += area_normal;
    normals[t.z] += area_normal;
  }
  for (glm::vec3& n : normals) {
    const float len = glm::length(n);
    n = len > 0.0f ? n / len : glm::vec3(0.0f, 0.0f, 1.0f);
  }
}

bool IsClosedOutward(std::span<const glm::vec3> positions, std::span<const glm::uvec3> triangles) {
  if (triangles.empty()) return false;
  // Directed edges as sorted keys: each must occur once, and its reverse once.
  std::vector<std::uint64_t> edges;
  edges.reserve(3 * triangles.size());
  for (const glm::uvec3& t : triangles) {
    if (t.x >= positions.size() || t.y >= positions.size() || t.z >= positions.size()) return false;
    for (int k = 0; k < 3; ++k)
      edges.push_back(static_cast<std::uint64_t>(t[k]) << 32 | t[(k + 1) % 3]);
  }
  std::sort(edges.begin(), edges.end());
  if (std::adjacent_find(edges.begin(), edges.end()) != edges.end()) return false;
  for (const std::uint64_t e : edges) {
    const std::uint64_t reverse = (e << 32) | (e >> 32);
    if (!std::binary_search(edges.begin(), edges.end(), reverse)) return false;
  }
  // Consistent winding could still face inwards: the enclosed volume says which.
  double volume = 0.0;
  for (const glm::uvec3& t : triangles) {
    const glm::dvec3 a(positions[t.x]), b(positions[t.y]), c(positions[t.z]);
    volume += glm::dot(a, glm::cross(b, c));
  }
  return volume > 0.0;
}

Bounds ComputeBounds(std::span<const glm::vec3> points) {
  Bounds b;
  for (const glm::vec3& p : points) b.Extend(p);
  return b;
}

}  // namespace deform
