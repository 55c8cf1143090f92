#pragma once
// The input checks deform's jobs and builders share: finiteness of points and
// the error a bad argument gets (kInvalidArgument, no file position unless one
// is given). One definition each, so the layer's files can be compiled together.

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

inline base::Error InvalidArgument(base::FileLoc loc, std::string message) {
  return base::MakeError(base::ErrorCode::kInvalidArgument, std::move(loc), std::move(message));
}

inline base::Error InvalidArgument(std::string message) {
  return InvalidArgument(base::FileLoc{}, std::move(message));
}

}  // namespace deform::internal
