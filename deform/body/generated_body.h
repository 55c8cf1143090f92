#pragma once
// The generated body: one closed, smooth, manifold skin for any skeleton, with automatic
// weights. The default body of a capture without a mesh (BVH).
//
//   skeleton + rest matrices
//     -> BuildImplicitBody   (deform/body/implicit_body.h: round cones and ellipsoids per
//                             bone and muscle, smooth union)
//     -> MeshImplicitBody    (deform/body/body_mesher.h: OpenVDB narrow band, volumeToMesh)
//     -> ComputeBoneHeatWeights (deform/body/bone_heat.h: Baran and Popovic 2007)
//     -> SkinnedMesh: mesh in the model space of the rest matrices, 4 influences, skin
//        joints = the joints that own a bone (ascending), joint_from_bind their inverse
//        rest matrices; body_chain_coords empty (one welded skin binds to SWD's sweeps by
//        distance).
//
// Cost: about 0.5 s for a 30-joint humanoid on one core (bench/body_bench.cpp).
// Deterministic: the same skeleton, matrices and options give the same bytes whatever
// the thread count.

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include <glm/glm.hpp>

#include "deform/body/body_mesher.h"
#include "deform/body/bone_heat.h"
#include "deform/body/implicit_body.h"
#include "deform/mesh.h"
#include "base/error.h"
#include "mocap/skeleton.h"

namespace deform {

struct GeneratedBodyOptions {
  ImplicitBodyOptions shape;
  BodyMeshOptions mesh;
  BoneHeatOptions weights;
};

// Errors: those of the three steps (each names the joint or option at fault).
[[nodiscard]] base::Result<SkinnedMesh> BuildGeneratedBody(
    const mocap::Skeleton& skeleton, std::span<const glm::mat4> rest_model_from_joint,
    const GeneratedBodyOptions& options = {});

// A 64-bit key of everything the body depends on: the format version, the skeleton's
// parents, end sites and up axis, the rest matrices' bytes and the options.
std::uint64_t GeneratedBodyKey(const mocap::Skeleton& skeleton,
                               std::span<const glm::mat4> rest_model_from_joint,
                               const GeneratedBodyOptions& options);

// The folder of the body cache: $PATCHSKIN_CACHE_DIR, else $XDG_CACHE_HOME/patchskin, else
// $HOME/.cache/patchskin; empty (no cache) when PATCHSKIN_CACHE_DIR is "off" or no folder
// can be named.
std::filesystem::path BodyCacheFolder();

// BuildGeneratedBody through a file cache in `folder` (empty: no cache): a body built
// once for a skeleton in a rest pose is read back (body-<key>.bin) instead of generated
// again. A missing, unreadable or mismatched cache file means generate; the file is
// written atomically (a temporary file renamed), and a failure to write is ignored.
// `from_cache`, when given, says whether the body came from the cache.
[[nodiscard]] base::Result<SkinnedMesh> BuildGeneratedBodyCached(
    const mocap::Skeleton& skeleton, std::span<const glm::mat4> rest_model_from_joint,
    const GeneratedBodyOptions& options, const std::filesystem::path& folder,
    bool* from_cache = nullptr);

}  // namespace deform
