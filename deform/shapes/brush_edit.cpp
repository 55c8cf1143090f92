#include "deform/shapes/brush_edit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include "deform/shapes/internal/control_grid.h"
#include "deform/internal/checks.h"

namespace deform {
namespace {

using Triplet = Eigen::Triplet<double>;

using internal::InvalidArgument;

using internal::Finite;

// The 16 (or (p+1)(q+1)) nonzero weights of s(u,v) with their control indices.
struct SparseRow {
  std::array<int, 64> index{};
  std::array<double, 64> weight{};
  int count = 0;
};

SparseRow RowAt(const BSplineSurface& s, double u, double v) {
  const int p = s.degree_u(), q = s.degree_v();
  const int ku = FindSpan(s.knots_u(), s.num_u(), p, u);
  const int kv = FindSpan(s.knots_v(), s.num_v(), q, v);
  std::array<double, 8> nu{}, nv{};
  BasisFuns(s.knots_u(), ku, p, u, std::span<double>(nu.data(), static_cast<std::size_t>(p + 1)));
  BasisFuns(s.knots_v(), kv, q, v, std::span<double>(nv.data(), static_cast<std::size_t>(q + 1)));
  SparseRow row;
  for (int a = 0; a <= p; ++a) {
    for (int b = 0; b <= q; ++b) {
      const double w = nu[static_cast<std::size_t>(a)] * nv[static_cast<std::size_t>(b)];
      if (w == 0.0 || row.count >= 64) continue;
      row.index[static_cast<std::size_t>(row.count)] = (ku - p + a) * s.num_v() + (kv - q + b);
      row.weight[static_cast<std::size_t>(row.count)] = w;
      ++row.count;
    }
  }
  return row;
}

// Adds weight * r^T r to the normal matrix for a row r over the free points.
void AddOuter(const SparseRow& row, const std::vector<int>& free_index, double weight,
              std::vector<Triplet>& entries) {
  for (int a = 0; a < row.count; ++a) {
    const int fa = free_index[static_cast<std::size_t>(row.index[static_cast<std::size_t>(a)])];
    if (fa < 0) continue;
    for (int b = 0; b < row.count; ++b) {
      const int fb = free_index[static_cast<std::size_t>(row.index[static_cast<std::size_t>(b)])];
      if (fb < 0) continue;
      entries.emplace_back(fa, fb,
                           weight * row.weight[static_cast<std::size_t>(a)] *
                               row.weight[static_cast<std::size_t>(b)]);
    }
  }
}

void AddRhs(const SparseRow& row, const std::vector<int>& free_index, double weight,
            const glm::dvec3& target, Eigen::MatrixXd& rhs) {
  for (int a = 0; a < row.count; ++a) {
    const int fa = free_index[static_cast<std::size_t>(row.index[static_cast<std::size_t>(a)])];
    if (fa < 0) continue;
    const double w = weight * row.weight[static_cast<std::size_t>(a)];
    for (int d = 0; d < 3; ++d) rhs(fa, d) += w * target[d];
  }
}

}  // namespace

double BrushFalloff(double x) {
  if (!(x < 1.0)) return 0.0;
  const double t = 1.0 - std::max(x, 0.0);
  return t * t * t * t * (4.0 * std::max(x, 0.0) + 1.0);
}

base::Result<ManipulationResult> SolveBrushStrokes(const BSplineSurface& surface,
                                                   std::span<const BrushStroke> strokes,
                                                   const BrushOptions& options) {
  const int nu = surface.num_u(), nv = surface.num_v();
  const auto num_c = static_cast<std::size_t>(nu) * static_cast<std::size_t>(nv);
  if (strokes.empty()) return InvalidArgument("expected at least one brush stroke, found none");
  for (std::size_t k = 0; k < strokes.size(); ++k) {
    const BrushStroke& b = strokes[k];
    const std::string which = "stroke " + std::to_string(k) + ": ";
    if (!(b.u >= 0.0 && b.u <= 1.0 && b.v >= 0.0 && b.v <= 1.0)) {
      return InvalidArgument(which + "expected a centre (u, v) in [0,1]^2");
    }
    if (!(b.radius >= 0.0) || !std::isfinite(b.radius)) {
      return InvalidArgument(which + "expected a finite radius >= 0");
    }
    if (!Finite(b.delta)) return InvalidArgument(which + "expected a finite move");
  }
  if (!(options.smoothness >= 0.0)) return InvalidArgument("expected smoothness >= 0");
  if (!options.free_mask.empty() && options.free_mask.size() != num_c) {
    return InvalidArgument("expected a free mask of " + std::to_string(num_c) + " entries, found " +
                           std::to_string(options.free_mask.size()));
  }
  std::vector<int> free_index;
  const int nf = internal::FreeIndex(nu, nv, options.free_mask, free_index);
  if (nf == 0) return InvalidArgument("expected at least one free control point, found none");

  // Field fit over an su x sv grid covering the whole domain, weight 1/S each.
  const int su = std::max(options.min_samples, 4 * nu);
  const int sv = std::max(options.min_samples, 4 * nv);
  const double w_data = 1.0 / (static_cast<double>(su) * sv);
  std::vector<Triplet> entries;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(nf, 3);
  for (int a = 0; a < su; ++a) {
    for (int b = 0; b < sv; ++b) {
      const double u = static_cast<double>(a) / (su - 1), v = static_cast<double>(b) / (sv - 1);
      glm::dvec3 field(0.0);
      for (const BrushStroke& s : strokes) {
        if (s.radius <= 0.0) continue;
        const double dist = std::hypot(u - s.u, v - s.v);
        field += BrushFalloff(dist / s.radius) * s.delta;
      }
      const SparseRow row = RowAt(surface, u, v);
      AddOuter(row, free_index, w_data, entries);
      AddRhs(row, free_index, w_data, field, rhs);
    }
  }
  internal::AddSecondDifferences(nu, nv, free_index, options.smoothness / nf, entries);
  Eigen::SparseMatrix<double> normal(nf, nf);
  normal.setFromTriplets(entries.begin(), entries.end());
  // The centres as heavy rows: 1e6 x the data term's mean diagonal.
  const double w_hard = 1e6 * normal.diagonal().mean();
  entries.clear();
  std::vector<SparseRow> centre_rows;
  for (const BrushStroke& s : strokes) {
    centre_rows.push_back(RowAt(surface, s.u, s.v));
    AddOuter(centre_rows.back(), free_index, w_hard, entries);
    AddRhs(centre_rows.back(), free_index, w_hard, s.delta, rhs);
  }
  // A tiny ridge keeps the factorisation definite when a free point is
  // touched by no sample (it then stays put).
  for (int f = 0; f < nf; ++f) entries.emplace_back(f, f, 1e-12 * w_hard);
  Eigen::SparseMatrix<double> extra(nf, nf);
  extra.setFromTriplets(entries.begin(), entries.end());
  normal += extra;

  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(normal);
  if (ldlt.info() != Eigen::Success) {
    return base::MakeError(base::ErrorCode::kInternal, {},
                           "brush: the normal matrix is not definite");
  }
  const Eigen::MatrixXd x = ldlt.solve(rhs);

  ManipulationResult out;
  out.delta.assign(num_c, glm::dvec3(0.0));
  for (std::size_t c = 0; c < num_c; ++c) {
    const int f = free_index[c];
    if (f >= 0) out.delta[c] = {x(f, 0), x(f, 1), x(f, 2)};
  }
  const double tol = options.satisfied_tol_rel * surface.ControlDiagonal();
  for (std::size_t k = 0; k < strokes.size(); ++k) {
    glm::dvec3 moved(0.0);
    const SparseRow& row = centre_rows[k];
    for (int a = 0; a < row.count; ++a) {
      moved += row.weight[static_cast<std::size_t>(a)] *
               out.delta[static_cast<std::size_t>(row.index[static_cast<std::size_t>(a)])];
    }
    const double r = glm::length(moved - strokes[k].delta);
    out.residual.push_back(r);
    if (r > tol) out.unsatisfied.push_back(static_cast<int>(k));
  }
  return out;
}

double MaxSecondDifference(std::span<const glm::dvec3> delta, int num_u, int num_v) {
  double worst = 0.0;
  auto at = [&](int i, int j) { return delta[static_cast<std::size_t>(i * num_v + j)]; };
  for (int i = 0; i < num_u; ++i) {
    for (int j = 0; j < num_v; ++j) {
      if (i > 0 && i + 1 < num_u) {
        worst = std::max(worst, glm::length(at(i - 1, j) - 2.0 * at(i, j) + at(i + 1, j)));
      }
      if (j > 0 && j + 1 < num_v) {
        worst = std::max(worst, glm::length(at(i, j - 1) - 2.0 * at(i, j) + at(i, j + 1)));
      }
    }
  }
  return worst;
}

}  // namespace deform
