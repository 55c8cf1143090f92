#include "deform/shapes/direct_manipulation.h"
#include "deform/internal/checks.h"

#include <algorithm>
#include <cstddef>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <string>

namespace deform {
namespace {

using base::ErrorCode;
using base::JobStatus;

size_t NumControl(const BSplineSurface& s) {
  return static_cast<size_t>(s.num_u()) * static_cast<size_t>(s.num_v());
}

// Default free mask: everything but the boundary ring.
std::vector<std::uint8_t> InteriorMask(int m, int n) {
  std::vector<std::uint8_t> mask(static_cast<size_t>(m) * static_cast<size_t>(n), 0);
  for (int i = 1; i + 1 < m; ++i) {
    for (int j = 1; j + 1 < n; ++j) mask[static_cast<size_t>(i * n + j)] = 1;
  }
  return mask;
}

double PatchScale(const BSplineSurface& s) {
  const double diag = s.ControlDiagonal();
  return diag > 0.0 ? diag : 1.0;
}

// Grid Laplacian over the free points (|F| x |F|): row of free point (i,j) is
// deg * x_ij - sum of its free 4-neighbours; fixed neighbours count as zeros.
cv::Mat FreeLaplacian(int m, int n, const std::vector<int>& free_index) {
  const int nf = static_cast<int>(
      std::count_if(free_index.begin(), free_index.end(), [](int k) { return k >= 0; }));
  cv::Mat lap = cv::Mat::zeros(nf, nf, CV_64F);
  const int di[4] = {-1, 1, 0, 0}, dj[4] = {0, 0, -1, 1};
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < n; ++j) {
      const int row = free_index[static_cast<size_t>(i * n + j)];
      if (row < 0) continue;
      for (int k = 0; k < 4; ++k) {
        const int ii = i + di[k], jj = j + dj[k];
        if (ii < 0 || ii >= m || jj < 0 || jj >= n) continue;
        lap.at<double>(row, row) += 1.0;
        const int col = free_index[static_cast<size_t>(ii * n + jj)];
        if (col >= 0) lap.at<double>(row, col) -= 1.0;
      }
    }
  }
  return lap;
}

using internal::InvalidArgument;

// 3x3 determinant helper in double.
double Det(const glm::dmat3& m) { return glm::determinant(m); }

// Polar rotation through OpenCV's SVD (any determinant).
glm::dmat3 PolarBySvd(const glm::dmat3& m) {
  cv::Mat a(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) a.at<double>(r, c) = m[c][r];  // glm is column-major
  }
  cv::SVD svd(a, cv::SVD::FULL_UV);
  cv::Mat u = svd.u.clone();
  if (cv::determinant(u * svd.vt) < 0.0) u.col(2) *= -1.0;  // nearest proper rotation
  const cv::Mat rot = u * svd.vt;
  glm::dmat3 out(1.0);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out[c][r] = rot.at<double>(r, c);
  }
  return out;
}

}  // namespace

std::vector<double> SurfaceRowWeights(const BSplineSurface& surface, double u, double v,
                                      ConstraintKind kind) {
  std::vector<double> a(NumControl(surface), 0.0);
  const int p = surface.degree_u(), q = surface.degree_v();
  u = std::clamp(u, 0.0, 1.0);
  v = std::clamp(v, 0.0, 1.0);
  const int ku = FindSpan(surface.knots_u(), surface.num_u(), p, u);
  const int kv = FindSpan(surface.knots_v(), surface.num_v(), q, v);
  const BasisDerivs bu = BasisFunsDerivs(surface.knots_u(), ku, p, u, 1);
  const BasisDerivs bv = BasisFunsDerivs(surface.knots_v(), kv, q, v, 1);
  const int du = kind == ConstraintKind::kTangentU ? 1 : 0;  // derivative order along u
  const int dv = kind == ConstraintKind::kTangentV ? 1 : 0;
  for (int a_i = 0; a_i <= p; ++a_i) {
    for (int b_j = 0; b_j <= q; ++b_j) {
      const int i = ku - p + a_i, j = kv - q + b_j;
      a[static_cast<size_t>(i) * static_cast<size_t>(surface.num_v()) + static_cast<size_t>(j)] =
          bu.ders[du][a_i] * bv.ders[dv][b_j];
    }
  }
  return a;
}

