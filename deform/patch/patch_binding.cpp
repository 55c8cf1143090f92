#include "deform/patch/patch_binding.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

namespace deform {
namespace {

using base::ErrorCode;
using base::MakeError;

// Knot constants of every span of one direction, kSpanTableStride floats per
// span k (row k-3): u_{k-1}, u_k, u_{k+1}, u_{k+2}, then with
// r1 = 1/(u_{k+1}-u_k), r2a = 1/(u_{k+1}-u_{k-1}), r2b = 1/(u_{k+2}-u_k):
// 3 r1 r2a/(u_{k+1}-u_{k-2}), 3 r1 r2a/(u_{k+2}-u_{k-1}), 3 r1 r2b/(u_{k+2}-u_{k-1}),
// 3 r1 r2b/(u_{k+3}-u_k) (used by DerivBasis in patch_rebuild.cpp). Every
// denominator contains the span itself, so it is positive for the non-empty
// spans records use; empty spans get zeros.
std::vector<float> MakeSpanTable(const std::vector<double>& U, int num_control) {
  std::vector<float> table(static_cast<size_t>(num_control - 3) * kSpanTableStride, 0.0f);
  for (int k = 3; k < num_control; ++k) {
    auto kn = [&](int i) { return U[static_cast<size_t>(i)]; };
    if (!(kn(k + 1) > kn(k))) continue;
    const double r1 = 1.0 / (kn(k + 1) - kn(k));
    const double r2a = 1.0 / (kn(k + 1) - kn(k - 1)), r2b = 1.0 / (kn(k + 2) - kn(k));
    const double g0 = 3.0 / (kn(k + 1) - kn(k - 2)), g1 = 3.0 / (kn(k + 2) - kn(k - 1));
    const double g2 = 3.0 / (kn(k + 3) - kn(k));
    const double vals[kSpanTableStride] = {kn(k - 1),      kn(k),          kn(k + 1),
                                           kn(k + 2),      g0 * r1 * r2a,  g1 * r1 * r2a,
                                           g1 * r1 * r2b,  g2 * r1 * r2b};
    for (int c = 0; c < kSpanTableStride; ++c) {
      table[static_cast<size_t>(k - 3) * kSpanTableStride + static_cast<size_t>(c)] =
          static_cast<float>(vals[c]);
    }
  }
  return table;
}

// One bound vertex before it is packed into the structure of arrays.
struct BindingRecord {
  int vertex;
  double u, v, d;
};

// Packs records: spans, basis values, span tables, sorted by span (stable,
// so records of one span keep their order).
PatchBinding MakeBinding(const BSplineSurface& surface, const std::vector<BindingRecord>& records) {
  const auto& ku = surface.knots_u();
  const auto& kv = surface.knots_v();
  std::vector<std::uint16_t> first(records.size());
  for (size_t r = 0; r < records.size(); ++r) {
    const int k = FindSpan(ku, surface.num_u(), 3, records[r].u);
    const int l = FindSpan(kv, surface.num_v(), 3, records[r].v);
    first[r] = static_cast<std::uint16_t>((k - 3) | ((l - 3) << 8));
  }
  std::vector<size_t> order(records.size());
  for (size_t r = 0; r < order.size(); ++r) order[r] = r;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return first[a] < first[b]; });
  PatchBinding b;
  b.num_u = surface.num_u();
  b.num_v = surface.num_v();
  b.sigma = static_cast<float>(surface.sigma());
  b.span_table_u = MakeSpanTable(ku, b.num_u);
  b.span_table_v = MakeSpanTable(kv, b.num_v);
  for (size_t r : order) {
    const BindingRecord& rec = records[r];
    const int k = (first[r] & 0xff) + 3, l = (first[r] >> 8) + 3;
    double nu[4], nv[4];
    BasisFuns(ku, k, 3, rec.u, nu);
    BasisFuns(kv, l, 3, rec.v, nv);
    b.vertex.push_back(rec.vertex);
    b.u.push_back(static_cast<float>(rec.u));
    b.v.push_back(static_cast<float>(rec.v));
    b.d.push_back(static_cast<float>(rec.d));
    b.nu0.push_back(static_cast<float>(nu[0]));
    b.nu1.push_back(static_cast<float>(nu[1]));
    b.nu2.push_back(static_cast<float>(nu[2]));
    b.nv0.push_back(static_cast<float>(nv[0]));
    b.nv1.push_back(static_cast<float>(nv[1]));
    b.nv2.push_back(static_cast<float>(nv[2]));
    b.first.push_back(first[r]);
  }
  return b;
}

