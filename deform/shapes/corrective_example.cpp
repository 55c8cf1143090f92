#include "deform/shapes/corrective_example.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include "deform/global/global_skinning.h"
#include "deform/patch/fold_measure.h"
#include "deform/shapes/direct_manipulation.h"
#include "deform/shapes/internal/control_grid.h"
#include "deform/internal/checks.h"

namespace deform {
namespace {

using base::ErrorCode;
using Triplet = Eigen::Triplet<double>;
using SparseMatrix = Eigen::SparseMatrix<double>;

using internal::InvalidArgument;

// One bound vertex's linearisation: its free control points and weights.
struct BoundRow {
  int vertex = -1;
  double u = 0.0, v = 0.0, d = 0.0, beta = 1.0;
  std::vector<std::pair<int, double>> free;  // (free index, a_vc)
  glm::dvec3 reference{0.0};                 // P_G(u, v)
};

glm::dvec3 PatchPoint(const BSplineSurface& s, const BoundRow& r) {
  return s.Evaluate(r.u, r.v) + r.d * s.Normal(r.u, r.v);
}

// Region positions for the control change `delta` (#C): G plus the faded
// patch change at the bound vertices.
void PosedRegion(const BSplineSurface& base, std::span<const glm::dvec3> delta,
                 std::span<const BoundRow> rows, std::span<const glm::dvec3> global,
                 std::vector<glm::dvec3>& x) {
  x.assign(global.begin(), global.end());
  BSplineSurface moved = base;
  for (std::size_t c = 0; c < delta.size(); ++c) moved.mutable_control()[c] += delta[c];
  for (const BoundRow& r : rows) {
    x[static_cast<std::size_t>(r.vertex)] += r.beta * (PatchPoint(moved, r) - r.reference);
  }
}

double RmsToTargets(std::span<const BoundRow> rows, std::span<const glm::dvec3> x,
                    std::span<const glm::dvec3> target) {
  double sum = 0.0;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const glm::dvec3 e = x[static_cast<std::size_t>(rows[k].vertex)] - target[k];
    sum += glm::dot(e, e);
  }
  return rows.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(rows.size()));
}

}  // namespace

int DominantSkinJoint(const SkinWeights& weights, int vertex) {
  const int k = weights.influences;
  int best = 0;
  float best_w = -1.0f;
  for (int i = 0; i < k; ++i) {
    const auto idx = static_cast<std::size_t>(vertex * k + i);
    if (weights.weights[idx] > best_w) {
      best_w = weights.weights[idx];
      best = weights.joints[idx];
    }
  }
  return best;
}

int DrivingSkinJoint(const PatchSetup& patch, int num_skin_joints) {
  std::vector<double> total(static_cast<std::size_t>(std::max(num_skin_joints, 0)), 0.0);
  const SkinWeights& w = patch.control_weights;
  for (std::size_t k = 0; k < w.weights.size(); ++k) {
    if (w.joints[k] < total.size()) total[w.joints[k]] += static_cast<double>(w.weights[k]);
  }
  int best = -1;
  for (std::size_t j = 0; j < total.size(); ++j) {
    if (total[j] > 0.0 && (best < 0 || total[j] > total[static_cast<std::size_t>(best)])) {
      best = static_cast<int>(j);
    }
  }
  return best;
}

double RegionVolume(std::span<const glm::dvec3> positions, std::span<const glm::uvec3> triangles,
                    std::span<const int> subset, const glm::dvec3& centre) {
  double v = 0.0;
  for (int t : subset) {
    const glm::uvec3& tri = triangles[static_cast<std::size_t>(t)];
    v += glm::dot(positions[tri.x] - centre,
                  glm::cross(positions[tri.y] - centre, positions[tri.z] - centre));
  }
  return v / 6.0;
}

void RegionVolumeGradient(std::span<const glm::dvec3> positions,
                          std::span<const glm::uvec3> triangles, std::span<const int> subset,
                          const glm::dvec3& centre, std::span<glm::dvec3> gradient) {
  std::fill(gradient.begin(), gradient.end(), glm::dvec3(0.0));
  for (int t : subset) {
    const glm::uvec3& tri = triangles[static_cast<std::size_t>(t)];
    const glm::dvec3 a = positions[tri.x] - centre, b = positions[tri.y] - centre,
                     c = positions[tri.z] - centre;
    gradient[tri.x] += glm::cross(b, c) / 6.0;  // the triple product is cyclic
    gradient[tri.y] += glm::cross(c, a) / 6.0;
    gradient[tri.z] += glm::cross(a, b) / 6.0;
  }
}

