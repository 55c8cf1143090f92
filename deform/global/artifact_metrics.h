#pragma once
// Measured skinning artifacts (ALGORITHMS.md 2.3, "Artifact figures"), usable for any
// global deformation (SSD, DQS, SWD) given the rest mesh and its deformed positions.
//
// Collapse figure: a ring of vertices around a joint, projected on the plane through
// J_k with normal hat(a_{k-1} + a_k), ordered by angle around its centroid (J_k itself can
// fall outside a strongly bent sweep's section); the polygon's area in
// the deformed pose divided by the same area at rest. 1 = no collapse.
// Candy-wrapper figure: the smallest such ratio over rings along a limb under a pure
// twist (each ring projected on the plane through its axis point, normal the limb axis).
//
// These are analysis functions: they allocate and run in double precision.

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "deform/global/sweep.h"
#include "base/error.h"

namespace deform {

// A plane for ring projection: a point (model space) and a normal (need not be unit).
struct RingPlane {
  glm::dvec3 point{0.0};
  glm::dvec3 normal{0.0, 0.0, 1.0};
};

// The bisector plane at a joint: through `joint`, normal hat(axis_in + axis_out)
// (the unit axes of the bones before and after it).
RingPlane BisectorPlane(const glm::vec3& joint, const glm::vec3& axis_in,
                        const glm::vec3& axis_out);

// Area of the polygon made of positions[ring[i]] projected on `plane`, ordered by angle
// around the projected points' centroid (model units squared). 0 for fewer than 3 points.
double ProjectedRingArea(std::span<const glm::vec3> positions,
                         std::span<const std::uint32_t> ring, const RingPlane& plane);

// A ring of vertex indices with its rest and deformed projection planes.
struct ArtifactRing {
  std::vector<std::uint32_t> vertices;  // indices into the position arrays, >= 3
  RingPlane rest_plane;                 // plane at the bind pose
  RingPlane plane;                      // the same plane carried to the deformed pose
};

// Deformed area / rest area of one ring. Errors (kInvalidArgument): sizes differ,
// fewer than 3 vertices, an index past the arrays, or a rest area below 1e-12.
base::Result<double> RingAreaRatio(std::span<const glm::vec3> rest_positions,
                                   std::span<const glm::vec3> positions, const ArtifactRing& ring);

// Collapse figure of one joint ring (= RingAreaRatio).
base::Result<double> CollapseFigure(std::span<const glm::vec3> rest_positions,
                                    std::span<const glm::vec3> positions, const ArtifactRing& ring);

// Candy-wrapper figure: the minimum RingAreaRatio over `rings` (at least one).
base::Result<double> CandyWrapperFigure(std::span<const glm::vec3> rest_positions,
                                        std::span<const glm::vec3> positions,
                                        std::span<const ArtifactRing> rings);

// Volume enclosed by `triangles` (a section of a closed skin, e.g. a limb between two
// rings, wound consistently) after closing every boundary loop with a fan from the
// centroid of the cap ring that holds it (model units cubed, absolute value). Every
// boundary edge (one used by a single triangle) must have both ends in one ring of
// `caps`. Errors (kInvalidArgument): index past the positions, an open boundary edge
// outside the caps, no triangles.
base::Result<double> CappedVolume(std::span<const glm::vec3> positions,
                                  std::span<const glm::uvec3> triangles,
                                  std::span<const std::vector<std::uint32_t>> caps);

// Volume figure: CappedVolume(positions) / CappedVolume(rest_positions) over the same
// triangles and caps (e.g. the limb within a few units of a joint). 1 = volume kept.
base::Result<double> VolumeFigure(std::span<const glm::vec3> rest_positions,
                                  std::span<const glm::vec3> positions,
                                  std::span<const glm::uvec3> triangles,
                                  std::span<const std::vector<std::uint32_t>> caps);

// Vertices within `half_thickness` of `plane` (rest positions, model units): the ring
// "nearest the rest bisector plane" used for SSD and DQS.
std::vector<std::uint32_t> RingNearPlane(std::span<const glm::vec3> rest_positions,
                                         const RingPlane& plane, double half_thickness);

// Vertices whose primary sweep binding is on `chain` with |u - u_centre| < half_width
// (the SWD ring, default half-width 0.02; use SweepChain::joint_parameter(k) as the centre,
// which is k itself only for bones of proportional region widths).
std::vector<std::uint32_t> RingNearParameter(std::span<const SweepVertexBinding> bindings,
                                             int chain, float u_centre,
                                             float half_width = 0.02f);

}  // namespace deform
