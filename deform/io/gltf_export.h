#pragma once
// glTF 2.0 (.glb) export of a deformed mesh sequence: one file that Blender,
// three.js and other viewers open as an animated mesh.
//
// Two layouts (the smaller one is chosen unless the caller forces one):
//
//  * kMorphTargets: one mesh whose base attributes are frame 0's positions and
//    normals, with one morph target per exported frame k (POSITION and NORMAL
//    deltas = frame k - frame 0; target 0 is all zero, stored as accessors
//    without a buffer view, which the specification defines as zeros), and an
//    animation of the
//    mesh node's `weights`: key k at time k * frame_time_s holds weight 1 for
//    target k and 0 for all others. LINEAR interpolation (default) blends two
//    neighbouring frames between keys, which is the linear interpolation of
//    their vertices; STEP holds frame k until the next key. Either way, at key
//    k's time exactly frame k is shown. The mesh's `extras.targetNames` names
//    the targets "frame_NNNN" (Blender uses them for shape keys).
//  * kBakedMeshes: one mesh per frame (sharing the index and colour accessors)
//    on its own node under a root node; a STEP `scale` animation shows node k
//    (scale 1) from key k's time until key k+1's and hides it (scale 0)
//    otherwise. Static viewers see frame 0.
//
// Sizes: both cost 24 bytes x #V per frame (morph: the base plus F-1 targets;
// baked: F meshes). On top, morph stores 4 x #F^2 bytes of (dense) weights and
// ~330 bytes of JSON per frame, baked ~935 bytes of JSON and keys per frame, so
// morph is smaller up to about 150 frames and baked beyond, whatever #V (the
// difference is small next to the vertex data either way).
// EstimateGltfExportBytes gives both figures.
//
// A camera (AddCameraFrame) is written as a glTF perspective camera on its own
// node "camera" in the scene, its translation and rotation keyed at every
// frame's time (LINEAR; rotations are unit quaternions, so viewers slerp):
// viewers that follow a scene's camera show the exported frames as `render`
// framed them.
//
// Units and axes are the caller's (glTF expects metres, +Y up). Every accessor
// POSITION carries min/max as the specification requires.
//
// Memory: frame data is not held. AddFrame appends each frame's bytes to an
// unnamed scratch file (in options.scratch_dir; it vanishes when closed, even
// on a crash); Finish writes the .glb under a temporary name (header, the JSON
// from tinygltf, then the binary chunk copied from the scratch file in 1 MiB
// blocks) and renames it into place. What stays in memory grows by about 1 KB
// of accessor/view/mesh descriptions per frame whatever #V (plus, for morph,
// frame 0's positions and normals, 24 x #V bytes, to form the deltas, and one
// #F-float row of weights at Finish). The file is limited to 4 GiB (GLB's
// 32-bit lengths; kLimitExceeded).

#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "deform/mesh.h"
#include "base/error.h"

namespace deform {

enum class GltfExportLayout : std::uint8_t { kAuto, kMorphTargets, kBakedMeshes };
const char* GltfExportLayoutName(GltfExportLayout layout);  // "auto", "morph", "baked"

// The lens of an exported camera (glTF 2.0 "cameras", perspective).
struct GltfCameraLens {
  float yfov_rad = 0.6f;     // vertical field of view, 0 < yfov < pi
  float aspect = 16.0f / 9;  // width / height, > 0
  float znear = 0.01f;       // > 0
  float zfar = 1000.0f;      // > znear
};

struct GltfExportOptions {
  double frame_time_s = 1.0 / 30.0;             // seconds between exported frames, > 0
  GltfExportLayout layout = GltfExportLayout::kAuto;
  bool step_interpolation = false;              // morph weights: STEP instead of LINEAR
  std::string generator = "patchskin";          // asset.generator
  std::string mesh_name = "body";               // mesh and node name
  // Folder for the scratch file holding the binary data until Finish; empty =
  // the system's temporary folder. Best: the output's folder (same disk).
  std::string scratch_dir = "";
  // With a lens, every frame also gets a camera pose (AddCameraFrame).
  std::optional<GltfCameraLens> camera = std::nullopt;
};

// Estimated file sizes in bytes of both layouts (binary data exact, JSON
// approximated per frame).
struct GltfExportEstimate {
  std::size_t morph_bytes = 0;
  std::size_t baked_bytes = 0;
};
GltfExportEstimate EstimateGltfExportBytes(int num_vertices, int num_triangles, int num_frames,
                                           bool with_colors);

// What a textured mesh adds to the file (both empty: an untextured export, as before).
//  * uvs: TEXCOORD_0 of every primitive (one accessor shared by all frames).
//  * materials: each material becomes a glTF material (baseColorFactor, metallic 0,
//    baseColorTexture with its sampler's wrap modes, the image's encoded bytes
//    embedded in the binary chunk), and the triangles are grouped into one
//    primitive per material (in order of first use; one material keeps the
//    triangle order). The primitives share the vertex attributes. Colours passed
//    to Create are albedo with the factor folded in (as the importer gives them),
//    so COLOR_0 is written as colour / factor (left out when that is all ones):
//    importing the file gives the same albedo back.
struct GltfExportSurface {
  std::span<const glm::vec2> uvs{};          // #V, or empty
  const MeshMaterials* materials = nullptr;  // or null; triangle_material #T or empty
};

// Builds the file frame by frame:
//   auto w = GltfSequenceWriter::Create(tris, colors, nv, nf, options);
//   for each frame: w->AddFrame(positions, normals);
//   w->Finish("out.glb");
class GltfSequenceWriter {
 public:
  GltfSequenceWriter(GltfSequenceWriter&&) noexcept;
  GltfSequenceWriter& operator=(GltfSequenceWriter&&) noexcept;
  ~GltfSequenceWriter();

  // triangles: #T, indices < num_vertices; colors: #V linear RGB or empty;
  // num_frames: how many AddFrame calls will follow (>= 1), which fixes the
  // layout when options.layout is kAuto; surface: uvs and materials (above).
  // Errors: kInvalidArgument (also: a texture whose image has no encoded bytes),
  // kIo (the scratch file cannot be created).
  static base::Result<GltfSequenceWriter> Create(std::span<const glm::uvec3> triangles,
                                                 std::span<const glm::vec3> colors,
                                                 int num_vertices, int num_frames,
                                                 const GltfExportOptions& options,
                                                 const GltfExportSurface& surface = {});

  // Adds the next frame: positions and normals are #V, finite. Errors:
  // kInvalidArgument (sizes, non-finite values, more frames than announced),
  // kIo (writing the scratch file failed, e.g. disk full).
  base::Status AddFrame(std::span<const glm::vec3> positions, std::span<const glm::vec3> normals);

  // With options.camera: the camera of the next frame, as its world position and
  // its world-from-camera rotation (the camera looks down its -Z with +Y up, as
  // an OpenGL view). Call once per frame. Errors: kInvalidArgument (no lens in
  // the options, non-finite values, more poses than frames announced).
  base::Status AddCameraFrame(const glm::vec3& eye, const glm::quat& world_from_camera);

  // Writes the .glb to `path` (folder must exist) after exactly num_frames
  // AddFrame calls (and as many AddCameraFrame calls with a lens). Call once:
  // after it, AddFrame and Finish are errors.
  // Errors: kInvalidArgument (frame or camera count, second call), kIo, kLimitExceeded
  // (more than 4 GiB).
  base::Status Finish(const std::string& path);

  GltfExportLayout layout() const;  // kMorphTargets or kBakedMeshes, never kAuto
  int frames_added() const;

 private:
  struct Impl;
  explicit GltfSequenceWriter(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace deform
