#include "deform/patch/bspline.h"
#include "deform/internal/checks.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace deform {
namespace {

using base::ErrorCode;
using base::MakeError;

using internal::InvalidArgument;

double Clamp01(double x) { return std::clamp(x, 0.0, 1.0); }

}  // namespace

std::vector<double> MakeClampedUniformKnots(int num_control, int degree) {
  const int m = num_control + degree + 1;
  std::vector<double> knots(static_cast<size_t>(std::max(m, 0)), 0.0);
  const int interior = num_control - degree;  // number of spans
  for (int i = 0; i < m; ++i) {
    if (i <= degree) {
      knots[static_cast<size_t>(i)] = 0.0;
    } else if (i >= num_control) {
      knots[static_cast<size_t>(i)] = 1.0;
    } else {
      knots[static_cast<size_t>(i)] = static_cast<double>(i - degree) / interior;
    }
  }
  return knots;
}

base::Status CheckKnots(std::span<const double> knots, int num_control, int degree,
                        const char* what) {
  if (degree < 1 || degree > kMaxSplineDegree) {
    return InvalidArgument(std::string(what) + ": expected degree in 1.." +
                           std::to_string(kMaxSplineDegree) + ", found " + std::to_string(degree));
  }
  if (num_control < degree + 1 || num_control > 255) {
    return InvalidArgument(std::string(what) + ": expected " + std::to_string(degree + 1) +
                           "..255 control points, found " + std::to_string(num_control));
  }
  const size_t expected = static_cast<size_t>(num_control + degree + 1);
  if (knots.size() != expected) {
    return InvalidArgument(std::string(what) + ": expected " + std::to_string(expected) +
                           " knots, found " + std::to_string(knots.size()));
  }
  for (size_t i = 0; i < knots.size(); ++i) {
    if (!std::isfinite(knots[i])) return InvalidArgument(std::string(what) + ": non-finite knot");
    if (i > 0 && knots[i] < knots[i - 1]) {
      return InvalidArgument(std::string(what) + ": knots decrease at index " + std::to_string(i));
    }
  }
  for (int i = 0; i <= degree; ++i) {
    if (knots[static_cast<size_t>(i)] != 0.0 || knots[expected - 1 - static_cast<size_t>(i)] != 1.0) {
      return InvalidArgument(std::string(what) + ": expected clamped knots (" +
                             std::to_string(degree + 1) + " zeros and ones at the ends)");
    }
  }
  // Interior multiplicity <= degree, so the surface stays continuous.
  int run = 1;
  for (size_t i = static_cast<size_t>(degree) + 1; i < expected - static_cast<size_t>(degree) - 1;
       ++i) {
    run = (knots[i] == knots[i - 1] && knots[i] != 0.0) ? run + 1 : 1;
    if (run > degree) {
      return InvalidArgument(std::string(what) + ": interior knot multiplicity exceeds the degree");
    }
  }
  return base::Status::Ok();
}

int FindSpan(std::span<const double> knots, int num_control, int degree, double u) {
  if (u >= knots[static_cast<size_t>(num_control)]) return num_control - 1;
  if (u <= knots[static_cast<size_t>(degree)]) return degree;
  int low = degree;
  int high = num_control;  // invariant: knots[low] <= u < knots[high]
  while (high - low > 1) {
    const int mid = (low + high) / 2;
    if (u < knots[static_cast<size_t>(mid)]) {
      high = mid;
    } else {
      low = mid;
    }
  }
  return low;
}

void BasisFuns(std::span<const double> knots, int span, int degree, double u,
               std::span<double> out) {
  double left[kMaxSplineDegree + 1];
  double right[kMaxSplineDegree + 1];
  out[0] = 1.0;
  for (int r = 1; r <= degree; ++r) {
    left[r] = u - knots[static_cast<size_t>(span + 1 - r)];
    right[r] = knots[static_cast<size_t>(span + r)] - u;
    double saved = 0.0;
    for (int a = 0; a < r; ++a) {
      const double denom = right[a + 1] + left[r - a];
      const double t = denom != 0.0 ? out[static_cast<size_t>(a)] / denom : 0.0;  // 0/0 := 0
      out[static_cast<size_t>(a)] = saved + right[a + 1] * t;
      saved = left[r - a] * t;
    }
    out[static_cast<size_t>(r)] = saved;
  }
}

