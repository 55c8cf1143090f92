#pragma once
// Steps of the glTF import that work on our own types only (no tinygltf):
// node-matrix decomposition, the skeleton's channel layout, weight
// normalization and the rest height.

#include <array>
#include <glm/glm.hpp>
#include <span>

#include "mocap/pose.h"
#include "mocap/skeleton.h"

namespace deform::internal {

// T * R * S of a finite affine matrix (column vectors). A negative determinant
// goes into scale.x; a zero scale axis gives the identity rotation. Sets
// *dropped_shear when T * R * S differs from m by more than 1e-4 (relative),
// i.e. the matrix had shear or a projective row that TRS cannot hold.
mocap::JointTransform DecomposeMatrix(const glm::dmat4& m, bool* dropped_shear);

// Gives every joint the channels some animation drives, in joint order:
// translation (kX/Y/ZPosition), rotation (kQuatX..W), scale (kX/Y/ZScale).
// driven[j] = {translation, rotation, scale}; #J entries. Sets num_channels.
void AssignChannelLayout(std::span<const std::array<bool, 3>> driven, mocap::Skeleton& skeleton);

// Scales each row of `influences` weights (#V x influences) to sum 1. A row
// summing to 0 gets weight 1 in its first slot. Returns how many rows that was.
int NormalizeWeightRows(std::span<float> weights, int influences);

// Extent along +Y of the joint origins in the rest pose (0 for no joints).
float RestHeight(const mocap::Skeleton& skeleton);

}  // namespace deform::internal