struct Eval {
  SurfaceDerivs sd;
  glm::dvec3 r{0.0};
  double dist = 0.0;
};

Eval EvalAt(const BSplineSurface& s, const glm::dvec3& p, double u, double v) {
  Eval e;
  e.sd = s.EvaluateDerivs(u, v, 2);
  e.r = e.sd.s - p;
  e.dist = glm::length(e.r);
  return e;
}

bool CosinesSmall(const Eval& e, double cos_tol) {
  const double f = glm::dot(e.r, e.sd.su), g = glm::dot(e.r, e.sd.sv);
  const double lu = glm::length(e.sd.su) * e.dist, lv = glm::length(e.sd.sv) * e.dist;
  return std::abs(f) <= cos_tol * lu && std::abs(g) <= cos_tol * lv;
}

}  // namespace

Projection ProjectFrom(const BSplineSurface& surface, const glm::dvec3& p, glm::dvec2 start,
                       const ProjectionOptions& options) {
  const double e1 = options.abs_tol_rel * surface.ControlDiagonal();
  double u = std::clamp(start.x, 0.0, 1.0), v = std::clamp(start.y, 0.0, 1.0);
  Eval e = EvalAt(surface, p, u, v);
  Projection out;
  for (int it = 0; it < options.max_iterations; ++it) {
    out.iterations = it;
    if (e.dist <= e1 || CosinesSmall(e, options.cos_tol)) break;
    const SurfaceDerivs& d = e.sd;
    const double f = glm::dot(e.r, d.su), g = glm::dot(e.r, d.sv);
    const double j11 = glm::dot(d.su, d.su) + glm::dot(e.r, d.suu);
    const double j12 = glm::dot(d.su, d.sv) + glm::dot(e.r, d.suv);
    const double j22 = glm::dot(d.sv, d.sv) + glm::dot(e.r, d.svv);
    // Levenberg-Marquardt scaling: never below the first fundamental form,
    // so large mu tends to a (decreasing) gradient step.
    const double s11 = std::max(std::abs(j11), glm::dot(d.su, d.su));
    const double s22 = std::max(std::abs(j22), glm::dot(d.sv, d.sv));
    bool accepted = false;
    double step_len = 0.0;
    for (double mu = 0.0; mu < 1e12; mu = mu == 0.0 ? 1e-3 : mu * 10.0) {
      const double a = j11 + mu * s11, c = j22 + mu * s22;
      const double det = a * c - j12 * j12;
      if (!(a > 0.0 && det > 0.0)) continue;  // not positive definite: damp more
      const double du = -(c * f - j12 * g) / det;
      const double dv = -(a * g - j12 * f) / det;
      const double nu = std::clamp(u + du, 0.0, 1.0), nv = std::clamp(v + dv, 0.0, 1.0);
      Eval ne = EvalAt(surface, p, nu, nv);
      if (ne.dist < e.dist || (ne.dist == e.dist && mu == 0.0)) {
        step_len = glm::length((nu - u) * d.su + (nv - v) * d.sv);
        u = nu;
        v = nv;
        e = ne;
        accepted = true;
        break;
      }
    }
    out.iterations = it + 1;
    if (!accepted || step_len <= e1) break;  // local minimum, or the step vanished
  }
  out.u = u;
  out.v = v;
  out.residual = e.dist;
  const glm::dvec3 c = glm::cross(e.sd.su, e.sd.sv);
  const double len = glm::length(c);
  const glm::dvec3 n = len > 0.0 ? (surface.sigma() / len) * c : glm::dvec3(0.0);
  out.d = glm::dot(p - e.sd.s, n);
  const bool clamped = u == 0.0 || u == 1.0 || v == 0.0 || v == 1.0;
  out.on_border = clamped && e.dist > e1 && !CosinesSmall(e, options.cos_tol);
  return out;
}

