#pragma once
// Brush edits of a B-spline patch (ALGORITHMS.md 8.1; issue 26 [ours, beyond
// the paper]). A minimum-norm edit (4.1, 4.2) of one point changes the control
// points in proportion to the basis values there, so the visible shape is one
// basis function: a bump of fixed size. A brush instead asks the whole
// neighbourhood of (u0, v0) to follow a displacement field
//
//   f(u,v) = phi(|(u,v) - (u0,v0)| / r) D,    phi(x) = (1 - x)^4 (4x + 1)  (x < 1), 0 beyond
//
// (Wendland's C2 kernel: phi(0) = 1, phi'(0) = 0, phi(1) = phi'(1) = phi''(1) = 0,
// so the shape meets the untouched surface without a crease), and solves for
// the change dQ_F of the free control points F (3 coordinates alike):
//
//   min  (1/S) sum_k |s_dQ(u_k,v_k) - f(u_k,v_k)|^2          field fit over an S-point grid
//        + mu/|F| |L2 dQ|^2                                 second differences along u and v
//                                                           of the control-grid change (fixed
//                                                           points enter as zero values)
//        + w sum_c |s_dQ(u_c,v_c) - D_c|^2                   each edit's own point, w large
//
// with s_dQ(u,v) = sum_ij N_i(u) N_j(v) dQ_ij and f the sum of every brush's
// field. The last term (penalty weight 1e6 x the data term's mean diagonal)
// makes each edited point move by its D to ~1e-6 relative; a stroke with r = 0
// is such a hard point only (no field). Solved once by a sparse Cholesky
// factorisation (Eigen) of the normal equations; cost O(S x 16) to assemble
// and a banded solve of |F| unknowns, well under a millisecond for a 9 x 10
// grid. Setup only: never called per frame.

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "deform/patch/bspline.h"
#include "deform/shapes/direct_manipulation.h"
#include "base/error.h"

namespace deform {

// phi(x) of the brush (Wendland C2): 1 at x = 0, 0 for x >= 1, smooth (C2)
// everywhere; x is distance / radius (>= 0).
double BrushFalloff(double x);

// One stroke: move s(u, v) by `delta` (model units), dragging the surface
// around it with the falloff over `radius` (parameter units; 0 = a hard point
// with no field, as a plain edit).
struct BrushStroke {
  double u = 0.0, v = 0.0;  // centre, in [0,1]^2
  double radius = 0.0;      // >= 0, parameter units
  glm::dvec3 delta{0.0};    // model units
};

struct BrushOptions {
  // #C flags, 1 = may move; empty: all but the boundary ring (as 4.2).
  std::vector<std::uint8_t> free_mask{};
  double smoothness = 0.05;    // mu of the second-difference term, >= 0
  int min_samples = 24;        // field grid per direction: max(min_samples, 4 x #controls)
  double satisfied_tol_rel = 1e-4;  // a centre missing D by more than this x the
                                    // control diagonal is listed as unsatisfied
};

// Solves the strokes together. Result fields as SolvePointConstraints':
// delta (#C, zero at fixed points), residual per stroke centre (model units),
// unsatisfied stroke indices. Fails (kInvalidArgument) on no strokes, a
// centre outside [0,1]^2, a negative or non-finite radius, a non-finite
// delta, a mask of the wrong size or with no free point, mu < 0.
base::Result<ManipulationResult> SolveBrushStrokes(const BSplineSurface& surface,
                                                   std::span<const BrushStroke> strokes,
                                                   const BrushOptions& options = {});

// The largest |second difference| of a control-grid change along u or v
// (model units): how rough a change is; used by tests to compare a brush with
// a minimum-norm edit. `delta` is #C = M x N row-major.
double MaxSecondDifference(std::span<const glm::dvec3> delta, int num_u, int num_v);

}  // namespace deform
