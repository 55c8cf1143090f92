#include "deform/global/global_skinning.h"

#include <string>
#include <utility>

#include "deform/global/skinning_job.h"
#include "deform/global/swd_job.h"

namespace deform {
namespace {

template <typename T>
std::span<T> Range(std::span<T> v, int begin, int end, int stride = 1) {
  if (v.empty()) return v;
  return v.subspan(static_cast<std::size_t>(begin) * static_cast<std::size_t>(stride),
                   static_cast<std::size_t>(end - begin) * static_cast<std::size_t>(stride));
}

}  // namespace

const char* GlobalMethodName(GlobalMethod method) {
  switch (method) {
    case GlobalMethod::kSsd: return "ssd";
    case GlobalMethod::kDqs: return "dqs";
    case GlobalMethod::kSwd: return "swd";
  }
  return "?";
}

base::JobStatus SkinningPalettes::Update(std::span<const glm::mat4> model_from_joint,
                                         const SkinnedMesh& mesh, bool dqs) {
  model_from_bind.resize(mesh.skin_joints.size());
  dual_quats.resize(dqs ? mesh.skin_joints.size() : 0);
  const base::JobStatus s = BuildSkinningPalette(model_from_joint, mesh, model_from_bind);
  if (!s || !dqs) return s;
  return BuildDualQuatPalette(model_from_bind, dual_quats);
}

base::JobStatus SkinPoints(const SkinningPose& pose, const SkinWeights& weights,
                           std::span<const glm::vec3> rest_positions,
                           std::span<const glm::vec3> rest_normals, int begin, int end,
                           std::span<glm::vec3> positions, std::span<glm::vec3> normals) {
  if (begin < 0 || end < begin || static_cast<std::size_t>(end) > rest_positions.size()) {
    return {base::JobStatus::kOutOfRange, "point range past the rest points"};
  }
  const int k = weights.influences;
  const auto joints = Range(std::span<const std::uint16_t>(weights.joints), begin, end, k);
  const auto blend = Range(std::span<const float>(weights.weights), begin, end, k);
  const auto rest = Range(rest_positions, begin, end);
  const auto rest_n = Range(rest_normals, begin, end);
  const auto out = Range(positions, begin, end);
  const auto out_n = Range(normals, begin, end);
  if (!pose.dual_quats.empty()) {
    return DqsJob{.palette = pose.dual_quats,
                  .influences = k,
                  .joint_indices = joints,
                  .joint_weights = blend,
                  .rest_positions = rest,
                  .rest_normals = rest_n,
                  .positions = out,
                  .normals = out_n}
        .Run();
  }
  return SkinningJob{.model_from_bind = pose.model_from_bind,
                     .influences = k,
                     .joint_indices = joints,
                     .joint_weights = blend,
                     .rest_positions = rest,
                     .rest_normals = rest_n,
                     .positions = out,
                     .normals = out_n}
      .Run();
}

base::Result<GlobalSkinning> GlobalSkinning::Create(
    GlobalMethod method, const mocap::Skeleton& skeleton,
    std::span<const glm::mat4> bind_model_from_joint, const SkinnedMesh& mesh) {
  GlobalSkinning g(method, mesh);
  if (method != GlobalMethod::kSwd) return g;
  base::Result<SwdRig> rig = BuildSwdRig(skeleton, bind_model_from_joint, mesh.bind,
                                         {.vertex_chains = mesh.body_chain_coords});
  if (!rig.ok()) return std::move(rig).error();
  g.swd_ = std::move(*rig);
  g.swd_rotations_.resize(static_cast<std::size_t>(skeleton.num_joints()));
  g.swd_positions_.resize(static_cast<std::size_t>(skeleton.num_joints()));
  return g;
}

base::JobStatus GlobalSkinning::Pose(std::span<const glm::mat4> model_from_joint) {
  if (method_ == GlobalMethod::kSwd) {
    return ComputeSwdJointState(*swd_, model_from_joint, swd_rotations_, swd_positions_);
  }
  return palettes_.Update(model_from_joint, *mesh_, method_ == GlobalMethod::kDqs);
}

base::JobStatus GlobalSkinning::SkinVertices(int begin, int end, std::span<glm::vec3> positions,
                                             std::span<glm::vec3> normals) const {
  const Mesh& bind = mesh_->bind;
  if (bind.normals.empty()) normals = {};
  if (method_ != GlobalMethod::kSwd) {
    return SkinPoints(palettes_.view(), mesh_->weights, bind.positions,
                      normals.empty() ? std::span<const glm::vec3>() : bind.normals, begin, end,
                      positions, normals);
  }
  if (begin < 0 || end < begin || end > bind.num_vertices()) {
    return {base::JobStatus::kOutOfRange, "vertex range past the mesh"};
  }
  return Sweep(
      Range(swd_->bindings(), begin, end),
      Range(normals.empty() ? std::span<const glm::vec3>() : swd_->rest_normals(), begin, end),
      Range(positions, begin, end), Range(normals, begin, end));
}

base::Result<SkinBoundPoints> GlobalSkinning::BindPoints(std::span<const glm::vec3> rest,
                                                         const SkinWeights& weights,
                                                         std::span<const int> guides) const {
  SkinBoundPoints points{.rest = rest, .weights = &weights, .sweeps = {}};
  if (method_ != GlobalMethod::kSwd) return points;
  base::Result<std::vector<SweepVertexBinding>> bound = BindPointsLikeVertices(*swd_, rest, guides);
  if (!bound.ok()) return std::move(bound).error();
  points.sweeps = std::move(*bound);
  return points;
}

base::JobStatus GlobalSkinning::CarryPoints(const SkinBoundPoints& points,
                                            std::span<glm::vec3> out) const {
  if (out.size() != points.rest.size()) {
    return {base::JobStatus::kSizeMismatch, "carried points differ in number from the bound ones"};
  }
  if (method_ != GlobalMethod::kSwd) {
    if (points.weights == nullptr)
      return {base::JobStatus::kMissingInput, "points without weights"};
    return SkinPoints(palettes_.view(), *points.weights, points.rest, {}, 0,
                      static_cast<int>(points.rest.size()), out, {});
  }
  return Sweep(points.sweeps, {}, out, {});
}

base::JobStatus GlobalSkinning::Sweep(std::span<const SweepVertexBinding> bindings,
                                      std::span<const glm::vec3> rest_normals,
                                      std::span<glm::vec3> positions,
                                      std::span<glm::vec3> normals) const {
  return SwdJob{.chains = swd_->chains(),
                .joint_rotations = swd_rotations_,
                .joint_positions = swd_positions_,
                .bindings = bindings,
                .rest_normals = rest_normals,
                .keep_volume = false,
                .section_scales = {},
                .positions = positions,
                .normals = normals}
      .Run();
}

}  // namespace deform
