#pragma once
// The implicit body: a signed distance around a skeleton's bones, the shape the generated
// body is meshed from (deform/body/body_mesher.h).
//
// Inputs: a skeleton and its rest (bind) model-space matrices. Output: a list of solid
// primitives, each a tapered capsule (round cone: the convex hull of two spheres) or an
// oriented ellipsoid, and their smooth union
//     d(p) = smin_k(d_1(p), d_2(p), ...) over groups of parts (below),   smin_k(a, b) = min(a, b) - k/4 max(0, 1 - |a-b|/k)^2 k
// with a blend radius k proportional to the thinner of the two parts it joins (a finger
// does not swell where it meets the palm as much as a thigh meets the pelvis).
//
// Shape (lengths from the bone lengths and S, the body size of deform/body/body_chains.h):
//  - Every body chain (deform/body/body_chains.h: spine, neck/head, arms, legs, tails found by
//    topology) gets one round cone per bone; radii taper along a limb from its length,
//    a spine's trunk is thick up to its last big branch, a head ellipsoid ends each torso
//    spine.
//  - A humanoid (upright spine, a pair of legs at its start, a pair of arms higher up)
//    gets anatomical radii per limb bone and volumes for the pelvis, buttocks, belly,
//    chest, deltoids, biceps, forearm and calf muscles, heels, hands and feet. Front and
//    back come from the toes (or, without feet, from the knees' bend).
//  - A quadruped or any other topology keeps the generic chain shape (trunk, legs, tail,
//    head), so it gets a plausible body, never an error for its topology.
//
// Cost: building is O(#J); one distance evaluation is O(primitives near p) through a
// coarse cell grid (Distance); the whole body evaluates in well under a microsecond per
// point for a 30-joint humanoid.

#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "base/error.h"
#include "mocap/skeleton.h"

namespace deform {

struct ImplicitBodyOptions {
  float min_branch_extent = 0.15f;  // as MannequinOptions: side branches folded into mittens
  float blend = 0.5f;               // smooth-union radius in units of the thinner part's radius, 0..2
  float radius_scale = 1.0f;        // multiplies every radius, 0.5..2
};

enum class BodyPrimitiveKind { kRoundCone, kEllipsoid };

struct BodyPrimitive {
  BodyPrimitiveKind kind = BodyPrimitiveKind::kRoundCone;
  // Round cone: spheres of radius r0 at a and r1 at b. Ellipsoid: centre a, semi-axes
  // radii.x along axes[0], radii.y along axes[1], radii.z along axes[2] (orthonormal).
  glm::vec3 a{0.0f}, b{0.0f};
  float r0 = 0.0f, r1 = 0.0f;
  glm::mat3 axes{1.0f};
  glm::vec3 radii{0.0f};
  float thickness = 0.0f;  // its smallest radius (model units)
  // Parts of one group (the bones of one chain, whose round cones meet in shared spheres
  // of equal radius: already a smooth tube) join with a plain min, so hundreds of short
  // bones do not pile up smooth-union bulges; groups blend with each other with a
  // radius set by the group's mean thickness.
  int group = 0;
  float group_thickness = 0.0f;
  glm::vec3 box_min{0.0f}, box_max{0.0f};  // bounds of the solid, model units
};

// A bone of the body's chains, for weights: the segment a -> b turns with `joint`.
struct BodyBone {
  glm::vec3 a{0.0f}, b{0.0f};
  int joint = -1;   // skeleton joint index
  int chain = -1;   // BodyChains chain index
  int k = 0;        // bone k of that chain (points k -> k+1)
};

class ImplicitBody {
 public:
  // Signed distance estimate at p (model units; negative inside). Exact for one round
  // cone, a bound for ellipsoids and near blends; far from every primitive it returns
  // a positive value no larger than the true distance (the cell grid's margin).
  float Distance(const glm::vec3& p) const;

  std::span<const BodyPrimitive> primitives() const { return primitives_; }
  std::span<const BodyBone> bones() const { return bones_; }
  float size() const { return size_; }              // S, model units
  bool humanoid() const { return humanoid_; }
  glm::vec3 box_min() const { return box_min_; }    // bounds of all primitives
  glm::vec3 box_max() const { return box_max_; }
  float max_blend() const { return max_blend_; }    // largest smooth-union radius k

 private:
  friend base::Result<ImplicitBody> BuildImplicitBody(const mocap::Skeleton&,
                                                      std::span<const glm::mat4>,
                                                      const ImplicitBodyOptions&);
  void BuildCells();

  std::vector<BodyPrimitive> primitives_;
  std::vector<BodyBone> bones_;
  float size_ = 0.0f;
  float blend_ = 0.5f;
  float max_blend_ = 0.0f;
  bool humanoid_ = false;
  glm::vec3 box_min_{0.0f}, box_max_{0.0f};
  // Coarse cells over the bounds: per cell, the primitives whose box (grown by the
  // blend radius and `margin_`) overlaps it, ascending (so evaluation order is fixed).
  glm::ivec3 cells_{0};
  float cell_size_ = 1.0f;
  float margin_ = 0.0f;
  std::vector<int> cell_begin_;  // #cells + 1
  std::vector<int> cell_items_;
};

// Builds the implicit body. Errors: those of BuildBodyChains (kCountMismatch, kNonFinite,
// kInvalidArgument naming a joint where one is to blame), kInvalidArgument for options
// out of range, kLimitExceeded for more than 4096 primitives.
[[nodiscard]] base::Result<ImplicitBody> BuildImplicitBody(
    const mocap::Skeleton& skeleton, std::span<const glm::mat4> rest_model_from_joint,
    const ImplicitBodyOptions& options = {});

// Signed distance to one primitive (exact for a round cone, a close bound for an
// ellipsoid); exposed for tests.
float PrimitiveDistance(const BodyPrimitive& primitive, const glm::vec3& p);

// The smooth minimum above (k > 0), and min(a, b) for k <= 0.
float SmoothMin(float a, float b, float k);

}  // namespace deform
