#include "deform/global/dqs_job.h"

#include <cmath>

#include "deform/mesh.h"

namespace deform {
namespace {

using base::JobStatus;

inline glm::vec3 Rotate(const glm::quat& q, const glm::vec3& v) {
  const glm::vec3 u(q.x, q.y, q.z);
  return v + 2.0f * glm::cross(u, glm::cross(u, v) + q.w * v);  // q v q* for unit q
}

inline float Dot(const glm::quat& a, const glm::quat& b) {
  return a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z;
}

}  // namespace

JobStatus BuildDualQuatPalette(std::span<const glm::mat4> model_from_bind,
                               std::span<DualQuat> palette) {
  if (model_from_bind.size() != palette.size()) {
    return {JobStatus::kSizeMismatch, "palette must have as many entries as model_from_bind"};
  }
  for (std::size_t i = 0; i < palette.size(); ++i) {
    const glm::mat4& m = model_from_bind[i];
    glm::mat3 r(m);
    for (int c = 0; c < 3; ++c) {
      const float len = glm::length(r[c]);
      if (len > 0.0f) r[c] /= len;
    }
    const glm::quat real = glm::normalize(glm::quat_cast(r));
    const glm::vec3 t(m[3]);
    palette[i].real = real;
    palette[i].dual = 0.5f * (glm::quat(0.0f, t.x, t.y, t.z) * real);
  }
  return base::kJobOk;
}

JobStatus DqsJob::Validate() const {
  if (influences < 1 || influences > kMaxInfluences) {
    return {JobStatus::kOutOfRange, "influences must be in 1..kMaxInfluences"};
  }
  const std::size_t n = rest_positions.size();
  const std::size_t k = static_cast<std::size_t>(influences);
  if (n > 0 && palette.empty()) return {JobStatus::kMissingInput, "dual quaternion palette is empty"};
  if (joint_indices.size() != n * k) {
    return {JobStatus::kSizeMismatch, "joint_indices must hold #V x influences entries"};
  }
  if (joint_weights.size() != n * k) {
    return {JobStatus::kSizeMismatch, "joint_weights must hold #V x influences entries"};
  }
  if (positions.size() != n) return {JobStatus::kSizeMismatch, "positions must have #V entries"};
  if (!rest_normals.empty()) {
    if (normals.empty()) return {JobStatus::kMissingOutput, "rest_normals set without normals"};
    if (rest_normals.size() != n || normals.size() != n) {
      return {JobStatus::kSizeMismatch, "rest_normals and normals must have #V entries"};
    }
  }
  return base::kJobOk;
}

JobStatus DqsJob::Run() const {
  const JobStatus status = Validate();
  if (!status.ok()) return status;
  const std::size_t n = rest_positions.size();
  const std::size_t k = static_cast<std::size_t>(influences);
  for (std::size_t v = 0; v < n; ++v) {
    const std::uint16_t* idx = joint_indices.data() + v * k;
    const float* w = joint_weights.data() + v * k;
    std::size_t heaviest = 0;
    for (std::size_t i = 1; i < k; ++i) {
      if (w[i] > w[heaviest]) heaviest = i;
    }
    const glm::quat pivot = palette[idx[heaviest]].real;
    glm::quat real(0.0f, 0.0f, 0.0f, 0.0f);
    glm::quat dual(0.0f, 0.0f, 0.0f, 0.0f);
    for (std::size_t i = 0; i < k; ++i) {
      const DualQuat& dq = palette[idx[i]];
      const float s = Dot(dq.real, pivot) < 0.0f ? -w[i] : w[i];  // shorter arc to the pivot
      real = real + s * dq.real;
      dual = dual + s * dq.dual;
    }
    const float len = std::sqrt(Dot(real, real));
    const float inv = len > 0.0f ? 1.0f / len : 0.0f;
    real = real * inv;
    dual = dual * inv;
    const glm::vec3 r(real.x, real.y, real.z);
    const glm::vec3 d(dual.x, dual.y, dual.z);
    const glm::vec3 t = 2.0f * (real.w * d - dual.w * r + glm::cross(r, d));
    positions[v] = Rotate(real, rest_positions[v]) + t;
    if (!rest_normals.empty()) normals[v] = Rotate(real, rest_normals[v]);
  }
  return base::kJobOk;
}

}  // namespace deform
