#pragma once
// Reading of morph targets and "weights" animation channels for the glTF
// import (glTF 2.0, "Morph Targets" and "Animations"). Everything read is
// checked first (deform/io/internal/gltf_view.h); errors name the file and the
// glTF field, e.g. "body.glb: meshes[0].primitives[0].targets[3].POSITION".

#include <cstddef>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "deform/io/gltf_import.h"
#include "base/error.h"

namespace tinygltf {
class Model;
}

namespace deform::internal {

// The morph targets of one primitive.
struct PrimitiveTargets {
  int num_targets = 0;               // #K (0: the primitive has none)
  std::vector<glm::vec3> positions;  // #K x #V POSITION deltas (zeros where a target has none)
  std::vector<glm::vec3> normals;    // #K x #V NORMAL deltas, or empty when no target has NORMAL
};

// Reads meshes[mesh].primitives[prim].targets for a primitive of
// `num_vertices` vertices: POSITION and NORMAL deltas as float VEC3 accessors
// with one element per vertex, dense, sparse, or without a buffer view
// (zeros). TANGENT and other attributes are skipped with a warning.
// kLimitExceeded when #K x #V exceeds max_values (checked before allocating).
base::Result<PrimitiveTargets> ReadPrimitiveTargets(const tinygltf::Model& model,
                                                    const std::string& path, int mesh, int prim,
                                                    std::size_t num_vertices,
                                                    std::size_t max_values,
                                                    std::vector<base::Warning>& warnings);

// The default weights of meshes[mesh]: its `weights` (exactly num_targets
// finite numbers) or zeros when absent.
base::Result<std::vector<float>> ReadDefaultWeights(const tinygltf::Model& model,
                                                    const std::string& path, int mesh,
                                                    int num_targets);

// Reads the sampler of a channel whose target.path is "weights": input key
// times (float SCALAR, >= 0, non-decreasing) and output values (float or
// normalized integer SCALAR, #keys x num_targets, x 3 for CUBICSPLINE).
// Errors name the sampler ("animations[0].samplers[1]"). Fills
// everything of the channel except first_target.
base::Result<GltfWeightsChannel> ReadWeightsSampler(const tinygltf::Model& model,
                                                    const std::string& path, int animation,
                                                    int sampler, int num_targets);

}  // namespace deform::internal
