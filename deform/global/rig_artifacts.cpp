#include "deform/global/rig_artifacts.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "deform/global/artifact_metrics.h"
#include "deform/global/dqs_job.h"
#include "deform/global/skinning_job.h"

namespace deform {
namespace {

using base::ErrorCode;
using base::MakeError;

constexpr double kRingReach = 0.6;       // ring vertices lie within this x Lmin of the joint
constexpr double kRingThickness = 0.02;  // one mesh ring: within this x Lmin of the nearest

// The vertices of the mesh ring nearest `plane` among those bound (whole, no junction)
// to `chain` within `reach` of the plane's point.
std::vector<std::uint32_t> NearestRing(std::span<const glm::vec3> rest,
                                       std::span<const SweepVertexBinding> bindings, int chain,
                                       const RingPlane& plane, double reach, double thickness) {
  const glm::dvec3 n = glm::normalize(plane.normal);
  double nearest = 1e300, nearest_d = 0.0;
  std::vector<std::uint32_t> candidates;
  for (std::size_t v = 0; v < rest.size(); ++v) {
    if (bindings[v].primary.chain != chain || bindings[v].weight < 1.0f) continue;
    const glm::dvec3 d = glm::dvec3(rest[v]) - plane.point;
    if (glm::length(d) > reach) continue;
    candidates.push_back(static_cast<std::uint32_t>(v));
    const double s = glm::dot(d, n);
    if (std::abs(s) < nearest) nearest = std::abs(s), nearest_d = s;
  }
  std::vector<std::uint32_t> ring;
  for (std::uint32_t v : candidates) {
    const double s = glm::dot(glm::dvec3(rest[v]) - plane.point, n);
    if (std::abs(s - nearest_d) < thickness) ring.push_back(v);
  }
  return ring;
}

// SSD, DQS and SWD positions of `mesh` under model_from_joint.
// The topmost of the joints that sit where `joint` sits (zero-length helpers such as
// CMU's LeftFingerBase under LeftHand): the joint a user turns to bend or twist there.
int TopJointAt(const mocap::Skeleton& skeleton, std::span<const glm::mat4> bind, int joint) {
  const glm::vec3 at(bind[static_cast<std::size_t>(joint)][3]);
  const float scale = std::max(1e-6f, glm::length(at));
  while (true) {
    const int parent = skeleton.parents[static_cast<std::size_t>(joint)];
    if (parent < 0 ||
        glm::distance(glm::vec3(bind[static_cast<std::size_t>(parent)][3]), at) > 1e-5f * scale) {
      return joint;
    }
    joint = parent;
  }
}

base::Status DeformAll(const SkinnedMesh& mesh, const SwdRig& rig, std::span<const glm::mat4> model,
                       std::vector<glm::vec3> out[3]) {
  const std::size_t nv = mesh.bind.positions.size();
  std::vector<glm::mat4> palette(mesh.skin_joints.size());
  std::vector<DualQuat> dq(mesh.skin_joints.size());
  for (int m = 0; m < 3; ++m) out[m].resize(nv);
  base::JobStatus s = BuildSkinningPalette(model, mesh, palette);
  if (s) s = BuildDualQuatPalette(palette, dq);
  const int k = mesh.weights.influences;
  if (s) {
    s = SkinningJob{.model_from_bind = palette, .influences = k,
                    .joint_indices = mesh.weights.joints, .joint_weights = mesh.weights.weights,
                    .rest_positions = mesh.bind.positions, .rest_normals = {},
                    .positions = out[0], .normals = {}}
            .Run();
  }
  if (s) {
    s = DqsJob{.palette = dq, .influences = k, .joint_indices = mesh.weights.joints,
               .joint_weights = mesh.weights.weights, .rest_positions = mesh.bind.positions,
               .rest_normals = {}, .positions = out[1], .normals = {}}
            .Run();
  }
  if (s) {
    std::vector<glm::quat> rot(model.size());
    std::vector<glm::vec3> joints(model.size());
    s = SwdRigJob{.rig = &rig, .model_from_joint = model, .vertex_begin = 0,
                  .joint_rotations = rot, .joint_positions = joints, .keep_volume = false,
                  .positions = out[2], .normals = {}}
            .Run();
  }
  if (!s) return MakeError(ErrorCode::kInternal, {}, std::string("artifact pose: ") + s.what);
  return base::Status::Ok();
}

// Ratios of one set of rings for the three methods (minimum over the rings).
base::Result<MethodFigures> Figures(std::span<const glm::vec3> rest,
                                    const std::vector<glm::vec3> deformed[3],
                                    std::span<const ArtifactRing> rings) {
  double f[3];
  for (int m = 0; m < 3; ++m) {
    base::Result<double> r = CandyWrapperFigure(rest, deformed[m], rings);
    if (!r.ok()) return std::move(r).error();
    f[m] = *r;
  }
  return MethodFigures{f[0], f[1], f[2]};
}

}  // namespace

void TurnSubtree(const mocap::Skeleton& skeleton, int joint, const glm::quat& rotation,
                 const glm::vec3& pivot, std::span<glm::mat4> model_from_joint) {
  const glm::mat4 turn = glm::translate(glm::mat4(1.0f), pivot) * glm::mat4_cast(rotation) *
                         glm::translate(glm::mat4(1.0f), -pivot);
  std::vector<char> inside(model_from_joint.size(), 0);
  for (std::size_t j = 0; j < model_from_joint.size() && j < skeleton.parents.size(); ++j) {
    const int p = skeleton.parents[j];
    inside[j] = static_cast<int>(j) == joint || (p >= 0 && inside[static_cast<std::size_t>(p)]);
    if (inside[j]) model_from_joint[j] = turn * model_from_joint[j];
  }
}

base::Result<std::vector<LimbArtifacts>> MeasureLimbArtifacts(
    const mocap::Skeleton& skeleton, std::span<const glm::mat4> bind, const SkinnedMesh& mesh,
    const SwdRig& rig, std::span<const double> bend_degrees,
    std::span<const double> twist_degrees) {
  if (bind.size() != static_cast<std::size_t>(skeleton.num_joints()) ||
      rig.num_joints() != skeleton.num_joints() ||
      rig.num_vertices() != mesh.bind.num_vertices()) {
    return MakeError(ErrorCode::kCountMismatch, {},
                     "artifact figures need #J bind matrices and the rig of this mesh");
  }
  if (rig.limbs().empty()) {
    return base::InvalidArgument("the skeleton has no limb (a chain of two bones leaving a trunk)");
  }
  const glm::vec3 up = skeleton.info.up_axis == mocap::UpAxis::kZ ? glm::vec3(0, 0, 1)
                                                                   : glm::vec3(0, 1, 0);
  const std::span<const glm::vec3> rest = mesh.bind.positions;
  std::vector<LimbArtifacts> out;
  std::vector<glm::vec3> deformed[3];
  std::vector<glm::mat4> model(bind.begin(), bind.end());
  for (const SwdLimb& limb : rig.limbs()) {
    const SweepChain& c = rig.chains()[static_cast<std::size_t>(limb.chain)];
    const int k = limb.middle;
    const glm::vec3 joint(c.rest_pose().points[static_cast<std::size_t>(k)]);
    const glm::vec3 a_in(c.rest_axis(k - 1));
    const glm::vec3 a_out(c.rest_axis(k));
    const double lmin = std::min(c.rest_length(k - 1), c.rest_length(k));
    LimbArtifacts limb_out;
    limb_out.arm = limb.arm;
    const int bent = TopJointAt(skeleton, bind, c.joint(k));
    limb_out.joint = skeleton.names[static_cast<std::size_t>(bent)];
    // Bend axis: across the bone, horizontal when the bone is not vertical.
    glm::vec3 axis = glm::cross(a_out, up);
    if (glm::length(axis) < 0.3f) axis = glm::cross(a_out, glm::vec3(up.y, up.z, up.x));
    axis = glm::normalize(axis);
    ArtifactRing ring;
    ring.rest_plane = BisectorPlane(joint, a_in, a_out);
    ring.vertices = NearestRing(rest, rig.bindings(), limb.chain, ring.rest_plane,
                                kRingReach * lmin, kRingThickness * lmin);
    if (ring.vertices.size() < 3) {
      return base::InvalidArgument("no mesh ring around joint '" + limb_out.joint + "'");
    }
    for (double deg : bend_degrees) {
      const glm::quat q = glm::angleAxis(static_cast<float>(glm::radians(deg)), axis);
      std::copy(bind.begin(), bind.end(), model.begin());
      TurnSubtree(skeleton, bent, q, joint, model);
      if (base::Status s = DeformAll(mesh, rig, model, deformed); !s.ok()) return s.error();
      ring.plane = BisectorPlane(joint, a_in, q * a_out);
      base::Result<MethodFigures> f = Figures(rest, deformed, std::span(&ring, 1));
      if (!f.ok()) return std::move(f).error();
      limb_out.collapse.push_back({deg, *f});
    }
    if (limb.arm && limb.has_end) {
      const int w = k + 1;
      const glm::vec3 wrist(c.rest_pose().points[static_cast<std::size_t>(w)]);
      const int twisted = TopJointAt(skeleton, bind, c.joint(w));
      limb_out.end_joint = skeleton.names[static_cast<std::size_t>(twisted)];
      std::vector<ArtifactRing> rings;
      const double len = c.rest_length(k);
      for (double s : {0.5, 0.6, 0.7, 0.8, 0.9, 1.0}) {
        ArtifactRing r;
        r.rest_plane.point = glm::dvec3(joint) + s * len * glm::dvec3(a_out);
        r.rest_plane.normal = glm::dvec3(a_out);
        r.plane = r.rest_plane;  // the forearm does not move under a twist of the hand
        r.vertices = NearestRing(rest, rig.bindings(), limb.chain, r.rest_plane,
                                 kRingReach * lmin, kRingThickness * lmin);
        if (r.vertices.size() >= 3) rings.push_back(std::move(r));
      }
      if (rings.empty()) {
        return base::InvalidArgument("no mesh ring along the bone before '" + limb_out.end_joint +
                                     "'");
      }
      for (double deg : twist_degrees) {
        const glm::quat q = glm::angleAxis(static_cast<float>(glm::radians(deg)), a_out);
        std::copy(bind.begin(), bind.end(), model.begin());
        TurnSubtree(skeleton, twisted, q, wrist, model);
        if (base::Status s = DeformAll(mesh, rig, model, deformed); !s.ok()) return s.error();
        base::Result<MethodFigures> f = Figures(rest, deformed, rings);
        if (!f.ok()) return std::move(f).error();
        limb_out.candy.push_back({deg, *f});
      }
    }
    out.push_back(std::move(limb_out));
  }
  return out;
}

}  // namespace deform