ProjectionGrid MakeProjectionGrid(const BSplineSurface& surface, int grid_per_span) {
  auto params = [&](const std::vector<double>& U) {
    std::vector<double> out;
    for (size_t i = 1; i < U.size(); ++i) {
      if (!(U[i] > U[i - 1])) continue;
      for (int k = 0; k < grid_per_span; ++k) out.push_back(U[i - 1] + (U[i] - U[i - 1]) * k / grid_per_span);
    }
    out.push_back(1.0);
    return out;
  };
  const std::vector<double> us = params(surface.knots_u()), vs = params(surface.knots_v());
  ProjectionGrid grid;
  for (double u : us) {
    for (double v : vs) {
      grid.uv.emplace_back(u, v);
      grid.points.push_back(surface.Evaluate(u, v));
    }
  }
  return grid;
}

Projection Project(const BSplineSurface& surface, const ProjectionGrid& grid, const glm::dvec3& p,
                   glm::dvec2 own_uv, const ProjectionOptions& options) {
  size_t best = 0;
  double best_d = 1e300;
  for (size_t g = 0; g < grid.points.size(); ++g) {
    const glm::dvec3 diff = grid.points[g] - p;
    const double dd = glm::dot(diff, diff);
    if (dd < best_d) {
      best_d = dd;
      best = g;
    }
  }
  Projection a = ProjectFrom(surface, p, grid.uv.empty() ? glm::dvec2(0.5) : grid.uv[best], options);
  if (own_uv.x >= 0.0 && own_uv.y >= 0.0) {
    Projection b = ProjectFrom(surface, p, own_uv, options);
    if (b.residual < a.residual) return b;
  }
  return a;
}

PatchBindingView PatchBindingView::Slice(size_t begin, size_t end) const {
  end = std::min(end, size());
  begin = std::min(begin, end);
  const size_t n = end - begin;
  PatchBindingView s = *this;
  s.u = u.subspan(begin, n);
  s.v = v.subspan(begin, n);
  s.d = d.subspan(begin, n);
  s.nu0 = nu0.subspan(begin, n);
  s.nu1 = nu1.subspan(begin, n);
  s.nu2 = nu2.subspan(begin, n);
  s.nv0 = nv0.subspan(begin, n);
  s.nv1 = nv1.subspan(begin, n);
  s.nv2 = nv2.subspan(begin, n);
  s.first = first.subspan(begin, n);
  return s;
}

PatchBindingView PatchBinding::view() const {
  return PatchBindingView{.num_u = num_u, .num_v = num_v, .sigma = sigma,
                          .span_table_u = span_table_u, .span_table_v = span_table_v,
                          .u = u, .v = v, .d = d, .nu0 = nu0, .nu1 = nu1, .nu2 = nu2,
                          .nv0 = nv0, .nv1 = nv1, .nv2 = nv2, .first = first};
}

base::Result<PatchBinding> RefreshBinding(const PatchBinding& binding,
                                          const BSplineSurface& refined) {
  if (refined.degree_u() != 3 || refined.degree_v() != 3 || refined.num_u() > 256 ||
      refined.num_v() > 256) {
    return MakeError(ErrorCode::kUnsupported, {}, "refresh binding: expected a bicubic patch of at most 256 x 256");
  }
  std::vector<BindingRecord> recs;
  recs.reserve(binding.size());
  for (size_t i = 0; i < binding.size(); ++i) {
    recs.push_back({binding.vertex[i], binding.u[i], binding.v[i], binding.d[i]});
  }
  return MakeBinding(refined, recs);
}

