#pragma once
// Patch generation (ALGORITHMS.md 3.2-3.4): map a mesh region into [0,1]^2,
// sample it on an S x T grid, and fit an M x N bicubic control grid to the
// samples (interpolation when S x T = M x N, least squares otherwise).
//
// All of this is setup work in double precision. The region is given as mesh
// vertex indices; triangles are the whole mesh's, and only those with all
// three corners in the region are used.
//
// Typical use:
//   auto param = ParametrizePlane(mesh.positions, region, mesh.triangles);
//   auto samples = SampleRegion(mesh.positions, region, mesh.triangles, *param,
//                               UniformParameters(6), UniformParameters(6));
//   auto fit = FitSurface(*samples, {.num_u = 6, .num_v = 6});
//   OrientNormal(fit->surface, *param);

#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "deform/patch/bspline.h"
#include "base/error.h"

namespace deform {

// A region's map into the parameter square. The map is affine in the
// region's best-fit plane (kPlane) or in (angle, height) about a bone axis
// (kCylinder); either way cross(ds/du, ds/dv) points away from the body.
struct RegionParametrization {
  enum class Kind { kPlane, kCylinder };
  Kind kind = Kind::kPlane;
  std::vector<int> region;        // #R mesh vertex indices, as given
  std::vector<glm::dvec2> uv;     // #R parameters in [0,1]^2, one per region vertex
  glm::dvec3 mean_normal{0.0};    // unit, area-weighted normal of the region's triangles
  glm::dvec3 origin{0.0};         // plane: area-weighted centroid; cylinder: axis point
  glm::dvec3 axis_u{0.0};         // plane: e1; cylinder: r (zero angle direction), unit
  glm::dvec3 axis_v{0.0};         // plane: e2; cylinder: the unit axis a, unit
  double angular_span_deg = 0.0;  // cylinder only: max phi - min phi over the region
  int region_triangles = 0;       // #triangles with all corners in the region
};

// Plane map (3.2): eigenvectors e1 >= e2 >= e3 of the region's area-weighted
// covariance, e3 flipped towards the mean normal, e2 = cross(e3, e1); if
// `axis_hint` is nonzero it replaces e1 after projection onto the plane (to
// align the grid with a limb). Fails (kInvalidArgument) on fewer than 3
// vertices or out-of-range indices, and (kUnsupported) when a region triangle
// folds over in (u,v), naming how many: the map must be one-to-one.
base::Result<RegionParametrization> ParametrizePlane(std::span<const glm::vec3> positions,
                                                     std::span<const int> region,
                                                     std::span<const glm::uvec3> triangles,
                                                     glm::dvec3 axis_hint = glm::dvec3(0.0));

// Cylinder map (3.2) around the axis through `axis_origin` along
// `axis_direction` (need not be unit): u = normalized angle (seam opposite the
// region), v = normalized height. Fails when the angular span exceeds
// `max_span_deg` (closed tubes need periodic splines), on a degenerate axis,
// or when a triangle folds over.
base::Result<RegionParametrization> ParametrizeCylinder(std::span<const glm::vec3> positions,
                                                        std::span<const int> region,
                                                        std::span<const glm::uvec3> triangles,
                                                        glm::dvec3 axis_origin,
                                                        glm::dvec3 axis_direction,
                                                        double max_span_deg = 300.0);

// k/(S-1), k = 0..S-1 (S >= 2).
std::vector<double> UniformParameters(int count);

// How a sample point is taken from the mesh (3.3).
enum class SampleMode {
  kNearestVertex,  // the region vertex whose (u,v) is nearest [paper]
  kBarycentric,    // the exact mesh point at (u,v) in the 2D layout; outside the layout,
                   // the mesh point at the nearest layout point (on its border)
};

// S x T sample points on the region and their parameters.
struct PatchSamples {
  int num_s = 0;                    // S, along u
  int num_t = 0;                    // T, along v
  std::vector<double> us;           // #S increasing sample parameters in [0,1]
  std::vector<double> vs;           // #T increasing sample parameters in [0,1]
  std::vector<glm::dvec3> points;   // #S x #T row-major (k*T + l), model space
  std::vector<int> vertex;          // #S x #T mesh vertex used, or -1 for a barycentric point
  std::vector<base::Warning> warnings;  // e.g. two samples on the same vertex
};

// Samples the region at every (us[k], vs[l]) (uniform or any non-uniform
// increasing lists). Fails on lists that are not increasing in [0,1] or shorter
// than 2, or on a parametrization that does not match `region`.
base::Result<PatchSamples> SampleRegion(std::span<const glm::vec3> positions,
                                        std::span<const glm::uvec3> triangles,
                                        const RegionParametrization& param,
                                        std::span<const double> us, std::span<const double> vs,
                                        SampleMode mode = SampleMode::kBarycentric);

// Hand-picked samples: an S x T grid of mesh vertex indices (row-major). Their
// parameters come from the points themselves (chord length, 3.4).
base::Result<PatchSamples> SampleHandPicked(std::span<const glm::vec3> positions,
                                            std::span<const int> vertices, int num_s, int num_t);

// How the fit assigns a parameter to each sample row and column (3.4).
enum class FitParameterization {
  kSampleGrid,   // the samples' own us, vs
  kChordLength,  // cumulative chord length averaged over rows (columns)
  kCentripetal,  // as chord length with square roots of the distances
};

struct FitOptions {
  int num_u = 6;  // M control points along u, 4 <= M <= S
  int num_v = 6;  // N control points along v, 4 <= N <= T
  FitParameterization parameterization = FitParameterization::kSampleGrid;
  // Least squares only: adds lambda D^T D (D = second differences of the
  // control points) with lambda = smoothing * trace(A^T A) / M; 0 disables.
  // The paper's suggestion is about 1e-3.
  double smoothing = 0.0;
};

struct PatchFit {
  BSplineSurface surface;       // degree 3 x 3, M x N, sigma +1 (see OrientNormal)
  std::vector<double> ub;       // #S parameters the fit used along u
  std::vector<double> vb;       // #T parameters along v
  double max_error = 0.0;       // max |s(ub_k, vb_l) - Q_kl|, model units
  double rms_error = 0.0;       // RMS of the same
  bool interpolating = false;   // S = M and T = N
};

// Tensor-product fit (3.4): every data row in u, then every column of those in
// v, each a small dense solve (interpolation or normal equations). Fails
// (kInvalidArgument) when M > S, N > T or M, N < 4, and (kInternal) on a
// singular system.
base::Result<PatchFit> FitSurface(const PatchSamples& samples, const FitOptions& options);

// Sets the surface's sigma so its normal agrees, on average over the region's
// parameters, with the region's mean normal (3.2).
void OrientNormal(BSplineSurface& surface, const RegionParametrization& param);

}  // namespace deform
