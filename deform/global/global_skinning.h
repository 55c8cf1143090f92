#pragma once
// The global layer (ALGORITHMS.md 2) behind one interface: skinning by blended
// matrices (SSD), by blended dual quaternions (DQS), or by sweeps along the
// body's chains (SWD). Callers pose it once per frame, then skin vertex ranges
// and carry points bound like the skin (a patch's control points); which job
// runs is decided here only.
//
// Cost per frame: Pose is O(#S) (SSD, DQS) or O(#J) (SWD); SkinVertices and
// CarryPoints are those of the jobs they run (skinning_job.h, dqs_job.h,
// swd_job.h). Any split of a vertex range gives the same bits.

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "base/error.h"
#include "deform/global/dqs_job.h"
#include "deform/global/swd_rig.h"
#include "deform/mesh.h"
#include "mocap/skeleton.h"

namespace deform {

enum class GlobalMethod { kSsd, kDqs, kSwd };

// "ssd", "dqs" or "swd".
const char* GlobalMethodName(GlobalMethod method);

// The palettes of the weight-blended methods at one pose.
struct SkinningPose {
  std::span<const glm::mat4> model_from_bind{};  // #S SSD palette (BuildSkinningPalette)
  std::span<const DualQuat> dual_quats{};        // #S DQS palette, or empty: SSD
};

// The same, owned: built for a pose by Update.
struct SkinningPalettes {
  std::vector<glm::mat4> model_from_bind;  // #S
  std::vector<DualQuat> dual_quats;        // #S with DQS, empty with SSD

  // Palettes of `mesh` at the pose model_from_joint (#J); `dqs` adds the dual
  // quaternions. Sizes are those of mesh.skin_joints.
  [[nodiscard]] base::JobStatus Update(std::span<const glm::mat4> model_from_joint,
                                       const SkinnedMesh& mesh, bool dqs);
  SkinningPose view() const { return {model_from_bind, dual_quats}; }
};

// Points [begin, end) skinned by their weights at `pose` (DqsJob when
// pose.dual_quats is set, else SkinningJob): rest_positions, weights and the
// outputs are whole arrays, indexed from 0. rest_normals and normals may be
// empty (no normals). Errors: those of the job.
[[nodiscard]] base::JobStatus SkinPoints(const SkinningPose& pose, const SkinWeights& weights,
                                         std::span<const glm::vec3> rest_positions,
                                         std::span<const glm::vec3> rest_normals, int begin,
                                         int end, std::span<glm::vec3> positions,
                                         std::span<glm::vec3> normals);

// Rest points that follow the skin (bind model space): by skin weights with SSD
// and DQS, by the sweeps of a guide vertex with SWD. Refers to the rest points
// and weights given to BindPoints, which must outlive it.
struct SkinBoundPoints {
  std::span<const glm::vec3> rest;         // #P
  const SkinWeights* weights = nullptr;    // #P entries (SSD, DQS)
  std::vector<SweepVertexBinding> sweeps;  // #P (SWD)
};

class GlobalSkinning {
 public:
  // The layer for `mesh` (bound in the pose bind_model_from_joint, #J; read by
  // SWD only, which builds its sweeps there, with mesh.body_chain_coords).
  // Errors: those of BuildSwdRig.
  static base::Result<GlobalSkinning> Create(GlobalMethod method, const mocap::Skeleton& skeleton,
                                             std::span<const glm::mat4> bind_model_from_joint,
                                             const SkinnedMesh& mesh);

  GlobalMethod method() const { return method_; }

  // Sets this frame's pose, before any SkinVertices or CarryPoints: the
  // palettes (SSD, DQS) or the sweeps' joint state (SWD) of model_from_joint.
  [[nodiscard]] base::JobStatus Pose(std::span<const glm::mat4> model_from_joint);

  // Vertices [begin, end) of the mesh at the pose, into the same entries of
  // positions and normals (#V each; normals may be empty, and are left alone
  // when the mesh has no bind normals). Ranges may run on several threads at once.
  [[nodiscard]] base::JobStatus SkinVertices(int begin, int end, std::span<glm::vec3> positions,
                                             std::span<glm::vec3> normals) const;

  // Binds rest points to follow the skin: `weights` (#P) for SSD and DQS;
  // with SWD each point takes the sweeps of guides[i], a mesh vertex
  // (BindPointsLikeVertices). Errors: kInvalidArgument from the SWD binding.
  base::Result<SkinBoundPoints> BindPoints(std::span<const glm::vec3> rest,
                                           const SkinWeights& weights,
                                           std::span<const int> guides) const;
  // The bound points at the pose (#P).
  [[nodiscard]] base::JobStatus CarryPoints(const SkinBoundPoints& points,
                                            std::span<glm::vec3> out) const;

  // The SSD and DQS palettes at the pose, the frames example shapes turn in
  // (ALGORITHMS.md 4.3); empty with SWD.
  SkinningPose palettes() const { return palettes_.view(); }

 private:
  GlobalSkinning(GlobalMethod method, const SkinnedMesh& mesh) : method_(method), mesh_(&mesh) {}
  // SWD at the posed joint state, for bound points (vertices or others).
  [[nodiscard]] base::JobStatus Sweep(std::span<const SweepVertexBinding> bindings,
                                      std::span<const glm::vec3> rest_normals,
                                      std::span<glm::vec3> positions,
                                      std::span<glm::vec3> normals) const;

  GlobalMethod method_;
  const SkinnedMesh* mesh_;
  SkinningPalettes palettes_;             // SSD, DQS
  std::optional<SwdRig> swd_;             // SWD
  std::vector<glm::quat> swd_rotations_;  // #J, SWD joint state
  std::vector<glm::vec3> swd_positions_;  // #J
};

}  // namespace deform
