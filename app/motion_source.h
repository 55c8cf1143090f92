#pragma once
// Loading what the user points a command at: a BVH capture or a glTF character
// with its animation, into the runtime Skeleton and Motion (plus the glTF's
// skinned mesh). The format follows the file extension.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "deform/io/gltf_import.h"
#include "base/error.h"
#include "mocap/motion.h"
#include "mocap/skeleton.h"

namespace app {

struct MotionSourceOptions {
  float scale = 1.0f;                  // BVH: length factor; 0 = detected units to metres
  bool y_up = false;                   // BVH: rotate a Z-up capture to Y-up
  bool add_position_to_offset = false; // BVH: position channels add to OFFSET
  bool allow_short_motion = false;     // BVH: load the frames present when fewer than declared
  int animation = 0;                   // glTF: which animation drives the skeleton
  double frame_time_s = 0.0;           // glTF: sampling step; 0 = detected from the key times
  std::optional<mocap::UpAxis> up = std::nullopt;  // BVH: the file's up axis (--up); empty = detected
  bool require_skin = true;            // glTF: false also reads a file without a skin (its
                                       // meshes rigid on their nodes, e.g. an exported .glb)
};

struct MotionSource {
  std::string format;                  // "bvh", "gltf" or "glb"
  mocap::Skeleton skeleton;
  mocap::Motion motion;
  std::vector<base::Warning> warnings;
  std::optional<deform::GltfModel> gltf;  // the character, for glTF inputs
  int mesh_vertices = 0;
  int mesh_triangles = 0;
};

// Reads `path`. Errors (kIo for a missing file or a directory, kUnsupported for
// an unknown extension, anything the readers report) name the file.
base::Result<MotionSource> LoadMotionSource(const std::string& path,
                                            const MotionSourceOptions& options);

// Parses BVH text held in memory (the built-in demo); `name` labels messages.
base::Result<MotionSource> LoadBvhText(std::string_view text, const std::string& name,
                                       const MotionSourceOptions& options);

}  // namespace app
