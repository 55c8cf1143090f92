#include "deform/global/swd_job.h"

#include <array>
#include <cmath>

namespace deform {
namespace {

using base::JobStatus;

struct Deformed {
  glm::vec3 position;
  glm::vec3 normal;
};

// (sa, sb) per joint region of one chain; (1, 1) = no elliptic scaling.
using RegionScales = std::array<glm::vec2, kMaxSweepBones + 1>;

// One sweep's rebuild of a bound point: c(u) + dR(u) s(u) E0 diag(sa', sb', 1) E0^T o,
// normal dR(u) n0.
Deformed Rebuild(const SweepChain& chain, const SweepPose& pose, const SweepBinding& binding,
                 const glm::vec3* rest_normal, bool keep_volume, const RegionScales* scales) {
  const glm::vec3 centre = SweepCentre<float>(chain, pose, binding.u, nullptr);
  const glm::quat frame = SweepFrame<float>(chain, pose, binding.u);
  const float scale = keep_volume ? SweepScale<float>(chain, pose, binding.u) : 1.0f;
  glm::vec3 offset = binding.offset;
  int joint = 0;
  float x = 0.0f;
  if (scales != nullptr && SweepRegionAt<float>(chain, binding.u, &joint, &x)) {
    const glm::vec2 s = (*scales)[static_cast<std::size_t>(joint)];
    if (s != glm::vec2(1.0f)) {
      const float bump = 4.0f * x * (1.0f - x);
      const float sa = 1.0f + (s.x - 1.0f) * bump;
      const float sb = 1.0f + (s.y - 1.0f) * bump;
      // o lies in the section plane (g(u) = 0), so E0 diag(sa, sb, 1) E0^T o reduces to
      // sb o + (sa - sb)(e_a . o) e_a.
      const glm::vec3& axis = binding.section_axis;
      offset = sb * offset + ((sa - sb) * glm::dot(axis, offset)) * axis;
    }
  }
  Deformed out;
  out.position = centre + frame * (scale * offset);
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
  for (const SectionScale& s : section_scales) {
    if (s.chain >= chains.size() || s.joint < 1 || s.joint >= chains[s.chain].num_bones()) {
      return {JobStatus::kOutOfRange, "section scale names no interior joint of a chain"};
    }
    if (!(std::isfinite(s.scale_a) && std::isfinite(s.scale_b) && s.scale_a > 0.0f &&
          s.scale_b > 0.0f)) {
      return {JobStatus::kOutOfRange, "section scales must be finite and positive"};
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
  return base::kJobOk;
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
  std::array<RegionScales, kMaxSwdChains> scales;
  for (RegionScales& chain_scales : scales) chain_scales.fill(glm::vec2(1.0f));
  for (const SectionScale& s : section_scales) {
    scales[s.chain][s.joint] = glm::vec2(s.scale_a, s.scale_b);
  }
  const bool with_scales = !section_scales.empty();
  const bool with_normals = !rest_normals.empty();
  for (std::size_t v = 0; v < bindings.size(); ++v) {
    const SweepVertexBinding& binding = bindings[v];
    const glm::vec3* rest_normal = with_normals ? &rest_normals[v] : nullptr;
    const std::size_t c0 = binding.primary.chain;
    Deformed result = Rebuild(chains[c0], poses[c0], binding.primary, rest_normal, keep_volume,
                              with_scales ? &scales[c0] : nullptr);
    if (binding.weight < 1.0f) {
      const std::size_t c1 = binding.secondary.chain;
      const Deformed trunk =
          Rebuild(chains[c1], poses[c1], binding.secondary, rest_normal, keep_volume,
                  with_scales ? &scales[c1] : nullptr);
      const float om = binding.weight;
      result.position = om * result.position + (1.0f - om) * trunk.position;
      const glm::vec3 n = om * result.normal + (1.0f - om) * trunk.normal;
      const float length = glm::length(n);
      result.normal = length > 0.0f ? n / length : result.normal;
    }
    positions[v] = result.position;
    if (with_normals) normals[v] = result.normal;
  }
  return base::kJobOk;
}

}  // namespace deform