BasisDerivs BasisFunsDerivs(std::span<const double> knots, int span, int degree, double u,
                            int num_derivs) {
  // Triangular table: ndu[j][r] holds basis values of degree j (upper part)
  // and knot differences (lower part), as in The NURBS Book A2.3.
  constexpr int kP = kMaxSplineDegree + 1;
  double ndu[kP][kP];
  double left[kP];
  double right[kP];
  ndu[0][0] = 1.0;
  for (int j = 1; j <= degree; ++j) {
    left[j] = u - knots[static_cast<size_t>(span + 1 - j)];
    right[j] = knots[static_cast<size_t>(span + j)] - u;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      ndu[j][r] = right[r + 1] + left[j - r];                    // knot difference
      const double t = ndu[j][r] != 0.0 ? ndu[r][j - 1] / ndu[j][r] : 0.0;
      ndu[r][j] = saved + right[r + 1] * t;                      // degree-j value
      saved = left[j - r] * t;
    }
    ndu[j][j] = saved;
  }
  BasisDerivs out;
  for (int r = 0; r <= degree; ++r) out.ders[0][r] = ndu[r][degree];
  const int n = std::min(num_derivs, std::min(degree, 2));
  // Derivatives by repeated application of N' = p/(u_{i+p}-u_i) N_{i,p-1} - ...
  for (int r = 0; r <= degree; ++r) {
    double a[2][kP] = {};
    int s1 = 0;
    int s2 = 1;
    a[0][0] = 1.0;
    for (int k = 1; k <= n; ++k) {
      double d = 0.0;
      const int rk = r - k;
      const int pk = degree - k;
      if (r >= k) {
        a[s2][0] = ndu[pk + 1][rk] != 0.0 ? a[s1][0] / ndu[pk + 1][rk] : 0.0;
        d = a[s2][0] * ndu[rk][pk];
      }
      const int j1 = rk >= -1 ? 1 : -rk;
      const int j2 = (r - 1 <= pk) ? k - 1 : degree - r;
      for (int j = j1; j <= j2; ++j) {
        const double den = ndu[pk + 1][rk + j];
        a[s2][j] = den != 0.0 ? (a[s1][j] - a[s1][j - 1]) / den : 0.0;
        d += a[s2][j] * ndu[rk + j][pk];
      }
      if (r <= pk) {
        const double den = ndu[pk + 1][r];
        a[s2][k] = den != 0.0 ? -a[s1][k - 1] / den : 0.0;
        d += a[s2][k] * ndu[r][pk];
      }
      out.ders[k][r] = d;
      std::swap(s1, s2);
    }
  }
  // Multiply by p!/(p-k)!.
  double factor = degree;
  for (int k = 1; k <= n; ++k) {
    for (int r = 0; r <= degree; ++r) out.ders[k][r] *= factor;
    factor *= (degree - k);
  }
  return out;
}

std::vector<double> GrevilleAbscissae(std::span<const double> knots, int num_control,
                                      int degree) {
  std::vector<double> xi(static_cast<size_t>(num_control));
  for (int i = 0; i < num_control; ++i) {
    double sum = 0.0;
    for (int a = 1; a <= degree; ++a) sum += knots[static_cast<size_t>(i + a)];
    xi[static_cast<size_t>(i)] = sum / degree;
  }
  return xi;
}

KnotInsertionMap KnotInsertionMap::After(const KnotInsertionMap& first) const {
  KnotInsertionMap out;
  out.num_old = first.num_old;
  out.num_new = num_new;
  out.matrix.assign(static_cast<size_t>(num_new) * first.num_old, 0.0);
  for (int r = 0; r < num_new; ++r) {
    for (int k = 0; k < num_old; ++k) {
      const double w = at(r, k);
      if (w == 0.0) continue;
      for (int c = 0; c < first.num_old; ++c) {
        out.matrix[static_cast<size_t>(r) * first.num_old + c] += w * first.at(k, c);
      }
    }
  }
  return out;
}