std::vector<double> SurfacePointWeights(const BSplineSurface& surface, double u, double v) {
  return SurfaceRowWeights(surface, u, v, ConstraintKind::kPosition);
}

glm::dvec3 ConstrainedValue(const BSplineSurface& surface, double u, double v,
                            ConstraintKind kind) {
  if (kind == ConstraintKind::kPosition) return surface.Evaluate(u, v);
  const SurfaceDerivs d = surface.EvaluateDerivs(u, v, 1);
  return kind == ConstraintKind::kTangentU ? d.su : d.sv;
}

std::vector<glm::dvec3> MoveSurfacePointMinNorm(const BSplineSurface& surface, double u, double v,
                                                const glm::dvec3& delta) {
  const std::vector<double> a = SurfacePointWeights(surface, u, v);
  double sum_sq = 0.0;
  for (double x : a) sum_sq += x * x;  // > 0: the weights sum to 1
  std::vector<glm::dvec3> dq(a.size());
  for (size_t c = 0; c < a.size(); ++c) dq[c] = (a[c] / sum_sq) * delta;
  return dq;
}

PointConstraint KeepHere(const BSplineSurface& surface, double u, double v) {
  return {.u = u, .v = v, .target = surface.Evaluate(u, v)};
}

base::Result<ManipulationResult> SolvePointConstraints(const BSplineSurface& surface,
                                                       std::span<const PointConstraint> constraints,
                                                       const ManipulationOptions& options) {
  const size_t num_c = NumControl(surface);
  if (constraints.empty()) return InvalidArgument("expected at least one constraint, found none");
  for (size_t r = 0; r < constraints.size(); ++r) {
    const PointConstraint& k = constraints[r];
    if (!(k.u >= 0.0 && k.u <= 1.0 && k.v >= 0.0 && k.v <= 1.0)) {
      return InvalidArgument("constraint " + std::to_string(r) +
                             ": expected (u,v) in [0,1]^2, found (" + std::to_string(k.u) + ", " +
                             std::to_string(k.v) + ")");
    }
    if (!std::isfinite(k.target.x) || !std::isfinite(k.target.y) || !std::isfinite(k.target.z)) {
      return InvalidArgument("constraint " + std::to_string(r) + ": expected a finite target");
    }
  }
  if (!(options.laplacian_mu >= 0.0)) return InvalidArgument("expected laplacian_mu >= 0");
  if (!options.free_mask.empty() && options.free_mask.size() != num_c) {
    return InvalidArgument("expected a free mask of " + std::to_string(num_c) + " entries, found " +
                           std::to_string(options.free_mask.size()));
  }
  const std::vector<std::uint8_t> mask = options.free_mask.empty()
                                             ? InteriorMask(surface.num_u(), surface.num_v())
                                             : options.free_mask;
  std::vector<int> free_index(num_c, -1);
  std::vector<size_t> free_list;
  for (size_t c = 0; c < num_c; ++c) {
    if (mask[c] != 0) {
      free_index[c] = static_cast<int>(free_list.size());
      free_list.push_back(c);
    }
  }
  if (free_list.empty())
    return InvalidArgument("expected at least one free control point, the mask has none");

  const int nc = static_cast<int>(constraints.size());
  const int nf = static_cast<int>(free_list.size());
  std::vector<std::vector<double>> rows(constraints.size());
  cv::Mat a_mat(nc, nf, CV_64F), rhs(nc, 3, CV_64F);
  for (int r = 0; r < nc; ++r) {
    const PointConstraint& k = constraints[static_cast<size_t>(r)];
    rows[static_cast<size_t>(r)] = SurfaceRowWeights(surface, k.u, k.v, k.kind);
    for (int f = 0; f < nf; ++f)
      a_mat.at<double>(r, f) = rows[static_cast<size_t>(r)][free_list[static_cast<size_t>(f)]];
    const glm::dvec3 res = k.target - ConstrainedValue(surface, k.u, k.v, k.kind);
    for (int x = 0; x < 3; ++x) rhs.at<double>(r, x) = res[x];
  }

  ManipulationResult out;
  out.delta.assign(num_c, glm::dvec3(0.0));
  try {
    cv::Mat x_mat;  // H^-1 A^T, |F| x c
    if (options.spread == SpreadMode::kLaplacian && options.laplacian_mu > 0.0) {
      const cv::Mat lap = FreeLaplacian(surface.num_u(), surface.num_v(), free_index);
      const cv::Mat h = cv::Mat::eye(nf, nf, CV_64F) + options.laplacian_mu * (lap.t() * lap);
      cv::solve(h, a_mat.t(), x_mat, cv::DECOMP_CHOLESKY);  // H is symmetric positive definite
    } else {
      x_mat = a_mat.t();
    }
    const cv::Mat s_mat = a_mat * x_mat;  // A H^-1 A^T, c x c
    cv::SVD svd(s_mat, cv::SVD::FULL_UV);
    const double s_max = svd.w.at<double>(0), s_min = svd.w.at<double>(nc - 1);
    out.condition = s_min > 0.0 ? s_max / s_min : std::numeric_limits<double>::infinity();
    cv::Mat y_mat;  // (A H^-1 A^T + lam I)^-1 R, c x 3
    if (options.solve == ConstraintSolve::kSvd) {
      cv::Mat winv = cv::Mat::zeros(nc, nc, CV_64F);
      for (int k = 0; k < nc; ++k) {
        const double w = svd.w.at<double>(k);
        if (w > 1e-12 * s_max) winv.at<double>(k, k) = 1.0 / w;
      }
      y_mat = svd.vt.t() * winv * svd.u.t() * rhs;
    } else {
      if (!(out.condition <= options.max_condition)) {
        out.lambda = 1e-9 * cv::trace(s_mat)[0] / nc;
      }
      const cv::Mat reg = s_mat + out.lambda * cv::Mat::eye(nc, nc, CV_64F);
      cv::solve(reg, rhs, y_mat, cv::DECOMP_LU);
    }
    const cv::Mat dq = x_mat * y_mat;  // |F| x 3
    for (int f = 0; f < nf; ++f) {
      out.delta[free_list[static_cast<size_t>(f)]] =
          glm::dvec3(dq.at<double>(f, 0), dq.at<double>(f, 1), dq.at<double>(f, 2));
    }
  } catch (const cv::Exception& e) {
    return base::MakeError(ErrorCode::kInternal, {},
                           std::string("constraint solve failed: ") + e.what());
  }

  const double tol = options.satisfied_tol_rel * PatchScale(surface);
  out.residual.resize(constraints.size());
  for (size_t r = 0; r < constraints.size(); ++r) {
    const PointConstraint& k = constraints[r];
    glm::dvec3 moved = ConstrainedValue(surface, k.u, k.v, k.kind);
    for (size_t c = 0; c < num_c; ++c) moved += rows[r][c] * out.delta[c];
    out.residual[r] = glm::length(k.target - moved);
    if (out.residual[r] > tol) out.unsatisfied.push_back(static_cast<int>(r));
  }
  return out;
}

