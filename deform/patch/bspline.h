#pragma once
// Tensor-product B-spline surfaces on clamped, non-uniform knot vectors
// (ALGORITHMS.md sections 1 and 7; The NURBS Book, Piegl & Tiller, ch. 2, 3, 5).
//
//   s(u,v) = sum_{i<M} sum_{j<N} N_{i,p}(u) N_{j,q}(v) q_ij        (u,v) in [0,1]^2
//
// Setup work (fitting, projection, knot insertion) runs in double precision;
// the per-frame rebuild (patch_binding.h) uses float copies of the control
// points. Degrees are general (p,q >= 1); the patches of the method are
// bicubic (p = q = 3), which is the default.

#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "base/error.h"

namespace deform {

// Highest degree the fixed-size helpers below support.
inline constexpr int kMaxSplineDegree = 5;

// Basis values and their derivatives at one parameter: ders[r][a] is the r-th
// derivative of N_{span-p+a,p}(u), a = 0..p, r = 0..max derivative asked for.
struct BasisDerivs {
  double ders[3][kMaxSplineDegree + 1] = {};
};

// Knot vector (u_0 .. u_{M+p}) of M control points, degree p, clamped (p+1
// equal knots at each end), interior knots equally spaced in [0,1].
std::vector<double> MakeClampedUniformKnots(int num_control, int degree);

// Checks that `knots` is a clamped knot vector on [0,1] for `num_control`
// points of degree `degree`: size M+p+1, non-decreasing, finite, end
// multiplicity p+1, interior multiplicity <= p. `what` names it in messages.
base::Status CheckKnots(std::span<const double> knots, int num_control, int degree,
                        const char* what);

// The span k in [p, M-1] with u_k <= u < u_{k+1}; u >= 1 gives M-1 and u <= 0
// gives p (values outside [0,1] are clamped). Binary search, O(log M).
int FindSpan(std::span<const double> knots, int num_control, int degree, double u);

// The p+1 nonzero basis values N_{k-p..k,p}(u) at span k (the triangular
// Cox-de Boor table; 0/0 taken as 0). out has p+1 entries; they are >= 0 and
// sum to 1.
void BasisFuns(std::span<const double> knots, int span, int degree, double u,
               std::span<double> out);

// Basis values and derivatives up to order num_derivs (0..2) at span k.
BasisDerivs BasisFunsDerivs(std::span<const double> knots, int span, int degree, double u,
                            int num_derivs);

// Greville abscissae xi_i = (u_{i+1} + ... + u_{i+p}) / p, i < M: the
// parameters "under" each control point.
std::vector<double> GrevilleAbscissae(std::span<const double> knots, int num_control, int degree);

// Point and derivatives of a surface at (u,v).
struct SurfaceDerivs {
  glm::dvec3 s{0.0};    // s(u,v)
  glm::dvec3 su{0.0};   // ds/du
  glm::dvec3 sv{0.0};   // ds/dv
  glm::dvec3 suu{0.0};  // d2s/du2 (zero unless asked for)
  glm::dvec3 suv{0.0};  // d2s/dudv
  glm::dvec3 svv{0.0};  // d2s/dv2
};

// Linear map of one knot insertion or refinement: new control points
// P'_r = sum_c rows[r][c] P_c, as a dense #new x #old matrix (row-major).
// Apply it along u to columns and along v to rows of any per-control-point
// field (ALGORITHMS.md 7): X' = Tu X Tv^T. Rows are convex combinations.
struct KnotInsertionMap {
  int num_old = 0;
  int num_new = 0;
  std::vector<double> matrix;  // #new x #old, row-major

  double at(int r, int c) const { return matrix[static_cast<size_t>(r) * num_old + c]; }
  // Composition: (this after first), i.e. this->matrix * first.matrix.
  KnotInsertionMap After(const KnotInsertionMap& first) const;
};

// A B-spline surface of degree (p,q) with an M x N control grid.
class BSplineSurface {
 public:
  BSplineSurface() = default;

  // Builds and checks a surface: knots per CheckKnots, #M*#N control points
  // (row-major: index i*N + j, i along u), finite; sigma = +1 or -1.
  static base::Result<BSplineSurface> Create(int degree_u, int degree_v,
                                             std::vector<double> knots_u,
                                             std::vector<double> knots_v, int num_u, int num_v,
                                             std::vector<glm::dvec3> control, int sigma = 1);
  // Bicubic surface on uniform clamped knots with the given control grid.
  static base::Result<BSplineSurface> CreateUniform(int num_u, int num_v,
                                                    std::vector<glm::dvec3> control,
                                                    int degree = 3);

  int degree_u() const { return degree_u_; }
  int degree_v() const { return degree_v_; }
  int num_u() const { return num_u_; }  // M, control points along u
  int num_v() const { return num_v_; }  // N, control points along v
  int sigma() const { return sigma_; }  // normal orientation, +1 or -1
  void set_sigma(int sigma) { sigma_ = sigma < 0 ? -1 : 1; }
  const std::vector<double>& knots_u() const { return knots_u_; }  // #M+p+1
  const std::vector<double>& knots_v() const { return knots_v_; }  // #N+q+1
  const std::vector<glm::dvec3>& control() const { return control_; }  // #M x #N row-major
  std::vector<glm::dvec3>& mutable_control() { return control_; }
  const glm::dvec3& control(int i, int j) const {
    return control_[static_cast<size_t>(i) * num_v_ + j];
  }

  // s(u,v); (u,v) are clamped to [0,1]^2.
  glm::dvec3 Evaluate(double u, double v) const;
  // s and its partial derivatives up to order num_derivs (1 or 2).
  SurfaceDerivs EvaluateDerivs(double u, double v, int num_derivs) const;
  // n = sigma * hat(cross(s_u, s_v)); (0,0,0) where the surface is degenerate.
  glm::dvec3 Normal(double u, double v) const;
  // Diagonal of the control points' bounding box: the "patch size" that
  // tolerances are relative to.
  double ControlDiagonal() const;

  // Boehm insertion of knot ub in (0,1) once along u (resp. v); fails when its
  // multiplicity would exceed the degree. Returns the map of the direction's
  // control indices (#M+1 x #M along u); the surface is unchanged.
  base::Result<KnotInsertionMap> InsertKnotU(double ub);
  base::Result<KnotInsertionMap> InsertKnotV(double vb);
  // Inserts every knot of `knots` (each in (0,1), any order) one at a time;
  // returns the composed map. On failure the knots inserted before the bad
  // one stay inserted (the surface is still unchanged).
  base::Result<KnotInsertionMap> RefineU(std::span<const double> knots);
  base::Result<KnotInsertionMap> RefineV(std::span<const double> knots);
  // Midpoints of every non-empty knot span along u (resp. v), for refinement.
  std::vector<double> SpanMidpointsU() const;
  std::vector<double> SpanMidpointsV() const;

 private:
  int degree_u_ = 3;
  int degree_v_ = 3;
  int num_u_ = 0;
  int num_v_ = 0;
  int sigma_ = 1;
  std::vector<double> knots_u_;
  std::vector<double> knots_v_;
  std::vector<glm::dvec3> control_;
};

// Insertion of ub once into `knots` for `num_control` points of `degree`:
// the new knot vector and the (#M+1 x #M) map. Fails on ub outside (0,1) or a
// multiplicity that would exceed the degree.
base::Result<KnotInsertionMap> InsertKnot(std::vector<double>& knots, int num_control, int degree,
                                          double ub);

}  // namespace deform
