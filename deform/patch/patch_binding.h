#pragma once
// Vertex binding to a bicubic patch and the per-frame rebuild
// (ALGORITHMS.md 3.5, 3.6; equation (3) of Lee, Kim, Yoon 2009):
//
//   bind (once):    p  ->  (u, v, d),  s(u,v) the orthogonal projection of p,
//                   d = dot(p - s(u,v), n(u,v))
//   rebuild (per frame, control points Q):
//                   p' = sum_{a,b<4} Nu[a] Nv[b] Q_{k-3+a, l-3+b} + d n(u,v)
//
// Stored per bound vertex (structure of arrays, 38 bytes read by the rebuild):
//   u, v, d                     3 floats
//   N_{k-3..k-1}(u), N_{l-3..l-1}(v)   6 floats (the 4th value is 1 - the others:
//                               partition of unity)
//   first control row/column    2 bytes (k-3, l-3)
// plus the mesh vertex index (4 bytes, used by the caller to scatter results,
// not by the rebuild): 42 bytes in all, under the paper's 44. The normal's
// derivative basis values are recomputed from u, v and a per-span table of
// knot constants (8 floats per span and direction, shared by all vertices).
// Records are sorted by span so runs of 8 vertices share one 4x4 block of
// control points; the rebuild evaluates them 8 at a time with AVX when the
// CPU has it, with exactly the scalar path's operations (no FMA), so results
// are bit-identical for any split and any machine.

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "deform/patch/bspline.h"
#include "base/error.h"

namespace deform {

// Floats per span in PatchBinding::span_table_u / _v (see patch_binding.cpp).
inline constexpr int kSpanTableStride = 8;

// Settings of the orthogonal projection (3.5). Defaults are the spec's.
struct ProjectionOptions {
  double abs_tol_rel = 1e-7;    // e1 = abs_tol_rel x patch diagonal (model units)
  double cos_tol = 1e-7;        // e2, zero-cosine tolerance
  int max_iterations = 20;      // Newton / Levenberg-Marquardt steps per start
  int grid_per_span = 4;        // coarse start grid: samples per knot span each way
  double far_rel = 0.25;        // |d| above far_rel x patch diagonal: not bound
};

// One projection result.
struct Projection {
  double u = 0.0, v = 0.0;   // parameters in [0,1]
  double d = 0.0;            // signed distance along the unit normal (model units)
  double residual = 0.0;     // |s(u,v) - p| (model units)
  bool on_border = false;    // clamped to the domain border with a failing cosine test
  int iterations = 0;
};

// Projects p onto the surface by Newton iteration with a Levenberg-Marquardt
// fallback from `start` (clamped to [0,1]^2). Stops per 3.5.
Projection ProjectFrom(const BSplineSurface& surface, const glm::dvec3& p, glm::dvec2 start,
                       const ProjectionOptions& options = {});

// Coarse start grid of a surface (grid_per_span samples per knot span each way).
struct ProjectionGrid {
  std::vector<glm::dvec2> uv;      // #G parameters
  std::vector<glm::dvec3> points;  // #G surface points
};
ProjectionGrid MakeProjectionGrid(const BSplineSurface& surface, int grid_per_span);

// Projects from the best grid point and, if given (non-negative), from the
// vertex's own parameters; keeps the smaller residual.
Projection Project(const BSplineSurface& surface, const ProjectionGrid& grid, const glm::dvec3& p,
                   glm::dvec2 own_uv = glm::dvec2(-1.0), const ProjectionOptions& options = {});

// Read-only view of binding records, which a caller may slice to split the
// rebuild over threads. All per-record spans have the same length #B.
struct PatchBindingView {
  int num_u = 0;                                // M, control points along u (4..255)
  int num_v = 0;                                // N, control points along v (4..255)
  float sigma = 1.0f;                           // normal orientation, +1 or -1
  std::span<const float> span_table_u{};        // (M-3) x kSpanTableStride knot constants
  std::span<const float> span_table_v{};        // (N-3) x kSpanTableStride
  std::span<const float> u{}, v{}, d{};         // #B parameters and signed distance
  std::span<const float> nu0{}, nu1{}, nu2{};       // #B N_{k-3}, N_{k-2}, N_{k-1} at u
  std::span<const float> nv0{}, nv1{}, nv2{};       // #B N_{l-3}, N_{l-2}, N_{l-1} at v
  std::span<const std::uint16_t> first{};       // #B (k-3) | (l-3) << 8