base::Result<VertexEdit> MakeVertexEdit(const PatchBinding& binding, int mesh_vertex,
                                        const glm::dvec3& delta) {
  for (size_t b = 0; b < binding.size(); ++b) {
    if (binding.vertex[b] == mesh_vertex) {
      return VertexEdit{.u = binding.u[b], .v = binding.v[b], .d = binding.d[b], .delta = delta};
    }
  }
  return base::MakeError(ErrorCode::kNotFound, {},
                         "vertex " + std::to_string(mesh_vertex) + " is not bound to this patch");
}

base::Result<ManipulationResult> MoveBoundVertices(const BSplineSurface& surface,
                                                   std::span<const VertexEdit> edits,
                                                   const ManipulationOptions& options,
                                                   int iterations,
                                                   std::span<const PointConstraint> keep) {
  if (edits.empty()) return InvalidArgument("expected at least one vertex edit, found none");
  if (iterations < 0 || iterations > 100) return InvalidArgument("expected 0..100 iterations");
  BSplineSurface moved = surface;
  const size_t num_c = NumControl(surface);
  std::vector<glm::dvec3> goal(edits.size());
  std::vector<PointConstraint> cons(edits.size());
  for (size_t e = 0; e < edits.size(); ++e) {
    const VertexEdit& ed = edits[e];
    const glm::dvec3 s = surface.Evaluate(ed.u, ed.v);
    goal[e] = s + ed.d * surface.Normal(ed.u, ed.v) + ed.delta;  // p + D
    cons[e] = {.u = ed.u, .v = ed.v, .target = s + ed.delta};
  }
  cons.insert(cons.end(), keep.begin(), keep.end());

  ManipulationResult total;
  total.delta.assign(num_c, glm::dvec3(0.0));
  const double tol = options.satisfied_tol_rel * PatchScale(surface);
  for (int it = 0; it <= iterations; ++it) {
    auto step = SolvePointConstraints(moved, cons, options);
    if (!step.ok()) return std::move(step).error();
    for (size_t c = 0; c < num_c; ++c) {
      total.delta[c] += step->delta[c];
      moved.mutable_control()[c] += step->delta[c];
    }
    total.condition = step->condition;
    total.lambda = step->lambda;
    // Residual on the vertices; next round aims the surface point past it.
    total.residual.assign(cons.size(), 0.0);
    double worst = 0.0;
    for (size_t e = 0; e < edits.size(); ++e) {
      const glm::dvec3 s = moved.Evaluate(edits[e].u, edits[e].v);
      const glm::dvec3 r = goal[e] - (s + edits[e].d * moved.Normal(edits[e].u, edits[e].v));
      total.residual[e] = glm::length(r);
      worst = std::max(worst, total.residual[e]);
      cons[e].target = s + r;
    }
    for (size_t k = edits.size(); k < cons.size(); ++k) total.residual[k] = step->residual[k];
    if (worst <= tol) break;
  }
  for (size_t r = 0; r < total.residual.size(); ++r) {
    if (total.residual[r] > tol) total.unsatisfied.push_back(static_cast<int>(r));
  }
  return total;
}