base::Result<CorrectedExample> CorrectExample(const PatchSetup& patch, const SkinnedMesh& mesh,
                                              const SkinningPose& pose, CorrectiveKind kind,
                                              const CorrectiveOptions& options) {
  const std::size_t num_skin = mesh.skin_joints.size();
  if (pose.model_from_bind.size() != num_skin ||
      (!pose.dual_quats.empty() && pose.dual_quats.size() != num_skin)) {
    return InvalidArgument("example pose: expected palettes of " + std::to_string(num_skin) +
                           " skin joints, found " + std::to_string(pose.model_from_bind.size()));
  }
  if (options.iterations < 1 || options.iterations > 20)
    return InvalidArgument("expected 1..20 iterations");
  if (patch.region.empty() || patch.num_bound() == 0)
    return InvalidArgument("the patch binds no vertex");
  const int nc = patch.num_control();
  const int nu = patch.fit.surface.num_u(), nv = patch.fit.surface.num_v();
  if (!options.free_mask.empty() && options.free_mask.size() != static_cast<std::size_t>(nc)) {
    return InvalidArgument("expected a free mask of " + std::to_string(nc) + " entries");
  }
  std::vector<int> free_index;
  const int nf = internal::FreeIndex(nu, nv, options.free_mask, free_index);
  if (nf == 0) return InvalidArgument("expected at least one free control point, found none");

  // G: skinned vertices and carried control points at the pose.
  const auto num_v = static_cast<std::size_t>(mesh.bind.num_vertices());
  std::vector<glm::vec3> skinned(num_v);
  base::JobStatus s = SkinPoints(pose, mesh.weights, mesh.bind.positions, {}, 0,
                                 mesh.bind.num_vertices(), skinned, {});
  if (!s) return InvalidArgument(s.what);
  std::vector<glm::vec3> carried(static_cast<std::size_t>(nc));
  s = CarryControlPointsJob{.patch = &patch, .pose = pose, .control = carried}.Run();
  if (!s) return InvalidArgument(s.what);
  BSplineSurface base = patch.fit.surface;
  for (int c = 0; c < nc; ++c) {
    base.mutable_control()[static_cast<std::size_t>(c)] = glm::dvec3(carried[static_cast<std::size_t>(c)]);
  }
  std::vector<glm::dvec3> global(skinned.begin(), skinned.end());

  // The bound vertices' linearisations.
  const PatchBinding& binding = patch.bound.binding;
  std::vector<BoundRow> rows(binding.vertex.size());
  for (std::size_t b = 0; b < rows.size(); ++b) {
    BoundRow& r = rows[b];
    r = {.vertex = binding.vertex[b], .u = binding.u[b], .v = binding.v[b], .d = binding.d[b],
         .beta = patch.border_weight.empty() ? 1.0 : patch.border_weight[b], .free = {},
         .reference = glm::dvec3(0.0)};
    const std::vector<double> a = SurfacePointWeights(base, r.u, r.v);
    for (std::size_t c = 0; c < a.size(); ++c) {
      if (a[c] != 0.0 && free_index[c] >= 0) r.free.emplace_back(free_index[c], a[c]);
    }
    r.reference = PatchPoint(base, r);
  }

  // The driving bone: its palette matrix and joint centre.
  CorrectedExample out;
  out.driving_skin_joint = DrivingSkinJoint(patch, static_cast<int>(num_skin));
  if (out.driving_skin_joint < 0)
    return InvalidArgument("no skin joint weights the patch's control points");
  const auto drv = static_cast<std::size_t>(out.driving_skin_joint);
  const glm::dmat4 carry(pose.model_from_bind[drv]);
  const glm::dvec3 centre_bind(glm::inverse(glm::dmat4(mesh.joint_from_bind[drv]))[3]);
  const glm::dvec3 centre(carry * glm::dvec4(centre_bind, 1.0));

  std::vector<glm::dvec3> delta(static_cast<std::size_t>(nc), glm::dvec3(0.0));
  std::vector<glm::dvec3> x;
  PosedRegion(base, delta, rows, global, x);
  std::vector<Triplet> entries;
  Eigen::SimplicialLDLT<SparseMatrix> ldlt;
  auto factor = [&](int n) -> bool {
    SparseMatrix m(n, n);
    m.setFromTriplets(entries.begin(), entries.end());
    ldlt.compute(m);
    return ldlt.info() == Eigen::Success;
  };
  auto add_step = [&](const Eigen::MatrixXd& step) {
    for (std::size_t c = 0; c < delta.size(); ++c) {
      const int f = free_index[c];
      if (f >= 0) delta[c] += glm::dvec3(step(f, 0), step(f, 1), step(f, 2));
    }
    PosedRegion(base, delta, rows, global, x);
  };

  if (kind == CorrectiveKind::kRest) {
    std::vector<glm::dvec3> target(rows.size());
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const int v = rows[k].vertex;
      const glm::dvec3 p(mesh.bind.positions[static_cast<std::size_t>(v)]);
      const glm::dmat4 bone(pose.model_from_bind[static_cast<std::size_t>(DominantSkinJoint(mesh.weights, v))]);
      target[k] = glm::dvec3(bone * glm::dvec4(p, 1.0));
    }
    const double w = 1.0 / static_cast<double>(rows.size());
    for (const BoundRow& r : rows) {
      for (const auto& [fa, aa] : r.free) {
        for (const auto& [fb, ab] : r.free) entries.emplace_back(fa, fb, w * r.beta * r.beta * aa * ab);
      }
    }
    internal::AddSecondDifferences(nu, nv, free_index, options.smoothness / nf, entries);
    for (int f = 0; f < nf; ++f) entries.emplace_back(f, f, 1e-9 * w);  // untouched points stay
    if (!factor(nf)) return base::MakeError(ErrorCode::kInternal, {}, "rest fit: not definite");
    out.report.before = RmsToTargets(rows, x, target);
    for (int it = 0; it < options.iterations; ++it) {
      Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(nf, 3);
      for (std::size_t k = 0; k < rows.size(); ++k) {
        const glm::dvec3 miss = target[k] - x[static_cast<std::size_t>(rows[k].vertex)];
        for (const auto& [f, a] : rows[k].free) {
          for (int d = 0; d < 3; ++d) rhs(f, d) += w * rows[k].beta * a * miss[d];
        }
      }
      add_step(ldlt.solve(rhs));
    }
    out.report.after = RmsToTargets(rows, x, target);
  } else {
    const std::vector<int> tris = RegionTriangles(mesh.bind.triangles, patch.region, mesh.bind.num_vertices());
    std::vector<glm::dvec3> bind_pos(mesh.bind.positions.begin(), mesh.bind.positions.end());
    out.report.bind_value = RegionVolume(bind_pos, mesh.bind.triangles, tris, centre_bind);
    out.report.before = RegionVolume(x, mesh.bind.triangles, tris, centre);
    for (int f = 0; f < nf; ++f) entries.emplace_back(f, f, 1.0);
    internal::AddSecondDifferences(nu, nv, free_index, options.volume_smoothness, entries);
    if (!factor(nf)) return base::MakeError(ErrorCode::kInternal, {}, "volume fit: not definite");
    std::vector<glm::dvec3> grad(num_v);
    for (int it = 0; it < options.iterations; ++it) {
      const double miss = out.report.bind_value - RegionVolume(x, mesh.bind.triangles, tris, centre);
      RegionVolumeGradient(x, mesh.bind.triangles, tris, centre, grad);
      Eigen::MatrixXd g = Eigen::MatrixXd::Zero(nf, 3);
      for (const BoundRow& r : rows) {
        const glm::dvec3 gv = grad[static_cast<std::size_t>(r.vertex)] * r.beta;
        for (const auto& [f, a] : r.free) {
          for (int d = 0; d < 3; ++d) g(f, d) += a * gv[d];
        }
      }
      const Eigen::MatrixXd z = ldlt.solve(g);
      const double gz = (g.array() * z.array()).sum();
      if (!(gz > 0.0))
        return InvalidArgument("the region's volume does not depend on its free control points");
      add_step(z * (miss / gz));
    }
    out.report.after = RegionVolume(x, mesh.bind.triangles, tris, centre);
  }

  out.shape.world_delta = delta;
  std::vector<glm::quat> rotations(static_cast<std::size_t>(nc));
  s = PatchControlRotations(patch, pose, rotations);
  if (!s) return InvalidArgument(s.what);
  out.shape.displacement.resize(static_cast<std::size_t>(nc));
  const std::vector<glm::vec3> zero(static_cast<std::size_t>(nc), glm::vec3(0.0f));
  s = StoreExampleDisplacement(rotations, zero, out.shape.world_delta, out.shape.displacement);
  if (!s) return base::MakeError(ErrorCode::kInternal, {}, s.what);
  return out;
}

}  // namespace deform
