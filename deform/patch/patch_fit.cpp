#include "deform/patch/patch_fit.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <unordered_map>

#include "deform/internal/dense_lu.h"
#include "deform/internal/checks.h"

namespace deform {
namespace {

using base::ErrorCode;
using base::MakeError;

using internal::InvalidArgument;

glm::dvec3 D(const glm::vec3& p) { return glm::dvec3(p); }

// Region triangles (all corners in the region) as region-local indices.
std::vector<glm::ivec3> RegionTriangles(std::span<const glm::uvec3> triangles,
                                        std::span<const int> region, size_t num_vertices) {
  std::unordered_map<unsigned, int> local;
  for (size_t r = 0; r < region.size(); ++r) local.emplace(static_cast<unsigned>(region[r]), static_cast<int>(r));
  std::vector<glm::ivec3> out;
  for (const glm::uvec3& t : triangles) {
    if (t.x >= num_vertices || t.y >= num_vertices || t.z >= num_vertices) continue;
    auto a = local.find(t.x), b = local.find(t.y), c = local.find(t.z);
    if (a == local.end() || b == local.end() || c == local.end()) continue;
    out.emplace_back(a->second, b->second, c->second);
  }
  return out;
}

base::Status CheckRegion(std::span<const glm::vec3> positions, std::span<const int> region) {
  if (region.size() < 3) {
    return InvalidArgument("patch region: expected at least 3 vertices, found " +
                           std::to_string(region.size()));
  }
  for (int v : region) {
    if (v < 0 || static_cast<size_t>(v) >= positions.size()) {
      return InvalidArgument("patch region: vertex index " + std::to_string(v) +
                             " out of range 0.." + std::to_string(positions.size()));
    }
  }
  return base::Status::Ok();
}

// Symmetric 3x3 eigen decomposition by cyclic Jacobi rotations; columns of
// `vecs` are eigenvectors, sorted by decreasing eigenvalue.
void SymmetricEigen(glm::dmat3 a, glm::dvec3& vals, glm::dmat3& vecs) {
  glm::dmat3 v(1.0);
  for (int sweep = 0; sweep < 50; ++sweep) {
    const double off = a[1][0] * a[1][0] + a[2][0] * a[2][0] + a[2][1] * a[2][1];
    if (off < 1e-30) break;
    for (int p = 0; p < 2; ++p) {
      for (int q = p + 1; q < 3; ++q) {
        if (std::abs(a[q][p]) < 1e-300) continue;
        const double theta = (a[q][q] - a[p][p]) / (2.0 * a[q][p]);
        const double t = (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
        const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
        glm::dmat3 r(1.0);
        r[p][p] = c;
        r[q][q] = c;
        r[q][p] = s;   // column q, row p
        r[p][q] = -s;  // column p, row q
        a = glm::transpose(r) * a * r;
        v = v * r;
      }
    }
  }
  int order[3] = {0, 1, 2};
  std::sort(order, order + 3, [&](int x, int y) { return a[x][x] > a[y][y]; });
  for (int i = 0; i < 3; ++i) {
    vals[i] = a[order[i]][order[i]];
    vecs[i] = v[order[i]];
  }
}

// Counts region triangles with non-positive signed area in (u,v).
int CountFolded(const std::vector<glm::ivec3>& tris, const std::vector<glm::dvec2>& uv) {
  int folded = 0;
  for (const glm::ivec3& t : tris) {
    const glm::dvec2 e1 = uv[t.y] - uv[t.x], e2 = uv[t.z] - uv[t.x];
    if (e1.x * e2.y - e1.y * e2.x <= 0.0) ++folded;
  }
  return folded;
}

// Normalizes raw (a,b) coordinates by their bounding box into [0,1]^2.
base::Status NormalizeUv(std::vector<glm::dvec2>& uv) {
  glm::dvec2 lo(1e300), hi(-1e300);
  for (const glm::dvec2& p : uv) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  const glm::dvec2 ext = hi - lo;
  if (!(ext.x > 0.0 && ext.y > 0.0)) {
    return MakeError(ErrorCode::kUnsupported, {}, "patch region: parameter domain is degenerate");
  }
  for (glm::dvec2& p : uv) p = (p - lo) / ext;
  return base::Status::Ok();
}

base::Status CheckOneToOne(const RegionParametrization& param, const std::vector<glm::ivec3>& tris,
                           const char* hint) {
  const int folded = CountFolded(tris, param.uv);
  if (folded > 0) {
    return MakeError(ErrorCode::kUnsupported, {},
                     "patch region: " + std::to_string(folded) + " of " +
                         std::to_string(tris.size()) +
                         " triangles fold over in the parameter domain; " + hint);
  }
  return base::Status::Ok();
}

// Area-weighted moments of the region: the normal sum, the centroid and the
// covariance integrated exactly over the triangles (for a triangle a,b,c
// about the centroid: A/12 (aa^T + bb^T + cc^T + ss^T), s = a+b+c), so the
// triangulation's diagonal direction does not tilt the axes. Without
// triangles, the vertices count equally.
struct RegionMoments {
  glm::dvec3 normal_sum{0.0};
  glm::dvec3 centroid{0.0};
  glm::dmat3 covariance{0.0};
};

RegionMoments Moments(std::span<const glm::vec3> positions, std::span<const int> region,
                      const std::vector<glm::ivec3>& tris) {
  RegionMoments m;
  auto pos = [&](int r) { return D(positions[static_cast<size_t>(region[static_cast<size_t>(r)])]); };
  double area = 0.0;
  for (const glm::ivec3& t : tris) {
    const glm::dvec3 n = glm::cross(pos(t.y) - pos(t.x), pos(t.z) - pos(t.x));
    m.normal_sum += n;
    const double a = 0.5 * glm::length(n);
    area += a;
    m.centroid += a * (pos(t.x) + pos(t.y) + pos(t.z)) / 3.0;
  }
  if (area > 0.0) {
    m.centroid /= area;
    for (const glm::ivec3& t : tris) {
      const glm::dvec3 a = pos(t.x) - m.centroid, b = pos(t.y) - m.centroid, c = pos(t.z) - m.centroid;
      const double ar = 0.5 * glm::length(glm::cross(b - a, c - a));
      const glm::dvec3 s = a + b + c;
      m.covariance += (ar / (12.0 * area)) * (glm::outerProduct(a, a) + glm::outerProduct(b, b) +
                                               glm::outerProduct(c, c) + glm::outerProduct(s, s));
    }
    return m;
  }
  for (size_t r = 0; r < region.size(); ++r) m.centroid += pos(static_cast<int>(r));
  m.centroid /= static_cast<double>(region.size());
  for (size_t r = 0; r < region.size(); ++r) {
    const glm::dvec3 d = pos(static_cast<int>(r)) - m.centroid;
    m.covariance += glm::outerProduct(d, d) / static_cast<double>(region.size());
  }
  return m;
}

// Knots for S parameters and M control points, degree p (3.4).
std::vector<double> FitKnots(const std::vector<double>& ub, int m, int p) {
  const int s = static_cast<int>(ub.size());
  std::vector<double> knots(static_cast<size_t>(m + p + 1), 0.0);
  for (int i = 0; i <= p; ++i) knots[static_cast<size_t>(m + i)] = 1.0;
  if (s == m) {  // averaging: u_{j+p} = mean of p consecutive parameters
    for (int j = 1; j <= m - p - 1; ++j) {
      double sum = 0.0;
      for (int i = j; i < j + p; ++i) sum += ub[static_cast<size_t>(i)];
      knots[static_cast<size_t>(j + p)] = sum / p;
    }
  } else {  // every span holds a parameter, so A^T A is nonsingular
    const double d = static_cast<double>(s) / (m - p);
    for (int j = 1; j <= m - p - 1; ++j) {
      const int i = static_cast<int>(std::floor(j * d));
      const double al = j * d - i;
      knots[static_cast<size_t>(j + p)] = (1.0 - al) * ub[static_cast<size_t>(i - 1)] + al * ub[static_cast<size_t>(i)];
    }
  }
  return knots;
}

// Solver for one direction: S parameters -> M control values.
struct DirectionFit {
  std::vector<double> knots;
  std::vector<double> basis;  // S x M
  internal::DenseLu lu;
  bool interpolating = false;
  int s = 0, m = 0;

  base::Status Setup(const std::vector<double>& params, int num_control, double smoothing) {
    const int p = 3;
    s = static_cast<int>(params.size());
    m = num_control;
    interpolating = s == m;
    knots = FitKnots(params, m, p);
    basis.assign(static_cast<size_t>(s) * m, 0.0);
    for (int k = 0; k < s; ++k) {
      const double u = params[static_cast<size_t>(k)];
      const int span = FindSpan(knots, m, p, u);
      double n[4];
      BasisFuns(knots, span, p, u, n);
      for (int a = 0; a < 4; ++a) basis[static_cast<size_t>(k) * m + (span - p + a)] = n[a];
    }
    std::vector<double> sys;
    if (interpolating) {
      sys = basis;
    } else {
      sys.assign(static_cast<size_t>(m) * m, 0.0);
      for (int r = 0; r < m; ++r) {
        for (int c = 0; c < m; ++c) {
          double sum = 0.0;
          for (int k = 0; k < s; ++k) sum += basis[static_cast<size_t>(k) * m + r] * basis[static_cast<size_t>(k) * m + c];
          sys[static_cast<size_t>(r) * m + c] = sum;
        }
      }
      if (smoothing > 0.0) {
        double trace = 0.0;
        for (int r = 0; r < m; ++r) trace += sys[static_cast<size_t>(r) * m + r];
        const double lambda = smoothing * trace / m;
        for (int i = 0; i + 2 < m; ++i) {  // D row i: (1, -2, 1) at i..i+2
          const double d[3] = {1.0, -2.0, 1.0};
          for (int a = 0; a < 3; ++a) {
            for (int b = 0; b < 3; ++b) sys[static_cast<size_t>(i + a) * m + (i + b)] += lambda * d[a] * d[b];
          }
        }
      }
    }
    if (!lu.Factor(std::move(sys), m)) {
      return MakeError(ErrorCode::kInternal, {}, "patch fit: singular system (too few distinct samples?)");
    }
    return base::Status::Ok();
  }

  // Fits S data values (stride-accessed) to M control values.
  void Fit(std::vector<glm::dvec3>& data_in_out) const {
    if (!interpolating) {
      std::vector<glm::dvec3> rhs(static_cast<size_t>(m), glm::dvec3(0.0));
      for (int r = 0; r < m; ++r) {
        for (int k = 0; k < s; ++k) rhs[static_cast<size_t>(r)] += basis[static_cast<size_t>(k) * m + r] * data_in_out[static_cast<size_t>(k)];
      }
      data_in_out = std::move(rhs);
    }
    lu.Solve(data_in_out);
  }
};

// Chord-length (or centripetal) parameters along the first index of a grid
// (count x other), averaged over the lines of nonzero length.
std::vector<double> ChordParameters(const std::vector<glm::dvec3>& pts, int count, int other,
                                    bool along_first, bool centripetal) {
  std::vector<double> out(static_cast<size_t>(count), 0.0);
  int lines = 0;
  for (int l = 0; l < other; ++l) {
    auto at = [&](int k) {
      return along_first ? pts[static_cast<size_t>(k) * other + l] : pts[static_cast<size_t>(l) * count + k];
    };
    std::vector<double> cum(static_cast<size_t>(count), 0.0);
    for (int k = 1; k < count; ++k) {
      double dist = glm::length(at(k) - at(k - 1));
      if (centripetal) dist = std::sqrt(dist);
      cum[static_cast<size_t>(k)] = cum[static_cast<size_t>(k - 1)] + dist;
    }
    const double total = cum.back();
    if (!(total > 0.0)) continue;
    ++lines;
    for (int k = 0; k < count; ++k) out[static_cast<size_t>(k)] += cum[static_cast<size_t>(k)] / total;
  }
  if (lines == 0) return UniformParameters(count);
  for (double& x : out) x /= lines;
  out.front() = 0.0;
  out.back() = 1.0;
  return out;
}

// Squared 2D distance from x to triangle abc and the barycentric weights of
// the closest point (0 and x's own weights when x is inside).
double ClosestInTriangle(const glm::dvec2& x, const glm::dvec2& a, const glm::dvec2& b,
                         const glm::dvec2& c, double w[3]) {
  const double det = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  if (det > 0.0) {
    const double wb = ((x.x - a.x) * (c.y - a.y) - (x.y - a.y) * (c.x - a.x)) / det;
    const double wc = ((b.x - a.x) * (x.y - a.y) - (b.y - a.y) * (x.x - a.x)) / det;
    const double wa = 1.0 - wb - wc;
    if (wa >= 0.0 && wb >= 0.0 && wc >= 0.0) {
      w[0] = wa;
      w[1] = wb;
      w[2] = wc;
      return 0.0;
    }
  }
  double best = 1e300;
  const glm::dvec2 pts[3] = {a, b, c};
  for (int e = 0; e < 3; ++e) {
    const glm::dvec2 p = pts[e], q = pts[(e + 1) % 3];
    const glm::dvec2 pq = q - p;
    const double len2 = glm::dot(pq, pq);
    const double t = len2 > 0.0 ? std::clamp(glm::dot(x - p, pq) / len2, 0.0, 1.0) : 0.0;
    const glm::dvec2 y = p + t * pq;
    const double d2 = glm::dot(x - y, x - y);
    if (d2 < best) {
      best = d2;
      w[e] = 1.0 - t;
      w[(e + 1) % 3] = t;
      w[(e + 2) % 3] = 0.0;
    }
  }
  return best;
}

base::Status CheckParameterList(std::span<const double> xs, const char* what) {
  if (xs.size() < 2)
    return InvalidArgument(std::string(what) + ": expected at least 2 sample parameters");
  for (size_t i = 0; i < xs.size(); ++i) {
    if (!(xs[i] >= 0.0 && xs[i] <= 1.0) || (i > 0 && !(xs[i] > xs[i - 1]))) {
      return InvalidArgument(std::string(what) + ": sample parameters must increase within [0,1]");
    }
  }
  return base::Status::Ok();
}

}  // namespace

std::vector<double> UniformParameters(int count) {
  std::vector<double> out(static_cast<size_t>(std::max(count, 0)));
  for (int k = 0; k < count; ++k) out[static_cast<size_t>(k)] = count > 1 ? static_cast<double>(k) / (count - 1) : 0.0;
  return out;
}

base::Result<RegionParametrization> ParametrizePlane(std::span<const glm::vec3> positions,
                                                     std::span<const int> region,
                                                     std::span<const glm::uvec3> triangles,
                                                     glm::dvec3 axis_hint) {
  if (base::Status st = CheckRegion(positions, region); !st) return st.error();
  const std::vector<glm::ivec3> tris = RegionTriangles(triangles, region, positions.size());
  RegionParametrization param;
  param.kind = RegionParametrization::Kind::kPlane;
  param.region.assign(region.begin(), region.end());
  param.region_triangles = static_cast<int>(tris.size());
  const RegionMoments mom = Moments(positions, region, tris);
  const glm::dvec3 normal_sum = mom.normal_sum, c = mom.centroid;
  const glm::dmat3 cov = mom.covariance;
  glm::dvec3 vals;
  glm::dmat3 vecs;
  SymmetricEigen(cov, vals, vecs);
  glm::dvec3 e1 = vecs[0], e3 = vecs[2];
  if (glm::dot(e3, normal_sum) < 0.0) e3 = -e3;
  if (glm::length(axis_hint) > 0.0) {
    const glm::dvec3 h = axis_hint - glm::dot(axis_hint, e3) * e3;
    if (glm::length(h) > 1e-9 * glm::length(axis_hint)) e1 = glm::normalize(h);
  }
  const glm::dvec3 e2 = glm::normalize(glm::cross(e3, e1));
  e1 = glm::cross(e2, e3);
  param.origin = c;
  param.axis_u = e1;
  param.axis_v = e2;
  const double nlen = glm::length(normal_sum);
  param.mean_normal = nlen > 0.0 ? normal_sum / nlen : e3;
  param.uv.reserve(region.size());
  for (int v : region) {
    const glm::dvec3 d = D(positions[static_cast<size_t>(v)]) - c;
    param.uv.emplace_back(glm::dot(d, e1), glm::dot(d, e2));
  }
  if (base::Status st = NormalizeUv(param.uv); !st) return st.error();
  if (base::Status st = CheckOneToOne(param, tris, "try the cylinder map or a smaller region");
      !st) {
    return st.error();
  }
  return param;
}

base::Result<RegionParametrization> ParametrizeCylinder(std::span<const glm::vec3> positions,
                                                        std::span<const int> region,
                                                        std::span<const glm::uvec3> triangles,
                                                        glm::dvec3 axis_origin,
                                                        glm::dvec3 axis_direction,
                                                        double max_span_deg) {
  if (base::Status st = CheckRegion(positions, region); !st) return st.error();
  if (!(glm::length(axis_direction) > 0.0))
    return InvalidArgument("cylinder map: zero axis direction");
  const std::vector<glm::ivec3> tris = RegionTriangles(triangles, region, positions.size());
  RegionParametrization param;
  param.kind = RegionParametrization::Kind::kCylinder;
  param.region.assign(region.begin(), region.end());
  param.region_triangles = static_cast<int>(tris.size());
  const RegionMoments mom = Moments(positions, region, tris);
  const glm::dvec3 normal_sum = mom.normal_sum, c = mom.centroid;
  const glm::dvec3 a = glm::normalize(axis_direction);
  glm::dvec3 radial = c - axis_origin;
  radial -= glm::dot(radial, a) * a;
  if (!(glm::length(radial) > 1e-12)) {
    return InvalidArgument("cylinder map: the region's centroid lies on the axis (a closed tube?)");
  }
  const glm::dvec3 r0 = glm::normalize(radial);
  const glm::dvec3 b2 = glm::cross(a, r0);
  param.origin = axis_origin;
  param.axis_u = r0;
  param.axis_v = a;
  const double nlen = glm::length(normal_sum);
  param.mean_normal = nlen > 0.0 ? normal_sum / nlen : r0;
  double lo = 1e300, hi = -1e300;
  for (int v : region) {
    const glm::dvec3 d = D(positions[static_cast<size_t>(v)]) - axis_origin;
    const double phi = std::atan2(glm::dot(d, b2), glm::dot(d, r0));
    lo = std::min(lo, phi);
    hi = std::max(hi, phi);
    param.uv.emplace_back(phi, glm::dot(d, a));
  }
  param.angular_span_deg = (hi - lo) * 180.0 / std::numbers::pi;
  if (param.angular_span_deg > max_span_deg) {
    return MakeError(ErrorCode::kUnsupported, {},
                     "cylinder map: region spans " + std::to_string(param.angular_span_deg) +
                         " deg around the axis, expected at most " + std::to_string(max_span_deg) +
                         " (closed tubes need periodic splines)");
  }
  if (base::Status st = NormalizeUv(param.uv); !st) return st.error();
  if (base::Status st = CheckOneToOne(param, tris, "check the axis or use a smaller region"); !st) {
    return st.error();
  }
  return param;
}

base::Result<PatchSamples> SampleRegion(std::span<const glm::vec3> positions,
                                        std::span<const glm::uvec3> triangles,
                                        const RegionParametrization& param,
                                        std::span<const double> us, std::span<const double> vs,
                                        SampleMode mode) {
  if (base::Status st = CheckParameterList(us, "sampling u"); !st) return st.error();
  if (base::Status st = CheckParameterList(vs, "sampling v"); !st) return st.error();
  if (param.uv.size() != param.region.size())
    return InvalidArgument("sampling: parametrization has mismatched sizes");
  if (base::Status st = CheckRegion(positions, param.region); !st) return st.error();
  const std::vector<glm::ivec3> tris = RegionTriangles(triangles, param.region, positions.size());
  PatchSamples out;
  out.num_s = static_cast<int>(us.size());
  out.num_t = static_cast<int>(vs.size());
  out.us.assign(us.begin(), us.end());
  out.vs.assign(vs.begin(), vs.end());
  std::unordered_map<int, int> used;  // mesh vertex -> first sample index
  for (int k = 0; k < out.num_s; ++k) {
    for (int l = 0; l < out.num_t; ++l) {
      const glm::dvec2 x(us[static_cast<size_t>(k)], vs[static_cast<size_t>(l)]);
      bool found = false;
      if (mode == SampleMode::kBarycentric && !tris.empty()) {
        // The containing triangle, or else the nearest point of the layout
        // (samples on the border of a non-rectangular layout stay on the
        // region's edge instead of jumping to a vertex).
        double best_d2 = 1e300;
        glm::dvec3 best_point(0.0);
        for (const glm::ivec3& t : tris) {
          const glm::dvec2 a = param.uv[static_cast<size_t>(t.x)], b = param.uv[static_cast<size_t>(t.y)],
                           c = param.uv[static_cast<size_t>(t.z)];
          double w[3] = {1.0, 0.0, 0.0};
          const double d2 = ClosestInTriangle(x, a, b, c, w);
          if (d2 < best_d2) {
            best_d2 = d2;
            auto pos = [&](int r) { return D(positions[static_cast<size_t>(param.region[static_cast<size_t>(r)])]); };
            best_point = w[0] * pos(t.x) + w[1] * pos(t.y) + w[2] * pos(t.z);
            if (d2 == 0.0) break;
          }
        }
        out.points.push_back(best_point);
        out.vertex.push_back(-1);
        found = true;
      }
      if (found) continue;
      size_t best = 0;
      double best_d = 1e300;
      for (size_t r = 0; r < param.uv.size(); ++r) {
        const glm::dvec2 d = param.uv[r] - x;
        const double dd = glm::dot(d, d);
        if (dd < best_d) {
          best_d = dd;
          best = r;
        }
      }
      const int vtx = param.region[best];
      out.points.push_back(D(positions[static_cast<size_t>(vtx)]));
      out.vertex.push_back(vtx);
      const int idx = k * out.num_t + l;
      auto [it, inserted] = used.emplace(vtx, idx);
      if (!inserted) {
        out.warnings.push_back({{}, "samples " + std::to_string(it->second) + " and " +
                                        std::to_string(idx) + " both take vertex " +
                                        std::to_string(vtx) + " (degenerate fit)"});
      }
    }
  }
  return out;
}

base::Result<PatchSamples> SampleHandPicked(std::span<const glm::vec3> positions,
                                            std::span<const int> vertices, int num_s, int num_t) {
  if (num_s < 2 || num_t < 2 || vertices.size() != static_cast<size_t>(num_s) * static_cast<size_t>(num_t)) {
    return InvalidArgument("hand-picked samples: expected S x T >= 2 x 2 vertices, found " +
                           std::to_string(vertices.size()));
  }
  if (base::Status st = CheckRegion(positions, vertices); !st) return st.error();
  PatchSamples out;
  out.num_s = num_s;
  out.num_t = num_t;
  for (int v : vertices) {
    out.points.push_back(D(positions[static_cast<size_t>(v)]));
    out.vertex.push_back(v);
  }
  out.us = ChordParameters(out.points, num_s, num_t, true, false);
  out.vs = ChordParameters(out.points, num_t, num_s, false, false);
  return out;
}

base::Result<PatchFit> FitSurface(const PatchSamples& samples, const FitOptions& options) {
  const int s = samples.num_s, t = samples.num_t, m = options.num_u, n = options.num_v;
  if (samples.points.size() != static_cast<size_t>(s) * static_cast<size_t>(t) ||
      samples.us.size() != static_cast<size_t>(s) || samples.vs.size() != static_cast<size_t>(t)) {
    return InvalidArgument("patch fit: samples have mismatched sizes");
  }
  if (m < 4 || n < 4 || m > s || n > t) {
    return InvalidArgument(
        "patch fit: expected 4 <= M <= S and 4 <= N <= T, found M x N = " + std::to_string(m) +
        " x " + std::to_string(n) + ", S x T = " + std::to_string(s) + " x " + std::to_string(t) +
        " (sample more points, or fit coarser and refine knots)");
  }
  if (!(options.smoothing >= 0.0)) return InvalidArgument("patch fit: smoothing must be >= 0");
  PatchFit fit;
  switch (options.parameterization) {
    case FitParameterization::kSampleGrid:
      fit.ub = samples.us;
      fit.vb = samples.vs;
      break;
    case FitParameterization::kChordLength:
    case FitParameterization::kCentripetal: {
      const bool centripetal = options.parameterization == FitParameterization::kCentripetal;
      fit.ub = ChordParameters(samples.points, s, t, true, centripetal);
      fit.vb = ChordParameters(samples.points, t, s, false, centripetal);
      break;
    }
  }
  DirectionFit fu, fv;
  if (base::Status st = fu.Setup(fit.ub, m, options.smoothing); !st) return st.error();
  if (base::Status st = fv.Setup(fit.vb, n, options.smoothing); !st) return st.error();
  // Rows in u: every data column l (fixed v) gives M intermediate points R_il.
  std::vector<glm::dvec3> r(static_cast<size_t>(m) * t);
  std::vector<glm::dvec3> line;
  for (int l = 0; l < t; ++l) {
    line.resize(static_cast<size_t>(s));
    for (int k = 0; k < s; ++k) line[static_cast<size_t>(k)] = samples.points[static_cast<size_t>(k) * t + l];
    fu.Fit(line);
    for (int i = 0; i < m; ++i) r[static_cast<size_t>(i) * t + l] = line[static_cast<size_t>(i)];
  }
  std::vector<glm::dvec3> control(static_cast<size_t>(m) * n);
  for (int i = 0; i < m; ++i) {
    line.assign(r.begin() + static_cast<std::ptrdiff_t>(i) * t, r.begin() + static_cast<std::ptrdiff_t>(i + 1) * t);
    fv.Fit(line);
    for (int j = 0; j < n; ++j) control[static_cast<size_t>(i) * n + j] = line[static_cast<size_t>(j)];
  }
  base::Result<BSplineSurface> surface =
      BSplineSurface::Create(3, 3, fu.knots, fv.knots, m, n, std::move(control));
  if (!surface) return std::move(surface).error();
  fit.surface = std::move(*surface);
  fit.interpolating = fu.interpolating && fv.interpolating;
  double sum2 = 0.0;
  for (int k = 0; k < s; ++k) {
    for (int l = 0; l < t; ++l) {
      const double e = glm::length(fit.surface.Evaluate(fit.ub[static_cast<size_t>(k)], fit.vb[static_cast<size_t>(l)]) -
                                   samples.points[static_cast<size_t>(k) * t + l]);
      fit.max_error = std::max(fit.max_error, e);
      sum2 += e * e;
    }
  }
  fit.rms_error = std::sqrt(sum2 / (static_cast<double>(s) * t));
  return fit;
}

void OrientNormal(BSplineSurface& surface, const RegionParametrization& param) {
  double agree = 0.0;
  surface.set_sigma(1);
  for (const glm::dvec2& uv : param.uv) agree += glm::dot(surface.Normal(uv.x, uv.y), param.mean_normal);
  surface.set_sigma(agree < 0.0 ? -1 : 1);
}

}  // namespace deform
