#include "deform/example_shapes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include <glm/gtc/quaternion.hpp>

#include "deform/polar_rotation.h"
#include "deform/polar_rotation_lanes.h"

namespace deform {
namespace {

using mocap::ErrorCode;

mocap::Error EditError(const ExampleEdit& e, const std::string& message) {
  return mocap::MakeError(ErrorCode::kInvalidArgument, e.loc, message);
}

// Most skin joints the fast SSD rotation path keeps on the stack.
constexpr std::size_t kMaxFastBones = 256;
// Largest |R^T R - I| entry for a palette matrix to count as a rotation.
constexpr double kRigidTol = 1e-4;
// Blends PatchControlRotations hands to the lane Newton at once (a multiple
// of kPolarLanes; stack arrays of this size).
constexpr std::size_t kPolarBatch = 32;

bool Finite(const glm::dvec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Rotation part of a palette matrix, in double.
glm::dmat3 Rotation3(const glm::mat4& m) { return glm::dmat3(glm::mat3(m)); }

}  // namespace

mocap::JobStatus PatchControlRotations(const PatchSetup& patch, const ExamplePose& pose,
                                       std::span<glm::quat> rotations,
                                       std::span<const glm::vec3> displacement) {
  if (!displacement.empty() && displacement.size() != rotations.size()) {
    return {mocap::JobStatus::kSizeMismatch, "displacement must be empty or #C"};
  }
  // Q = G + A dS is G whatever A is where dS is exactly zero (A 0 = 0): the
  // identity stands in for A there.
  const auto skip = [&](std::size_t c) {
    return !displacement.empty() && displacement[c] == glm::vec3(0.0f);
  };
  const auto identity_where_skipped = [&](mocap::JobStatus st) {
    if (!st) return st;
    for (std::size_t c = 0; c < rotations.size(); ++c) {
      if (skip(c)) rotations[c] = glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
    }
    return st;
  };
  const SkinWeights& w = patch.control_weights;
  if (!pose.dq_palette.empty()) {
    return identity_where_skipped(
        DqsControlRotations(pose.dq_palette, w.influences, w.joints, w.weights, rotations));
  }
  const std::size_t num_skin = pose.model_from_bind.size();
  const int k = w.influences;
  if (k < 1 || k > kMaxInfluences || num_skin > kMaxFastBones ||
      w.joints.size() != rotations.size() * static_cast<std::size_t>(k) ||
      w.weights.size() != w.joints.size()) {
    return identity_where_skipped(
        SsdControlRotations(pose.model_from_bind, k, w.joints, w.weights, rotations));
  }
  // Bone rotations as matrices and quaternions, converted once per call and
  // only for the bones this patch's moving control points use; a palette
  // matrix that is not a rotation (scale, shear) sends the whole patch to the
  // general polar decomposition.
  std::array<glm::dmat3, kMaxFastBones> bone_matrix;
  std::array<glm::dquat, kMaxFastBones> bone;
  std::array<std::uint8_t, kMaxFastBones> have{};
  const auto kk = static_cast<std::size_t>(k);
  for (std::size_t c = 0; c < rotations.size(); ++c) {
    if (skip(c)) continue;  // no slot of this control point is needed
    for (std::size_t slot = c * kk; slot < (c + 1) * kk; ++slot) {
      const std::uint16_t b = w.joints[slot];
      if (w.weights[slot] == 0.0f || have[b]) continue;
      if (b >= num_skin) return {mocap::JobStatus::kOutOfRange, "joint index beyond the palette"};
      const glm::dmat3 r(glm::mat3(pose.model_from_bind[b]));
      const glm::dmat3 rtr = glm::transpose(r) * r;
      double off = 0.0;
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) off = std::max(off, std::abs(rtr[i][j] - (i == j ? 1.0 : 0.0)));
      }
      if (off > kRigidTol || glm::determinant(r) <= 0.0) {
        return identity_where_skipped(
            SsdControlRotations(pose.model_from_bind, k, w.joints, w.weights, rotations));
      }
      bone_matrix[b] = r;
      bone[b] = glm::normalize(glm::quat_cast(r));
      have[b] = 1;
    }
  }
  // Blends of three or more bones wait in a batch for Newton's polar
  // iteration in SIMD lanes (polar_rotation_lanes.h, bit for bit the scalar
  // iteration, so the grouping does not change any result); a blend it
  // refuses (det <= kPolarNewtonMinDet: nearly singular or reflecting) takes
  // PolarRotation, whose SVD fixes the sign as SsdControlRotations always did.
  std::array<glm::dmat3, kPolarBatch> blends;
  std::array<glm::quat, kPolarBatch> quats;
  std::array<std::uint8_t, kPolarBatch> converged;
  std::array<std::size_t, kPolarBatch> batch_control;
  std::size_t batched = 0;
  const auto flush = [&] {
    (void)PolarRotationsNewton(std::span(blends.data(), batched), {},
                               std::span(converged.data(), batched), PolarLanesPath::kAuto,
                               std::span(quats.data(), batched));
    for (std::size_t i = 0; i < batched; ++i) {
      rotations[batch_control[i]] =
          converged[i] ? quats[i]
                       : glm::normalize(glm::quat(glm::quat_cast(PolarRotation(blends[i]))));
    }
    batched = 0;
  };
  for (std::size_t c = 0; c < rotations.size(); ++c) {
    if (skip(c)) {
      rotations[c] = glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
      continue;
    }
    // The influences with nonzero weight, in slot order.
    int n = 0;
    std::array<std::size_t, kMaxInfluences> slots{};
    for (std::size_t slot = c * kk; slot < (c + 1) * kk; ++slot) {
      if (w.weights[slot] != 0.0f) slots[static_cast<std::size_t>(n++)] = slot;
    }
    if (n == 0) {  // no weight at all (CheckSkinWeights rejects it): no turn
      rotations[c] = glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
      continue;
    }
    if (n == 1) {
      rotations[c] = glm::quat(bone[w.joints[slots[0]]]);
      continue;
    }
    if (n == 2) {
      const glm::dquat q1 = bone[w.joints[slots[0]]];
      glm::dquat rel = glm::conjugate(q1) * bone[w.joints[slots[1]]];  // R1^T R2 = Rot(a, theta)
      if (rel.w < 0.0) rel = -rel;
      const glm::dvec3 v(rel.x, rel.y, rel.z);                 // sin(theta/2) a
      const double s2 = glm::dot(v, v);
      const double w1 = w.weights[slots[0]], w2 = w.weights[slots[1]];
      // theta from rel = (c, s a), c = cos(theta/2), s = sin(theta/2):
      // sin theta = 2 s c, cos theta = 2 c^2 - 1 (no trigonometric calls).
      const double yc = 2.0 * w2 * rel.w;                      // y = yc s
      const double x = w1 + w2 * (2.0 * rel.w * rel.w - 1.0), y2 = yc * yc * s2;
      const double rho = std::sqrt(x * x + y2);
      if (s2 < 1e-24 && rho >= 1e-6) {
        rotations[c] = glm::quat(q1);
        continue;
      }
      if (rho >= 1e-6 && rho + x >= 1e-9) {
        // w1 I + w2 Rot(a, theta) is normal with eigenvalues 1 and w1 + w2 e^(+-i theta)
        // = rho e^(+-i phi), so its orthogonal polar factor is Rot(a, phi); as a
        // quaternion (cos(phi/2), sin(phi/2) a) ~ (rho + x, y a) = (rho + x, yc v),
        // of length sqrt((rho + x)^2 + y^2). q1 is a unit quaternion, so one
        // normalization of the product suffices.
        const glm::dquat turn(rho + x, yc * v);
        const double inv_len = 1.0 / std::sqrt((rho + x) * (rho + x) + y2);
        rotations[c] = glm::quat((q1 * turn) * inv_len);
        continue;
      }
      // Two opposite rotations at (nearly) equal weight: the general path.
    }
    // Three or more bones: the polar factor of sum_b w_b R_b, in the batch.
    glm::dmat3 blend(0.0);
    for (int i = 0; i < n; ++i) {
      const std::size_t slot = slots[static_cast<std::size_t>(i)];
      blend += static_cast<double>(w.weights[slot]) * bone_matrix[w.joints[slot]];
    }
    blends[batched] = blend;
    batch_control[batched++] = c;
    if (batched == kPolarBatch) flush();
  }
  flush();
  return mocap::kJobOk;
}

