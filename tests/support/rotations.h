#pragma once
// Distances between rotations for tests.

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace testsupport {

// Euclidean distance between unit quaternions a and b as rotations: b's sign
// is taken nearer a (q and -q are one rotation).
inline float QuatDistance(const glm::quat& a, const glm::quat& b) {
  const glm::quat s = glm::dot(a, b) < 0.0f ? -b : b;
  return glm::length(glm::vec4(a.x - s.x, a.y - s.y, a.z - s.z, a.w - s.w));
}

}  // namespace testsupport
