#pragma once
// The fold measure of issue 26 [ours]: how sharply a posed mesh creases inside
// a patch region, as the largest angle between the normals of two neighbouring
// triangles (triangles sharing an edge) among the region's triangles:
//
//   fold = max over shared edges e = (t1, t2) of  acos(dot(n_t1, n_t2))   (degrees)
//
// n_t = hat(cross(p1 - p0, p2 - p0)); degenerate (zero-area) triangles are
// skipped. A smooth surface sampled finely gives small angles; a crease or a
// fold-over gives angles up to 180. The criterion compares it with the
// global (patch-free) result's measure on the same triangles: the layer must not
// add more than 10 degrees at any frame. Cost O(#t log #t) for #t region triangles.

#include <span>
#include <vector>

#include <glm/glm.hpp>

namespace deform {

// Indices of the triangles whose three vertices are all in `region` (mesh
// vertex indices, any order; duplicates allowed). #T triangles, #V vertices;
// indices of `region` outside 0..#V-1 are ignored.
std::vector<int> RegionTriangles(std::span<const glm::uvec3> triangles, std::span<const int> region,
                                 int num_vertices);

// The fold measure (degrees, in [0, 180]) of the triangles `subset` (indices
// into `triangles`) over `positions` (#V, any space). Only edges shared by two
// triangles of the subset count; 0 when there is none. Triangle indices out of
// range are skipped.
double MaxFoldAngleDeg(std::span<const glm::vec3> positions, std::span<const glm::uvec3> triangles,
                       std::span<const int> subset);

// The fold a layer adds where it acts: the largest increase, over the shared
// edges of `subset`, of the angle between the two triangles' normals from
// `before` (the global result) to `after` (with the layer), in degrees (may be
// negative when the layer only smooths). Unlike comparing two MaxFoldAngleDeg
// figures it is local: a new crease beside a region's existing sharpest edge
// (the inner crease of a bent elbow) counts. Edges with a degenerate triangle
// in either pose are skipped; 0 when no edge counts.
double MaxAddedFoldAngleDeg(std::span<const glm::vec3> before, std::span<const glm::vec3> after,
                            std::span<const glm::uvec3> triangles, std::span<const int> subset);

}  // namespace deform
