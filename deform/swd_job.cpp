#include "deform/swd_job.h"

#include <array>

namespace deform {
namespace {

using mocap::JobStatus;

struct Deformed {
  glm::vec3 position;
  glm::vec3 normal;
};

// One sweep's rebuild of a bound point: c(u) + dR(u) s(u) o, normal dR(u) n0.
Deformed Rebuild(const SweepChain& chain, const SweepPose& pose, const SweepBinding& binding,
                 const glm::vec3* rest_normal, bool keep_volume) {
  const glm::vec3 centre = SweepCentre<float>(chain, pose, binding.u, nullptr);
  const glm::quat frame = SweepFrame<float>(chain, pose, binding.u);
  const float scale = keep_volume ? SweepScale<float>(chain, pose, binding.u) : 1.0f;
  Deformed out;
  out.position = centre + frame * (scale * binding.offset);
  out.normal = rest_normal != nullptr ? frame * *rest_normal : glm::vec3(0.0f);
  return out;
}

}  // namespace

JobStatus SwdJob::Validate() const {
  if (chains.empty()) return {JobStatus::kMissingInput, "no sweep chains"};
  if (chains.size() > static_cast<std::size_t>(kMaxSwdChains)) {
    return {JobStatus::kOutOfRange, "more sweep chains than kMaxSwdChains"};
  }
  if (joint_rotations.size() != joint_positions.size()) {
    return {JobStatus::kSizeMismatch, "joint rotations and positions differ in size"};
  }
  for (const SweepChain& chain : chains) {
    if (chain.num_bones() < 1) return {JobStatus::kMissingInput, "sweep chain was not built"};
    for (int k = 0; k < chain.num_bones(); ++k) {
      if (static_cast<std::size_t>(chain.joint(k)) >= joint_rotations.size()) {
        return {JobStatus::kOutOfRange, "sweep chain joint index past the joint arrays"};
      }
    }
  }
  if (positions.size() != bindings.size()) {
    return {JobStatus::kSizeMismatch, "positions and bindings differ in size"};
  }
  if (!rest_normals.empty()) {
    if (normals.empty()) return {JobStatus::kMissingOutput, "rest normals without normal output"};
    if (rest_normals.size() != bindings.size()) {
      return {JobStatus::kSizeMismatch, "rest normals and bindings differ in size"};
    }
  }
  if (!normals.empty()) {
    if (rest_normals.empty()) return {JobStatus::kMissingInput, "normal output without rest normals"};
    if (normals.size() != bindings.size()) {
      return {JobStatus::kSizeMismatch, "normals and bindings differ in size"};
    }
  }
  return mocap::kJobOk;
}

JobStatus SwdJob::Run() const {
  if (const JobStatus status = Validate(); !status) return status;
  for (const SweepVertexBinding& binding : bindings) {
    if (binding.primary.chain >= chains.size() ||
        (binding.weight < 1.0f && binding.secondary.chain >= chains.size())) {
      return {JobStatus::kOutOfRange, "binding names a chain past the chain list"};
    }
  }
  std::array<SweepPose, kMaxSwdChains> poses;
  for (std::size_t c = 0; c < chains.size(); ++c) {
    PoseSweepChain<float>(chains[c], joint_rotations, joint_positions, keep_volume, &poses[c]);
  }
  const bool with_normals = !rest_normals.empty();
  for (std::size_t v = 0; v < bindings.size(); ++v) {
    const SweepVertexBinding& binding = bindings[v];
    const glm::vec3* rest_normal = with_normals ? &rest_normals[v] : nullptr;
    const std::size_t c0 = binding.primary.chain;
    Deformed result = Rebuild(chains[c0], poses[c0], binding.primary, rest_normal, keep_volume);
    if (binding.weight < 1.0f) {
      const std::size_t c1 = binding.secondary.chain;
      const Deformed trunk =
          Rebuild(chains[c1], poses[c1], binding.secondary, rest_normal, keep_volume);
      const float om = binding.weight;
      result.position = om * result.position + (1.0f - om) * trunk.position;
      const glm::vec3 n = om * result.normal + (1.0f - om) * trunk.normal;
      const float length = glm::length(n);
      result.normal = length > 0.0f ? n / length : result.normal;
    }
    positions[v] = result.position;
    if (with_normals) normals[v] = result.normal;
  }
  return mocap::kJobOk;
}

}  // namespace deform
