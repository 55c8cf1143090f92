#pragma once
// The SWD rig of a whole body (ALGORITHMS.md 2.3): sweep chains built from the body's
// topological chains (deform/body/body_chains.h, the ones the mannequin's tubes follow),
// junctions where a branch leaves its trunk, and every mesh vertex bound to them.
//
// - Sweeps: one per body chain. A branch chain starts at its branch point on the trunk,
//   so its sweep already starts one bone early (chest -> clavicle -> upper arm -> ...,
//   pelvis -> hip -> thigh -> ...). A chain of more than kMaxSweepBones bones is cut into
//   pieces of at most that many, each next piece starting one bone before the previous
//   one ends (a junction on the shared bone).
// - Junctions: every branch sweep is blended with the trunk sweep over its first bone,
//   u in [0, 1], with SweepJunction::seam_band = the branch's first bone length (the
//   clavicle for an arm, as the SWD author recommends).
// - Twist: downstream everywhere except the wrist/ankle of a limb (upstream: forearm
//   pronation spreads along the forearm).
// - Binding (ALGORITHMS.md 2.3): a mesh made of several connected parts (the mannequin's
//   overlapping tubes) binds each part only to the sweeps of the body chain nearest most
//   of its vertices plus that chain's trunk, so the inner side of a thigh never follows
//   the other leg; a single welded skin is bound to all sweeps (nearest bone segment).
//   With SwdRigOptions::vertex_chains (the mannequin) a tube vertex is bound to the
//   chain and u it was generated at instead. A mesh of several parts has no seam fade
//   (SweepJunction::seam_band = 0), see BuildSwdRig.
// - Limbs (for artifact figures): in a limb chain, the interior joint whose shorter bone
//   is the longest is its elbow/knee, not counting the joint at the end of the chain's
//   first bone (clavicle, pelvis to hip) unless its pair is more than twice as long as
//   any other (a limb without a clavicle); the next joint is its wrist/ankle.
//   Limbs leaving the first point of a spine are legs, other limbs are arms.
//
// Per frame, SwdRigJob turns model-space joint matrices into positions and normals.

#include <span>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "deform/mesh.h"
#include "deform/global/sweep.h"
#include "base/error.h"
#include "mocap/skeleton.h"

namespace deform {

struct SwdRigOptions {
  double max_bend_rad = kDefaultMaxBendRad;  // largest expected bend, sets region widths
  float min_branch_extent = 0.15f;           // as MannequinOptions::min_branch_extent
  // #V, or empty: the body chain and chain coordinate each vertex was generated on
  // (SkinnedMesh::body_chain_coords of a mannequin built for this skeleton, in this bind
  // pose, with this min_branch_extent). A vertex with chain >= 0 is bound to the sweep
  // piece of that chain holding u, at u (offset p0 - c0(u)), so every ring of a tube
  // moves as one cross-section of its own sweep; distance alone can pick the wrong part
  // of a thick tube (the inner side of a hanging upper arm lies nearer the arm chain's
  // start, inside the chest, than its own axis). Vertices with chain -1 (the head) bind
  // by distance.
  std::span<const BodyChainCoord> vertex_chains;
};

// A limb found by topology.
struct SwdLimb {
  int chain = 0;       // sweep chain index
  int middle = 1;      // interior joint k of that chain: elbow/knee (bones k-1, k)
  bool has_end = false;  // the chain has a wrist/ankle at k+1 (interior joint)
  bool arm = false;    // true: arm (or front leg); false: leg leaving the spine's start
};

class SwdRig {
 public:
  std::span<const SweepChain> chains() const { return chains_; }
  std::span<const SweepJunction> junctions() const { return junctions_; }
  std::span<const SweepVertexBinding> bindings() const { return bindings_; }  // #V
  std::span<const glm::vec3> rest_normals() const { return rest_normals_; }   // #V, or empty
  std::span<const SwdLimb> limbs() const { return limbs_; }
  // #J inverse bind-pose joint matrices (model space of the mesh).
  std::span<const glm::mat4> joint_from_bind() const { return joint_from_bind_; }
  int num_joints() const { return static_cast<int>(joint_from_bind_.size()); }
  int num_vertices() const { return static_cast<int>(bindings_.size()); }

