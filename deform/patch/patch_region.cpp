#include "deform/patch/patch_region.h"
#include "deform/internal/checks.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace deform {
namespace {

using internal::InvalidArgument;

}  // namespace

base::Result<std::vector<int>> SelectJointRegion(const SkinnedMesh& mesh,
                                                 const JointRegionQuery& query) {
  if (query.bone_joints.empty()) return InvalidArgument("joint region: no bone joints given");
  if (!(query.radius > 0.0f) || !std::isfinite(query.radius)) {
    return InvalidArgument("joint region: radius must be positive and finite, found " +
                           std::to_string(query.radius));
  }
  if (!(query.min_bone_weight > 0.0f && query.min_bone_weight <= 1.0f)) {
    return InvalidArgument("joint region: min bone weight must be in (0, 1]");
  }
  if (!(query.half_angle_deg > 0.0f && query.half_angle_deg <= 180.0f)) {
    return InvalidArgument("joint region: half angle must be in (0, 180] degrees");
  }
  const Mesh& bind = mesh.bind;
  const int nv = bind.num_vertices();
  const int k = mesh.weights.influences;
  if (k < 1 || mesh.weights.num_vertices() != nv ||
      mesh.weights.joints.size() != mesh.weights.weights.size()) {
    return InvalidArgument("joint region: skin weights do not match the mesh");
  }
  // Which skin joints are the region's bones.
  std::vector<char> is_bone(mesh.skin_joints.size(), 0);
  for (std::size_t s = 0; s < mesh.skin_joints.size(); ++s) {
    is_bone[s] = std::find(query.bone_joints.begin(), query.bone_joints.end(),
                           mesh.skin_joints[s]) != query.bone_joints.end();
  }
  std::vector<glm::vec3> normals = bind.normals;
  if (query.half_angle_deg < 180.0f && normals.size() != bind.positions.size()) {
    normals.resize(bind.positions.size());
    ComputeVertexNormals(bind.positions, bind.triangles, normals);
  }
  const float side_len = glm::length(query.side);
  const bool use_side = query.half_angle_deg < 180.0f && side_len > 0.0f;
  const glm::vec3 side = use_side ? query.side / side_len : glm::vec3(0.0f);
  const float min_cos = std::cos(glm::radians(query.half_angle_deg));
  const float r2 = query.radius * query.radius;
  std::vector<int> region;
  for (int v = 0; v < nv; ++v) {
    const auto vi = static_cast<std::size_t>(v);
    const glm::vec3 offset = bind.positions[vi] - query.centre;
    if (glm::dot(offset, offset) > r2) continue;
    float w = 0.0f;
    for (int i = 0; i < k; ++i) {
      const std::size_t slot = vi * static_cast<std::size_t>(k) + static_cast<std::size_t>(i);
      const std::uint16_t s = mesh.weights.joints[slot];
      if (s < is_bone.size() && is_bone[s]) w += mesh.weights.weights[slot];
    }
    if (w < query.min_bone_weight) continue;
    if (use_side && glm::dot(normals[vi], side) < min_cos) continue;
    region.push_back(v);
  }
  if (region.empty()) {
    return base::MakeError(base::ErrorCode::kNotFound, {},
                           "joint region: no vertex within radius " + std::to_string(query.radius) +
                               " is weighted to the joint's bones");
  }
  return region;
}

base::Result<std::vector<int>> CheckVertexRegion(std::span<const int> vertices, int num_vertices) {
  if (vertices.empty()) return InvalidArgument("vertex region: the list is empty");
  std::vector<char> seen(static_cast<std::size_t>(std::max(0, num_vertices)), 0);
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const int v = vertices[i];
    if (v < 0 || v >= num_vertices) {
      return InvalidArgument("vertex region: vertex " + std::to_string(i) + " (index " +
                             std::to_string(v) + ") is outside the " +
                             std::to_string(num_vertices) + " vertices");
    }
    if (seen[static_cast<std::size_t>(v)]) {
      return InvalidArgument("vertex region: vertex " + std::to_string(i) + " (index " +
                             std::to_string(v) + ") appears twice");
    }
    seen[static_cast<std::size_t>(v)] = 1;
  }
  std::vector<int> sorted(vertices.begin(), vertices.end());
  std::sort(sorted.begin(), sorted.end());
  return sorted;
}

}  // namespace deform
