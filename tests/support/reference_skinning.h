#pragma once
// Test-only linear blend skinning in double precision, written independently
// of the deform jobs, to check imported data:
//   v' = sum_i w_i * model_from_joint[skin_joints[j_i]] * joint_from_bind[j_i] * v

#include <glm/glm.hpp>
#include <span>
#include <vector>

#include "deform/mesh.h"

namespace testsupport {

inline std::vector<glm::dvec3> ReferenceSkin(const deform::SkinnedMesh& mesh,
                                             std::span<const glm::mat4> model_from_joint) {
  const int n = mesh.weights.influences;
  std::vector<glm::dvec3> out(mesh.bind.positions.size());
  for (std::size_t v = 0; v < out.size(); ++v) {
    const glm::dvec4 rest(glm::dvec3(mesh.bind.positions[v]), 1.0);
    glm::dvec4 sum(0.0);
    for (int k = 0; k < n; ++k) {
      const std::size_t slot = v * static_cast<std::size_t>(n) + static_cast<std::size_t>(k);
      const double w = mesh.weights.weights[slot];
      if (w == 0.0) continue;
      const std::size_t s = mesh.weights.joints[slot];
      const glm::dmat4 skin = glm::dmat4(model_from_joint[static_cast<std::size_t>(mesh.skin_joints[s])]) *
                              glm::dmat4(mesh.joint_from_bind[s]);
      sum += w * (skin * rest);
    }
    out[v] = glm::dvec3(sum);
  }
  return out;
}

}  // namespace testsupport
