#pragma once
// The vertices of an imported glTF mesh at a time of one of its animations,
// evaluated as a glTF viewer does (glTF 2.0, "Morph Targets", then "Skins"):
//
//   1. weights w (#K): the meshes' default weights, replaced by the
//      animation's "weights" channels at t (SampleGltfMorphWeights);
//   2. morphing, in bind space:  p = bind_p + sum_k w_k dP_k,
//                                n = bind_n + sum_k w_k dN_k;
//   3. joint matrices: SampleGltfAnimation(t) -> mocap::LocalToModelJob;
//   4. linear blend skinning of p and n (SkinningJob with the palette
//      model_from_joint[skin_joints[s]] * joint_from_bind[s]);
//   5. normals renormalized (a zero normal stays zero).
//
// Key times are stored as floats: t is rounded to float before it is compared
// with them, so a time that rounds to a key's time gives exactly that key's
// weights (weight 1 on one target and 0 on the others stays exact).
// For a file read with require_skin = false (rigid mesh nodes), step 4 applies
// each mesh node's animated transform.

#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "deform/io/gltf_import.h"
#include "base/error.h"
#include "mocap/pose.h"

namespace deform {

// Morph weights of `animation` at t_s into `weights` (#K =
// model.morph.num_targets): the defaults, then each weights channel of the
// animation evaluated like the TRS channels (first key's value before it,
// last key's after it; LINEAR lerps, STEP holds, CUBICSPLINE is the Hermite
// form of SampleGltfAnimation). animation -1 gives the defaults. Checked with
// PATCHSKIN_CHECK: animation in -1..#animations-1, weights.size() == #K.
void SampleGltfMorphWeights(const GltfModel& model, int animation, double t_s,
                            std::span<float> weights);

// Evaluates one model at any number of times; owns its scratch buffers (no
// allocation after Create), not thread-safe. Keeps a pointer to the model,
// which must outlive it and not change.
class GltfMeshSampler {
 public:
  // Checks the skin weights once (CheckSkinWeights). Errors: kCountMismatch /
  // kBadNumber from that check, naming the model's file.
  static base::Result<GltfMeshSampler> Create(const GltfModel& model);

  // Positions and normals (#V each, model space, file units) at t_s seconds
  // of `animation` (-1: rest pose with the default weights). Errors:
  // kInvalidArgument for an animation index out of range or wrong output sizes.
  base::Status Sample(int animation, double t_s, std::span<glm::vec3> positions,
                      std::span<glm::vec3> normals);

  // The morph weights (#K) and joint matrices (#J) of the last Sample call.
  std::span<const float> weights() const { return weights_; }
  std::span<const glm::mat4> model_from_joint() const { return model_from_joint_; }

 private:
  explicit GltfMeshSampler(const GltfModel& model);

  const GltfModel* model_ = nullptr;
  std::vector<float> weights_;                 // #K
  std::vector<glm::vec3> morphed_positions_;   // #V, bind space
  std::vector<glm::vec3> morphed_normals_;     // #V, bind space
  std::vector<mocap::JointTransform> locals_;  // #J
  std::vector<glm::mat4> model_from_joint_;    // #J
  std::vector<glm::mat4> palette_;             // #S
};

}  // namespace deform