base::Result<KnotInsertionMap> InsertKnot(std::vector<double>& knots, int num_control, int degree,
                                          double ub) {
  if (!(ub > 0.0 && ub < 1.0)) {
    return InvalidArgument("knot insertion: expected a knot in (0,1), found " + std::to_string(ub));
  }
  const int k = FindSpan(knots, num_control, degree, ub);
  int multiplicity = 0;
  for (double knot : knots) multiplicity += knot == ub ? 1 : 0;
  if (multiplicity + 1 > degree) {
    return InvalidArgument("knot insertion: multiplicity of " + std::to_string(ub) +
                           " would exceed the degree " + std::to_string(degree));
  }
  KnotInsertionMap map;
  map.num_old = num_control;
  map.num_new = num_control + 1;
  map.matrix.assign(static_cast<size_t>(map.num_new) * num_control, 0.0);
  auto set = [&](int r, int c, double w) {
    map.matrix[static_cast<size_t>(r) * num_control + c] = w;
  };
  for (int i = 0; i <= num_control; ++i) {
    if (i <= k - degree) {
      set(i, i, 1.0);
    } else if (i >= k + 1) {
      set(i, i - 1, 1.0);
    } else {
      const double ui = knots[static_cast<size_t>(i)];
      const double al = (ub - ui) / (knots[static_cast<size_t>(i + degree)] - ui);
      set(i, i, al);
      set(i, i - 1, 1.0 - al);
    }
  }
  knots.insert(knots.begin() + k + 1, ub);
  return map;
}

base::Result<BSplineSurface> BSplineSurface::Create(int degree_u, int degree_v,
                                                    std::vector<double> knots_u,
                                                    std::vector<double> knots_v, int num_u,
                                                    int num_v, std::vector<glm::dvec3> control,
                                                    int sigma) {
  if (base::Status st = CheckKnots(knots_u, num_u, degree_u, "u knots"); !st) return st.error();
  if (base::Status st = CheckKnots(knots_v, num_v, degree_v, "v knots"); !st) return st.error();
  if (control.size() != static_cast<size_t>(num_u) * static_cast<size_t>(num_v)) {
    return InvalidArgument("expected " + std::to_string(num_u * num_v) + " control points, found " +
                           std::to_string(control.size()));
  }
  for (const glm::dvec3& q : control) {
    if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z)) {
      return MakeError(ErrorCode::kNonFinite, {}, "non-finite control point");
    }
  }
  BSplineSurface s;
  s.degree_u_ = degree_u;
  s.degree_v_ = degree_v;
  s.num_u_ = num_u;
  s.num_v_ = num_v;
  s.sigma_ = sigma < 0 ? -1 : 1;
  s.knots_u_ = std::move(knots_u);
  s.knots_v_ = std::move(knots_v);
  s.control_ = std::move(control);
  return s;
}

base::Result<BSplineSurface> BSplineSurface::CreateUniform(int num_u, int num_v,
                                                           std::vector<glm::dvec3> control,
                                                           int degree) {
  return Create(degree, degree, MakeClampedUniformKnots(num_u, degree),
                MakeClampedUniformKnots(num_v, degree), num_u, num_v, std::move(control));
}

glm::dvec3 BSplineSurface::Evaluate(double u, double v) const {
  u = Clamp01(u);
  v = Clamp01(v);
  const int ku = FindSpan(knots_u_, num_u_, degree_u_, u);
  const int kv = FindSpan(knots_v_, num_v_, degree_v_, v);
  double nu[kMaxSplineDegree + 1];
  double nv[kMaxSplineDegree + 1];
  BasisFuns(knots_u_, ku, degree_u_, u, nu);
  BasisFuns(knots_v_, kv, degree_v_, v, nv);
  glm::dvec3 s(0.0);
  for (int a = 0; a <= degree_u_; ++a) {
    glm::dvec3 row(0.0);
    for (int b = 0; b <= degree_v_; ++b) row += nv[b] * control(ku - degree_u_ + a, kv - degree_v_ + b);
    s += nu[a] * row;
  }
  return s;
}

SurfaceDerivs BSplineSurface::EvaluateDerivs(double u, double v, int num_derivs) const {
  u = Clamp01(u);
  v = Clamp01(v);
  const int ku = FindSpan(knots_u_, num_u_, degree_u_, u);
  const int kv = FindSpan(knots_v_, num_v_, degree_v_, v);
  const BasisDerivs bu = BasisFunsDerivs(knots_u_, ku, degree_u_, u, num_derivs);
  const BasisDerivs bv = BasisFunsDerivs(knots_v_, kv, degree_v_, v, num_derivs);
  SurfaceDerivs out;
  for (int a = 0; a <= degree_u_; ++a) {
    glm::dvec3 r0(0.0), r1(0.0), r2(0.0);  // row sums against N, N', N'' in v
    for (int b = 0; b <= degree_v_; ++b) {
      const glm::dvec3& q = control(ku - degree_u_ + a, kv - degree_v_ + b);
      r0 += bv.ders[0][b] * q;
      r1 += bv.ders[1][b] * q;
      r2 += bv.ders[2][b] * q;
    }
    out.s += bu.ders[0][a] * r0;
    out.su += bu.ders[1][a] * r0;
    out.sv += bu.ders[0][a] * r1;
    if (num_derivs >= 2) {
      out.suu += bu.ders[2][a] * r0;
      out.suv += bu.ders[1][a] * r1;
      out.svv += bu.ders[0][a] * r2;
    }
  }
  return out;
}