std::vector<glm::vec3> ControlPointsAsFloat(const BSplineSurface& surface) {
  std::vector<glm::vec3> out;
  out.reserve(surface.control().size());
  for (const glm::dvec3& q : surface.control()) out.emplace_back(q);
  return out;
}

base::Result<BindResult> BindPatch(const BSplineSurface& surface,
                                   std::span<const glm::vec3> positions,
                                   std::span<const int> region,
                                   std::span<const glm::dvec2> region_uv,
                                   const ProjectionOptions& options) {
  if (surface.degree_u() != 3 || surface.degree_v() != 3) {
    return MakeError(ErrorCode::kUnsupported, {}, "binding: expected a bicubic patch");
  }
  if (surface.num_u() < 4 || surface.num_v() < 4 || surface.num_u() > 256 || surface.num_v() > 256) {
    return base::InvalidArgument("binding: control grid must be 4..256 each way");
  }
  if (!region_uv.empty() && region_uv.size() != region.size()) {
    return base::InvalidArgument("binding: expected " + std::to_string(region.size()) +
                                 " region parameters, found " + std::to_string(region_uv.size()));
  }
  for (int vtx : region) {
    if (vtx < 0 || static_cast<size_t>(vtx) >= positions.size()) {
      return base::InvalidArgument("binding: vertex index " + std::to_string(vtx) +
                                   " out of range");
    }
  }
  BindResult result;
  BindingReport& report = result.report;
  report.patch_diagonal = surface.ControlDiagonal();
  const ProjectionGrid grid = MakeProjectionGrid(surface, std::max(1, options.grid_per_span));
  struct Record {
    int vertex;
    Projection proj;
  };
  std::vector<Record> records;
  for (size_t r = 0; r < region.size(); ++r) {
    const glm::dvec3 p(positions[static_cast<size_t>(region[r])]);
    const glm::dvec2 own = region_uv.empty() ? glm::dvec2(-1.0) : region_uv[r];
    const Projection proj = Project(surface, grid, p, own, options);
    if (proj.on_border) {
      report.border_vertices.push_back(region[r]);
      continue;
    }
    if (std::abs(proj.d) > options.far_rel * report.patch_diagonal) {
      report.far_vertices.push_back(region[r]);
      continue;
    }
    records.push_back({region[r], proj});
    report.max_abs_d = std::max(report.max_abs_d, std::abs(proj.d));
  }
  std::vector<BindingRecord> recs;
  recs.reserve(records.size());
  for (const Record& rec : records) {
    recs.push_back({rec.vertex, rec.proj.u, rec.proj.v, rec.proj.d});
  }
  PatchBinding& b = result.binding;
  b = MakeBinding(surface, recs);
  report.bound = static_cast<int>(b.size());
  // Rest check (3.5): rebuilding from the fitted control points gives p back.
  const std::vector<glm::vec3> control = ControlPointsAsFloat(surface);
  std::vector<glm::vec3> rebuilt(b.size());
  const PatchRebuildJob job{.control = control, .bindings = b.view(), .positions = rebuilt};
  if (const base::JobStatus st = job.Run(); !st) {
    return MakeError(ErrorCode::kInternal, {}, std::string("binding: rest rebuild failed: ") + st.what);
  }
  for (size_t i = 0; i < b.size(); ++i) {
    const double err = glm::length(glm::dvec3(rebuilt[i]) - glm::dvec3(positions[static_cast<size_t>(b.vertex[i])]));
    report.max_rest_error = std::max(report.max_rest_error, err);
  }
  return result;
}

}  // namespace deform