glm::dmat3 PolarRotation(const glm::dmat3& m) {
  // Newton iteration X <- (X + X^-T) / 2 converges quadratically to the polar
  // factor when det > 0; no allocation, so it also serves per frame.
  if (Det(m) > 1e-12) {
    glm::dmat3 x = m;
    for (int it = 0; it < 30; ++it) {
      const glm::dmat3 next = 0.5 * (x + glm::transpose(glm::inverse(x)));
      double diff = 0.0;
      for (int c = 0; c < 3; ++c) diff += glm::dot(next[c] - x[c], next[c] - x[c]);
      x = next;
      if (diff < 1e-28) return x;
    }
  }
  return PolarBySvd(m);
}

glm::dmat3 PolarRotationSvd(const glm::dmat3& m) { return PolarBySvd(m); }

JobStatus SsdControlRotations(std::span<const glm::mat4> model_from_bind, int influences,
                              std::span<const std::uint16_t> joint_indices,
                              std::span<const float> joint_weights,
                              std::span<glm::quat> rotations) {
  if (influences < 1 || influences > 8) return {JobStatus::kOutOfRange, "influences out of 1..8"};
  const size_t count = rotations.size() * static_cast<size_t>(influences);
  if (joint_indices.size() != count || joint_weights.size() != count) {
    return {JobStatus::kSizeMismatch, "joint arrays must be #C x influences"};
  }
  if (model_from_bind.empty() && !rotations.empty())
    return {JobStatus::kMissingInput, "empty palette"};
  for (size_t c = 0; c < rotations.size(); ++c) {
    glm::dmat3 blend(0.0);
    for (int k = 0; k < influences; ++k) {
      const size_t slot = c * static_cast<size_t>(influences) + static_cast<size_t>(k);
      blend += static_cast<double>(joint_weights[slot]) *
               glm::dmat3(glm::mat3(model_from_bind[joint_indices[slot]]));
    }
    rotations[c] = glm::normalize(glm::quat(glm::quat_cast(PolarRotation(blend))));
  }
  return base::kJobOk;
}