glm::dvec3 BSplineSurface::Normal(double u, double v) const {
  const SurfaceDerivs d = EvaluateDerivs(u, v, 1);
  const glm::dvec3 c = glm::cross(d.su, d.sv);
  const double len = glm::length(c);
  if (!(len > 0.0)) return glm::dvec3(0.0);
  return (static_cast<double>(sigma_) / len) * c;
}

double BSplineSurface::ControlDiagonal() const {
  if (control_.empty()) return 0.0;
  glm::dvec3 lo = control_[0], hi = control_[0];
  for (const glm::dvec3& q : control_) {
    lo = glm::min(lo, q);
    hi = glm::max(hi, q);
  }
  return glm::length(hi - lo);
}

base::Result<KnotInsertionMap> BSplineSurface::InsertKnotU(double ub) {
  std::vector<double> knots = knots_u_;
  base::Result<KnotInsertionMap> map = InsertKnot(knots, num_u_, degree_u_, ub);
  if (!map) return map;
  std::vector<glm::dvec3> next(static_cast<size_t>(num_u_ + 1) * num_v_, glm::dvec3(0.0));
  for (int r = 0; r <= num_u_; ++r) {
    for (int c = 0; c < num_u_; ++c) {
      const double w = map->at(r, c);
      if (w == 0.0) continue;
      for (int j = 0; j < num_v_; ++j) next[static_cast<size_t>(r) * num_v_ + j] += w * control(c, j);
    }
  }
  knots_u_ = std::move(knots);
  control_ = std::move(next);
  ++num_u_;
  return map;
}

base::Result<KnotInsertionMap> BSplineSurface::InsertKnotV(double vb) {
  std::vector<double> knots = knots_v_;
  base::Result<KnotInsertionMap> map = InsertKnot(knots, num_v_, degree_v_, vb);
  if (!map) return map;
  const int nn = num_v_ + 1;
  std::vector<glm::dvec3> next(static_cast<size_t>(num_u_) * nn, glm::dvec3(0.0));
  for (int i = 0; i < num_u_; ++i) {
    for (int r = 0; r < nn; ++r) {
      for (int c = 0; c < num_v_; ++c) {
        const double w = map->at(r, c);
        if (w != 0.0) next[static_cast<size_t>(i) * nn + r] += w * control(i, c);
      }
    }
  }
  knots_v_ = std::move(knots);
  control_ = std::move(next);
  num_v_ = nn;
  return map;
}

namespace {
template <typename InsertFn>
base::Result<KnotInsertionMap> RefineWith(std::span<const double> knots, int num, InsertFn insert) {
  KnotInsertionMap total;
  total.num_old = total.num_new = num;
  total.matrix.assign(static_cast<size_t>(num) * num, 0.0);
  for (int i = 0; i < num; ++i) total.matrix[static_cast<size_t>(i) * num + i] = 1.0;
  for (double ub : knots) {
    base::Result<KnotInsertionMap> step = insert(ub);
    if (!step) return step;
    total = step->After(total);
  }
  return total;
}

std::vector<double> Midpoints(const std::vector<double>& knots) {
  std::vector<double> out;
  for (size_t i = 1; i < knots.size(); ++i) {
    if (knots[i] > knots[i - 1]) out.push_back(0.5 * (knots[i] + knots[i - 1]));
  }
  return out;
}
}  // namespace

base::Result<KnotInsertionMap> BSplineSurface::RefineU(std::span<const double> knots) {
  return RefineWith(knots, num_u_, [this](double ub) { return InsertKnotU(ub); });
}

base::Result<KnotInsertionMap> BSplineSurface::RefineV(std::span<const double> knots) {
  return RefineWith(knots, num_v_, [this](double vb) { return InsertKnotV(vb); });
}

std::vector<double> BSplineSurface::SpanMidpointsU() const { return Midpoints(knots_u_); }
std::vector<double> BSplineSurface::SpanMidpointsV() const { return Midpoints(knots_v_); }

}  // namespace deform
