#include "deform/shapes/example_shapes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include <glm/gtc/quaternion.hpp>

#include "deform/shapes/polar_rotation.h"
#include "deform/internal/checks.h"

namespace deform {
namespace {

using base::ErrorCode;

base::Error EditError(const ExampleEdit& e, const std::string& message) {
  return base::InvalidArgument(e.loc, message);
}

using internal::Finite;

// Rotation part of a palette matrix, in double.
glm::dmat3 Rotation3(const glm::mat4& m) { return glm::dmat3(glm::mat3(m)); }

}  // namespace

base::Result<SculptedExample> SculptExample(const PatchSetup& patch, const SkinnedMesh& mesh,
                                            const SkinningPose& pose,
                                            std::span<const ExampleEdit> edits,
                                            const ManipulationOptions& options, int iterations) {
  const int nc = patch.num_control();
  const std::size_t num_skin = mesh.skin_joints.size();
  if (pose.model_from_bind.size() != num_skin ||
      (!pose.dual_quats.empty() && pose.dual_quats.size() != num_skin)) {
    return base::InvalidArgument("example pose: expected palettes of " + std::to_string(num_skin) +
                                 " skin joints, found " +
                                 std::to_string(pose.model_from_bind.size()));
  }
  if (edits.empty()) {
    return base::InvalidArgument("expected at least one edit, found none");
  }

  // G: the control points carried to the example pose (float, as per frame).
  std::vector<glm::vec3> carried(static_cast<std::size_t>(nc));
  base::JobStatus s =
      CarryControlPointsJob{.patch = &patch, .pose = pose, .control = carried}.Run();
  if (!s) return base::InvalidArgument(s.what);
  std::vector<glm::quat> rotations(static_cast<std::size_t>(nc));
  s = PatchControlRotations(patch, pose, rotations);
  if (!s) return base::InvalidArgument(s.what);
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

  bool brush = false;
  for (const ExampleEdit& e : edits) brush = brush || e.radius > 0.0;
  base::Result<ManipulationResult> solved = ManipulationResult{};
  if (brush) {
    std::vector<BrushStroke> strokes;
    for (std::size_t k = 0; k < edits.size(); ++k) {
      if (!(edits[k].radius >= 0.0 && std::isfinite(edits[k].radius))) {
        return EditError(edits[k], "expected a finite radius >= 0");
      }
      strokes.push_back({.u = targets[k].u, .v = targets[k].v, .radius = edits[k].radius,
                         .delta = targets[k].delta});
    }
    solved = SolveBrushStrokes(surface, strokes, {.free_mask = options.free_mask});
  } else {
    solved = MoveBoundVertices(surface, targets, options, iterations);
  }
  if (!solved.ok()) {
    base::Error err = std::move(solved).error();
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
  if (!s) return base::MakeError(ErrorCode::kInternal, {}, s.what);
  return out;
}

}  // namespace deform
