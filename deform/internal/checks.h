#pragma once
// The input checks deform's jobs and builders share: finiteness of points and
// the error a bad argument gets (base::InvalidArgument). One definition each,
// so the layer's files can be compiled together.

#include <cmath>
#include <span>
#include <string>
#include <utility>

#include <glm/glm.hpp>

#include "base/error.h"

namespace deform::internal {

inline bool Finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

inline bool Finite(const glm::dvec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

inline bool AllFinite(std::span<const glm::vec3> points) {
  for (const glm::vec3& p : points) {
    if (!Finite(p)) return false;
  }
  return true;
}

using base::InvalidArgument;

}  // namespace deform::internal
