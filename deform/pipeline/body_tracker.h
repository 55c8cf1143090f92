#pragma once
// Where the body is, cheaply, for whoever frames it (render/camera_plan.h): the
// joints at a time and a sparse hull of the skin, without deforming the mesh.
//
// The hull: for every skin joint, the vertices it moves (weight >= 0.25) that
// lie furthest along 98 directions of its bind frame (those of a 5x5x5 grid),
// so the hull turns with the part and covers its bends; tracked vertices (a
// camera's region) are added. Each frame those points are skinned with their
// own weights (SSD), so they are exactly where the SSD body has them, and the
// hull's bounds lie inside the SSD body's bounds, short of them by under 1.5%
// of the body's size on every capture of ../shared/data (tested). The demo
// body's hull is 6% of its vertices.
//
// Cost: Create O(98 #V); Sample O(#J + #H + #T) for the #H hull points and #T
// tracked vertices. Not thread-safe (keeps its buffers).

#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "base/error.h"
#include "deform/global/global_skinning.h"
#include "deform/mesh.h"
#include "deform/pipeline/character.h"

namespace deform {

// The body at one time, world space.
struct TrackedBody {
  std::vector<glm::vec3> joint_positions;  // #J
  Bounds hull_bounds;                      // of the hull points (inside the body's bounds)
  std::vector<glm::vec3> tracked;          // the tracked vertices, in the order given
};

class BodyTracker {
 public:
  // The tracker of `character` (which must outlive it), following the mesh
  // vertices `tracked` besides the hull. kInvalidArgument when a tracked index
  // is not a vertex of the mesh.
  static base::Result<BodyTracker> Create(const Character& character, std::span<const int> tracked);

  // The body at time_s seconds from the motion's first frame (clamped), as the
  // SSD frame pipeline would pose it. Errors: kInternal from the jobs.
  base::Status Sample(double time_s, TrackedBody& out);

  // The mesh vertices the hull is made of (sorted, unique).
  std::span<const int> hull_vertices() const { return hull_vertices_; }

 private:
  explicit BodyTracker(const Character& character) : character_(&character) {}

  const Character* character_;
  std::vector<int> hull_vertices_;
  int num_tracked_ = 0;
  // Hull points then tracked vertices: their rest positions and weights.
  std::vector<glm::vec3> rest_;
  SkinWeights weights_;
  CharacterPose pose_;
  SkinningPalettes palettes_;
  std::vector<glm::vec3> posed_;
};

}  // namespace deform