  size_t size() const { return d.size(); }
  // Records [begin, end) (clamped to the size).
  PatchBindingView Slice(size_t begin, size_t end) const;
};

// The bound vertices of one patch (#B records), sorted by span so that runs
// share a 4x4 block of control points; view() gives the job's input.
struct PatchBinding {
  int num_u = 0;                    // M, control points along u of the bound surface
  int num_v = 0;                    // N, control points along v
  float sigma = 1.0f;               // the surface's normal sign, +1 or -1
  std::vector<float> span_table_u;  // (M-3) x kSpanTableStride knot constants (per patch)
  std::vector<float> span_table_v;  // (N-3) x kSpanTableStride
  std::vector<int> vertex;          // #B mesh vertex index of each record (for the caller)
  std::vector<float> u, v;          // #B projection parameters in [0,1]
  std::vector<float> d;             // #B signed distance along n(u,v), model units
  std::vector<float> nu0, nu1, nu2; // #B N_{k-3..k-1}(u); N_k(u) = 1 - their sum
  std::vector<float> nv0, nv1, nv2; // #B N_{l-3..l-1}(v); N_l(v) = 1 - their sum
  std::vector<std::uint16_t> first; // #B (k-3) | (l-3) << 8: the block's first row/column

  size_t size() const { return vertex.size(); }
  PatchBindingView view() const;
  // Bytes per bound vertex that the rebuild reads (38) and that are stored (42).
  static constexpr int kRebuildBytesPerVertex = 9 * 4 + 2;
  static constexpr int kStoredBytesPerVertex = kRebuildBytesPerVertex + 4;
};

// What binding found, besides the records.
struct BindingReport {
  int bound = 0;                     // #B
  std::vector<int> border_vertices;  // mesh indices that project onto the domain border
  std::vector<int> far_vertices;     // mesh indices with |d| > far_rel x diagonal
  double max_abs_d = 0.0;            // over bound vertices (model units)
  double max_rest_error = 0.0;       // max |rebuild at rest - p| over bound vertices
  double patch_diagonal = 0.0;       // control-point bounding-box diagonal
};

struct BindResult {
  PatchBinding binding;
  BindingReport report;
};

// Binds region vertices (mesh indices) to a bicubic surface. `region_uv` is
// #R own parameters (3.2) used as a second Newton start, or empty. Border and
// far vertices are reported and left unbound (the caller keeps their global
// result). Fails on a non-bicubic surface, indices out of range or sizes
// that disagree. The rest rebuild error is measured with PatchRebuildJob.
base::Result<BindResult> BindPatch(const BSplineSurface& surface,
                                   std::span<const glm::vec3> positions,
                                   std::span<const int> region,
                                   std::span<const glm::dvec2> region_uv,
                                   const ProjectionOptions& options = {});

// After knot insertion or refinement (ALGORITHMS.md 7) the surface is the
// same, so every record's (u, v, d) stays valid: this recomputes only the
// spans, basis values and span tables for `refined` and re-sorts the records
// by span (vertex order may change; read PatchBinding::vertex). Fails on a
// non-bicubic surface.
base::Result<PatchBinding> RefreshBinding(const PatchBinding& binding,
                                          const BSplineSurface& refined);

// Float copy of a surface's control points (#M x #N row-major) for the rebuild.
std::vector<glm::vec3> ControlPointsAsFloat(const BSplineSurface& surface);

// Rebuilds bound vertices from control points by equation (3). Reads the
// records in `bindings`; writes #B positions and, optionally, #B unit normals
// n(u,v) of the patch surface (not the mesh normals). Never allocates; the
// result of a record does not depend on how the records are split. Records
// must come from BindPatch / RefreshBinding for a grid of this size: like
// every job, Validate() checks sizes and does not read the span indices.
struct PatchRebuildJob {
  // Inputs.
  std::span<const glm::vec3> control{};  // #M x #N control points Q (row-major, model space)
  PatchBindingView bindings{};           // #B records (any slice of a PatchBinding)
  // Outputs.
  std::span<glm::vec3> positions{};    // #B rebuilt positions (model space)
  std::span<glm::vec3> normals{};      // #B patch normals, or empty

  [[nodiscard]] base::JobStatus Validate() const;
  [[nodiscard]] base::JobStatus Run() const;
};

}  // namespace deform