 private:
  friend base::Result<SwdRig> BuildSwdRig(const mocap::Skeleton&, std::span<const glm::mat4>,
                                          const Mesh&, const SwdRigOptions&);
  std::vector<SweepChain> chains_;
  std::vector<SweepJunction> junctions_;
  std::vector<SweepVertexBinding> bindings_;
  std::vector<glm::vec3> rest_normals_;
  std::vector<SwdLimb> limbs_;
  std::vector<glm::mat4> joint_from_bind_;
};

// Builds the rig of `bind_mesh` (bind model space) for `skeleton` posed by
// bind_model_from_joint (#J, the pose the mesh was made in). Errors: those of
// BuildBodyChains; kLimitExceeded when the body needs more than kMaxSwdChains sweeps;
// kInvalidArgument when a chain cannot carry a sweep, the mesh is empty or the normals'
// count is not #V.
[[nodiscard]] base::Result<SwdRig> BuildSwdRig(const mocap::Skeleton& skeleton,
                                               std::span<const glm::mat4> bind_model_from_joint,
                                               const Mesh& bind_mesh,
                                               const SwdRigOptions& options = {});

// Binds extra rest points (bind model space), e.g. patch control points, to the rig's
// sweeps the way mesh vertices are (ALGORITHMS.md 2.3: "patch control points bind to
// sweeps exactly like vertices"): point i may use only the sweeps of vertex guides[i]
// (its nearest surface vertex, so the point follows the body part it approximates): that
// vertex's sweep, the trunk of its junction if it has one, and its second sweep. Within
// that set the nearest rest bone segment, the root of g(u) and the junction weight follow
// BindToSweeps. At the bind pose SwdJob rebuilds each point exactly (up to float).
// Errors (kInvalidArgument): sizes that differ, a guide outside 0..#V-1, non-finite points.
[[nodiscard]] base::Result<std::vector<SweepVertexBinding>> BindPointsLikeVertices(
    const SwdRig& rig, std::span<const glm::vec3> points, std::span<const int> guides);

// The per-frame joint state SwdJob reads, from #J rigid model-space joint matrices W_j:
// rotations dQ_j = rotation of W_j B_j^-1 (scale dropped, unit) and positions (W_j's
// translation). SwdRigJob does this first; call it to carry other bindings (patch control
// points) with SwdJob in the same pose. kSizeMismatch when a span is not #J.
[[nodiscard]] base::JobStatus ComputeSwdJointState(const SwdRig& rig,
                                                   std::span<const glm::mat4> model_from_joint,
                                                   std::span<glm::quat> joint_rotations,
                                                   std::span<glm::vec3> joint_positions);

// One frame of the rig over vertices [vertex_begin, vertex_begin + #n). Recomputes the
// joint rotations dQ_j = rotation(W_j B_j^-1) and positions into the caller's scratch, so
// any split of the vertex range gives bit-identical results. Never allocates.
struct SwdRigJob {
  const SwdRig* rig = nullptr;
  std::span<const glm::mat4> model_from_joint;  // #J W_j, rigid, model space
  int vertex_begin = 0;                         // first vertex of the range
  std::span<glm::quat> joint_rotations;         // #J scratch
  std::span<glm::vec3> joint_positions;         // #J scratch
  bool keep_volume = false;                     // see SwdJob::keep_volume
  std::span<glm::vec3> positions;               // #n outputs, model space
  std::span<glm::vec3> normals;                 // #n unit normals (empty: not computed)

  [[nodiscard]] base::JobStatus Run() const;
};

}  // namespace deform