mocap::Result<SculptedExample> SculptExample(const PatchSetup& patch, const SkinnedMesh& mesh,
                                             const ExamplePose& pose,
                                             std::span<const ExampleEdit> edits,
                                             const ManipulationOptions& options, int iterations) {
  const int nc = patch.num_control();
  const std::size_t num_skin = mesh.skin_joints.size();
  if (pose.model_from_bind.size() != num_skin ||
      (!pose.dq_palette.empty() && pose.dq_palette.size() != num_skin)) {
    return mocap::MakeError(ErrorCode::kInvalidArgument, {},
                            "example pose: expected palettes of " + std::to_string(num_skin) +
                                " skin joints, found " +
                                std::to_string(pose.model_from_bind.size()));
  }
  if (edits.empty()) {
    return mocap::MakeError(ErrorCode::kInvalidArgument, {}, "expected at least one edit, found none");
  }

  // G: the control points carried to the example pose (float, as per frame).
  std::vector<glm::vec3> carried(static_cast<std::size_t>(nc));
  mocap::JobStatus s = CarryControlPointsJob{.patch = &patch,
                                             .model_from_bind = pose.dq_palette.empty()
                                                                    ? pose.model_from_bind
                                                                    : std::span<const glm::mat4>(),
                                             .dq_palette = pose.dq_palette,
                                             .control = carried}
                           .Run();
  if (!s) return mocap::MakeError(ErrorCode::kInvalidArgument, {}, s.what);
  std::vector<glm::quat> rotations(static_cast<std::size_t>(nc));
  s = PatchControlRotations(patch, pose, rotations);
  if (!s) return mocap::MakeError(ErrorCode::kInvalidArgument, {}, s.what);
  BSplineSurface surface = patch.fit.surface;
  std::vector<glm::dvec3>& control = surface.mutable_control();
  for (int c = 0; c < nc; ++c) control[static_cast<std::size_t>(c)] = glm::dvec3(carried[static_cast<std::size_t>(c)]);

  // Each edit as a bound point (u, v, d) with its world move.
  const PatchBinding& binding = patch.bound.binding;
  const SkinWeights& sw = mesh.weights;
  std::vector<VertexEdit> targets;
  targets.reserve(edits.size());
  for (const ExampleEdit& e : edits) {
    if (!Finite(e.move)) return EditError(e, "expected a finite move");
    glm::dmat3 turn(1.0);
    VertexEdit target;
    if (e.vertex >= 0) {
      if (e.vertex >= mesh.bind.num_vertices()) {
        return EditError(e, "expected a vertex index below " +
                                std::to_string(mesh.bind.num_vertices()) + ", found " +
                                std::to_string(e.vertex));
      }
      const auto it = std::find(binding.vertex.begin(), binding.vertex.end(), e.vertex);
      if (it == binding.vertex.end()) {
        return EditError(e, "vertex " + std::to_string(e.vertex) +
                                " is not bound to this patch (outside its region, on its "
                                "border or too far from the surface)");
      }
      const auto record = static_cast<std::size_t>(it - binding.vertex.begin());
      const float beta = patch.border_weight.empty() ? 1.0f : patch.border_weight[record];
      if (beta < kMinEditableBorderWeight) {
        std::ostringstream msg;
        msg << "vertex " << e.vertex << " lies where the patch fades out (border weight " << beta
            << " < " << kMinEditableBorderWeight << "); edit a vertex further inside";
        return EditError(e, msg.str());
      }
      if (!e.world_frame) {
        glm::dmat3 blend(0.0);
        const int k = sw.influences;
        for (int i = 0; i < k; ++i) {
          const auto idx = static_cast<std::size_t>(e.vertex * k + i);
          blend += static_cast<double>(sw.weights[idx]) *
                   Rotation3(pose.model_from_bind[sw.joints[idx]]);
        }
        turn = PolarRotation(blend);
      }
      target = {.u = binding.u[record], .v = binding.v[record], .d = binding.d[record],
                .delta = turn * e.move / static_cast<double>(beta)};
    } else {
      if (!(e.uv.x >= 0.0 && e.uv.x <= 1.0 && e.uv.y >= 0.0 && e.uv.y <= 1.0)) {
        return EditError(e, "expected a surface point (u, v) in [0,1]^2");
      }
      if (!e.world_frame) {
        const std::vector<double> a = SurfacePointWeights(surface, e.uv.x, e.uv.y);
        glm::dmat3 blend(0.0);
        for (int c = 0; c < nc; ++c) {
          const double ac = a[static_cast<std::size_t>(c)];
          if (ac != 0.0) blend += ac * glm::dmat3(glm::mat3_cast(rotations[static_cast<std::size_t>(c)]));
        }
        turn = PolarRotation(blend);
      }
      target = {.u = e.uv.x, .v = e.uv.y, .d = 0.0, .delta = turn * e.move};
    }
    targets.push_back(target);
  }

  mocap::Result<ManipulationResult> solved = MoveBoundVertices(surface, targets, options, iterations);
  if (!solved.ok()) {
    mocap::Error err = std::move(solved).error();
    if (err.loc.file.empty()) err.loc = edits.front().loc;
    return err;
  }
  SculptedExample out;
  out.world_delta = std::move(solved->delta);
  out.condition = solved->condition;
  for (double r : solved->residual) out.max_residual = std::max(out.max_residual, r);
  for (int u : solved->unsatisfied) {
    const ExampleEdit& e = edits[static_cast<std::size_t>(std::min<int>(u, static_cast<int>(edits.size()) - 1))];
    std::ostringstream msg;
    msg << "edit left unsatisfied by " << solved->residual[static_cast<std::size_t>(u)]
        << " model units (coincident or too many constraints for the free control points)";
    out.warnings.push_back({e.loc, msg.str()});
  }
  out.displacement.resize(static_cast<std::size_t>(nc));
  const std::vector<glm::vec3> zero(static_cast<std::size_t>(nc), glm::vec3(0.0f));
  s = StoreExampleDisplacement(rotations, zero, out.world_delta, out.displacement);
  if (!s) return mocap::MakeError(ErrorCode::kInternal, {}, s.what);
  return out;
}

}  // namespace deform