JobStatus DqsControlRotations(std::span<const DualQuat> palette, int influences,
                              std::span<const std::uint16_t> joint_indices,
                              std::span<const float> joint_weights,
                              std::span<glm::quat> rotations) {
  if (influences < 1 || influences > 8) return {JobStatus::kOutOfRange, "influences out of 1..8"};
  const size_t count = rotations.size() * static_cast<size_t>(influences);
  if (joint_indices.size() != count || joint_weights.size() != count) {
    return {JobStatus::kSizeMismatch, "joint arrays must be #C x influences"};
  }
  if (palette.empty() && !rotations.empty()) return {JobStatus::kMissingInput, "empty palette"};
  for (size_t c = 0; c < rotations.size(); ++c) {
    const size_t base = c * static_cast<size_t>(influences);
    size_t best = base;
    for (int k = 1; k < influences; ++k) {
      if (joint_weights[base + static_cast<size_t>(k)] > joint_weights[best])
        best = base + static_cast<size_t>(k);
    }
    const glm::quat pivot = palette[joint_indices[best]].real;
    glm::dquat sum(0.0, 0.0, 0.0, 0.0);
    for (int k = 0; k < influences; ++k) {
      const size_t slot = base + static_cast<size_t>(k);
      const glm::quat r = palette[joint_indices[slot]].real;
      const double sign = glm::dot(r, pivot) < 0.0f ? -1.0 : 1.0;
      sum += (sign * static_cast<double>(joint_weights[slot])) * glm::dquat(r);
    }
    const double len = glm::length(sum);
    rotations[c] = len > 1e-12 ? glm::quat(sum / len) : glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
  }
  return base::kJobOk;
}

JobStatus StoreExampleDisplacement(std::span<const glm::quat> rotations,
                                   std::span<const glm::vec3> current_ds,
                                   std::span<const glm::dvec3> world_delta,
                                   std::span<glm::vec3> example) {
  if (current_ds.size() != rotations.size() || world_delta.size() != rotations.size() ||
      example.size() != rotations.size()) {
    return {JobStatus::kSizeMismatch, "rotations, current_ds, world_delta and example must be #C"};
  }
  for (size_t c = 0; c < rotations.size(); ++c) {
    const glm::dquat a(rotations[c]);
    example[c] = glm::vec3(glm::dvec3(current_ds[c]) + glm::inverse(a) * world_delta[c]);
  }
  return base::kJobOk;
}

JobStatus PoseSpaceApplyJob::Validate() const {
  if (rotations.size() != global.size() || displacement.size() != global.size() ||
      control.size() != global.size()) {
    return {JobStatus::kSizeMismatch, "global, rotations, displacement and control must be #C"};
  }
  return base::kJobOk;
}

JobStatus PoseSpaceApplyJob::Run() const {
  const JobStatus status = Validate();
  if (!status.ok()) return status;
  // Where dS is exactly zero (control points no example moves) A dS is zero:
  // Q = G, without the rotation.
  for (std::size_t c = 0; c < global.size(); ++c) {
    control[c] = displacement[c] == glm::vec3(0.0f) ? global[c]
                                                     : global[c] + rotations[c] * displacement[c];
  }
  return base::kJobOk;
}

}  // namespace deform
