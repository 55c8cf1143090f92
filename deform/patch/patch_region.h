#pragma once
// Patch regions (ALGORITHMS.md 3.1): which skin vertices a patch covers.
//
// Two of the three selections live here: joint + radius and an explicit vertex
// list. The paper's sketch (a screen rectangle in a view, visible front-facing
// vertices only) needs the rasterizer's depth buffer and so lives in render/
// (render/raster/region_select.h); it returns the same kind of list.
//
// A region is a sorted list of unique mesh vertex indices (model space of the
// mesh's bind pose). Regions are setup data: these functions allocate.

#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "deform/mesh.h"
#include "base/error.h"

namespace deform {

// Joint + radius [ours]: vertices of the bind mesh within `radius` (model
// units) of `centre` (model space, usually the joint's bind position) whose
// summed skin weight on `bone_joints` (skeleton joint indices, e.g. the joint
// and its parent: the two bones meeting there) is at least `min_bone_weight`.
// If `side` is nonzero, only vertices whose bind normal n has
// dot(n, hat(side)) >= cos(half_angle_deg) are kept: a limb region must stay a
// partial tube (< 300 degrees) for the cylinder map (3.2).
struct JointRegionQuery {
  std::vector<int> bone_joints;      // skeleton joint indices; at least one
  glm::vec3 centre{0.0f};            // model space
  float radius = 0.0f;               // model units, > 0
  float min_bone_weight = 0.5f;      // in (0, 1]
  glm::vec3 side{0.0f};              // model space direction, or zero: any side
  float half_angle_deg = 180.0f;     // in (0, 180]; 180 keeps every side
};

// Errors (kInvalidArgument): radius or weight out of range, no bone joints, a
// mesh whose arrays disagree; (kNotFound): no vertex qualifies.
base::Result<std::vector<int>> SelectJointRegion(const SkinnedMesh& mesh,
                                                 const JointRegionQuery& query);

// Explicit list: checks every index is in [0, num_vertices) and appears once,
// returns the list sorted. Errors (kInvalidArgument) name the first bad entry
// by position ("vertex 3 (index 912) is past the 800 vertices").
base::Result<std::vector<int>> CheckVertexRegion(std::span<const int> vertices, int num_vertices);

}  // namespace deform
