#pragma once
// glTF 2.0 skinned characters (.gltf and .glb): one skinned mesh, the joint
// hierarchy as a mocap::Skeleton, and the animations as keyframe channels that
// can be evaluated exactly (SampleGltfAnimation) or sampled into a
// mocap::Motion for the same LocalPoseJob that BVH clips use.
//
// Skinning follows the glTF 2.0 specification ("Skins"): a vertex v given in
// the mesh's own (bind) space moves to
//   v' = sum_i w_i * model_from_joint[skin_joints[j_i]] * joint_from_bind[j_i] * v
// where model_from_joint comes from mocap::LocalToModelJob over the skeleton.
// The transform of the node the skinned mesh hangs from is ignored, as the
// specification requires; non-joint ancestors of the joints (e.g. a "Z_UP" or
// "Armature" node) are skeleton joints without channels, so they do apply.
//
// Morph targets (glTF 2.0, "Morph Targets") are imported with the mesh's
// default weights and the animations' "weights" channels; GltfMeshSampler
// (deform/io/gltf_mesh_sampler.h) evaluates morphed and skinned vertices at a
// time. A file without any skin is read when GltfReadOptions::require_skin is
// false: each mesh node is then attached rigidly to its node (see GltfModel).
//
// Base colour (glTF 2.0, "Materials"): TEXCOORD_0 (float, or normalized
// unsigned byte/short) goes to mesh.bind.uvs; each primitive's material to
// mesh.materials (one per file material, with a material index per triangle):
// pbrMetallicRoughness.baseColorFactor, and baseColorTexture (texCoord 0 only)
// with its sampler's wrap modes and its image (buffer view, data: URI or file;
// PNG or JPEG decoded with OpenImageIO, sRGB converted to linear). The factor
// times COLOR_0 is also folded into mesh.bind.colors (as before textures were
// read), so a renderer's albedo is texture(uv) x colour. A texture whose image
// file is missing, or without TEXCOORD_0, or on another texCoord, is left out
// with a warning (the specification lets a viewer do without it); an index out
// of range or bytes that do not decode are errors. Metallic/roughness, normal,
// occlusion and emissive textures, texture transforms and cameras are not
// imported.
//
// Units are the file's (metres by the specification); the up axis is +Y.

#include <span>
#include <string>
#include <vector>

#include "deform/mesh.h"
#include "base/error.h"
#include "mocap/motion.h"
#include "mocap/pose.h"
#include "mocap/skeleton.h"

namespace deform {

// How a glTF sampler interpolates between keys (glTF 2.0, "Animations").
enum class GltfInterpolation : std::uint8_t {
  kLinear,       // lerp for translation/scale, shortest-path slerp for rotation
  kStep,         // the value of the key at or before t
  kCubicSpline,  // cubic Hermite with per-key in/out tangents (scaled by the key interval)
};

// The local-transform property a channel drives.
enum class GltfPath : std::uint8_t {
  kTranslation,  // 3 floats, file units
  kRotation,     // 4 floats, unit quaternion x, y, z, w
  kScale,        // 3 floats
};

// One animated property of one joint: keys of a glTF channel + sampler.
struct GltfChannel {
  int joint = 0;  // skeleton joint index
  GltfPath path = GltfPath::kTranslation;
  GltfInterpolation interpolation = GltfInterpolation::kLinear;
  std::vector<float> times_s;  // #K key times, non-decreasing, seconds
  // #K x width floats (width 3 or 4 by path) for kLinear / kStep. For
  // kCubicSpline #K x 3 x width: per key the in-tangent, the value, then the
  // out-tangent, as stored in the file. Rotation keys of kLinear/kStep are unit.
  std::vector<float> values;

  int width() const { return path == GltfPath::kRotation ? 4 : 3; }
  int num_keys() const { return static_cast<int>(times_s.size()); }
};

// The morph weights of one mesh: keys of a glTF channel whose target.path is
// "weights". Each key holds one weight per morph target of the mesh the
// channel's node instances; they drive GltfMorphTargets rows
// first_target .. first_target + num_targets - 1.
struct GltfWeightsChannel {
  int first_target = 0;        // first row of GltfMorphTargets it drives
  int num_targets = 0;         // weights per key (the mesh's target count), >= 1
  GltfInterpolation interpolation = GltfInterpolation::kLinear;
  std::vector<float> times_s;  // #K key times, non-decreasing, seconds
  // #K x num_targets weights for kLinear / kStep; #K x 3 x num_targets for
  // kCubicSpline (in-tangents, values, out-tangents per key, as in the file).
  // Normalized integer outputs are converted to floats.
  std::vector<float> values;

  int num_keys() const { return static_cast<int>(times_s.size()); }
};

struct GltfAnimation {
  std::string name;                   // the file's name, or "animation_<index>"
  double duration_s = 0.0;            // last key time over all channels (glTF time starts at 0)
  std::vector<GltfChannel> channels;  // channels on nodes outside the skeleton are dropped (warning)
  // "weights" channels of imported meshes with morph targets; channels on
  // other nodes are dropped with a warning.
  std::vector<GltfWeightsChannel> weights_channels;
};

// The morph targets of the imported (merged) mesh. In bind space, before
// skinning (glTF applies morphing first):
//   position(v) = bind.positions[v] + sum_k w_k * position_deltas[k * #V + v]
//   normal(v)   = normalize(bind.normals[v] + sum_k w_k * normal_deltas[k * #V + v])
// The targets of every morphed glTF mesh are concatenated (mesh order of
// import); a target is zero on the vertices of the other meshes.
struct GltfMorphTargets {
  int num_targets = 0;                     // #K over all imported meshes (0: no morphing)
  std::vector<glm::vec3> position_deltas;  // #K x #V, bind space, file units
  std::vector<glm::vec3> normal_deltas;    // #K x #V, or empty when no target has NORMAL
  std::vector<float> default_weights;      // #K, each mesh's `weights` (zeros where absent)
};

struct GltfModel {
  // Every node that is a skin joint or an ancestor of one, parent before child
  // (roots in node order, children in the file's order). Rest TRS is the
  // node's TRS (a `matrix` is decomposed; shear is dropped with a warning).
  // Each joint that any animation drives has channels: translation
  // (kX/Y/ZPosition, replacing the rest translation), rotation (kQuatX..W)
  // and scale (kX/Y/ZScale), only those any animation drives.
  mocap::Skeleton skeleton;
  // All triangle primitives of the nodes that use the chosen skin, merged.
  // Positions/normals in bind space (the mesh's own space); missing normals are
  // computed per primitive. weights.influences is 4, or 8 when any primitive
  // has JOINTS_1/WEIGHTS_1; each row is normalized to sum 1.
  // skin_joints[s] is the skeleton index of skin joint s; joint_from_bind[s]
  // is its inverse bind matrix (identity when the file gives none).
  SkinnedMesh mesh;
  // Rest-pose model_from_node of the (first) skinned mesh node, through all its
  // ancestors. Skinning ignores it (glTF rule). Most exporters bake it into the
  // inverse bind matrices, so that in the rest pose
  //   model_from_joint[skin_joints[s]] * joint_from_bind[s] == model_from_bind
  // for every skin joint s (CesiumMan; identity for SimpleSkin). Not
  // guaranteed: the early RiggedSimple export in ../shared/data leaves its
  // "Armature" node out of the bind matrices. Informational only.
  glm::mat4 model_from_bind{1.0f};
  // Morph targets of `mesh` (num_targets 0 when the file has none).
  GltfMorphTargets morph;
  std::vector<GltfAnimation> animations;  // in file order
  std::vector<base::Warning> warnings;    // tinygltf's warnings and ours
};

struct GltfReadOptions {
  // Upper bound on the size of the model file and of each external buffer.
  std::size_t max_file_bytes = std::size_t{1} << 30;
  // Which skin to import when several exist (index into the file's skins).
  int skin = 0;
  // When false, a file without skins is read too: the skeleton is every node
  // holding a mesh and their ancestors, and each mesh node's vertices are
  // attached rigidly to its own joint (one influence, weight 1, identity
  // joint_from_bind): bind positions are in the mesh's own space and
  // skinning applies the animated node transform, as a viewer does. Mesh
  // nodes with a skin are then ignored. When true (default), no skin is an
  // error (kNotFound "skins").
  bool require_skin = true;
  // Upper bound on #K x #V of the morph deltas (each of positions and normals),
  // checked before allocating: accessors without a buffer view cost no file
  // bytes, so the file size alone does not bound them. kLimitExceeded past it.
  std::size_t max_morph_values = std::size_t{1} << 26;
};

// Reads a .gltf (JSON, buffers as data: URIs or files) or .glb file. External
// buffers and images are read only from inside the model's folder: a URI with
// "..", an absolute path, or a symlink leading out of the folder is an error.
// Every accessor is checked (bounds, component type, count, index ranges,
// finite values) before use; errors name the file and the glTF field, e.g.
// "walk.gltf: accessors[3].count: error: ...". Never throws.
base::Result<GltfModel> ReadGltf(const std::string& path, const GltfReadOptions& options = {});

// ReadGltf on the bytes of a .gltf or .glb already in memory (the fuzz target,
// embedders). `path` labels messages and decides the folder that external
// buffers are read from (its parent; "." when it has none), under the same
// confinement rules; a path whose folder does not exist makes every external
// URI a read error, so only data: URIs and the GLB chunk load. Never throws.
base::Result<GltfModel> ReadGltfFromMemory(std::span<const unsigned char> bytes,
                                           const std::string& path,
                                           const GltfReadOptions& options = {});

// Exact evaluation of animation `animation` at time t_s into local transforms:
// rest TRS for joints and properties the animation does not drive; before the
// first key the first value, after the last key the last value. LINEAR lerps
// (rotation: shortest-path slerp), STEP holds, CUBICSPLINE evaluates
//   p(s) = (2s^3-3s^2+1) v_k + (s^3-2s^2+s) dt b_k + (-2s^3+3s^2) v_k+1 + (s^3-s^2) dt a_k+1
// with s = (t - t_k) / dt, dt = t_k+1 - t_k, b = out-tangent, a = in-tangent.
// Rotations are normalized. `locals` must hold skeleton.num_joints() entries
// and `animation` must be a valid index (checked with PATCHSKIN_CHECK).
void SampleGltfAnimation(const GltfModel& model, int animation, double t_s,
                         std::span<mocap::JointTransform> locals);

// A frame time detected from the key times of an animation: with N the
// smallest integer in 1..240 such that every key time is a multiple of 1/N s
// (within 1e-3 frame), 1/M s for the first M of 24, 25, 30, 60 that N divides,
// else 1/N s; 1/30 s when no N fits or there are no channels.
double DetectFrameTime(const GltfAnimation& animation);

// Samples animation `animation` at t = f * frame_time_s for f = 0 .. F-1, where
// the last frame reaches duration_s (F = ceil(duration / frame_time) + 1,
// up to a 1e-6 relative slack). frame_time_s <= 0 picks DetectFrameTime().
// The values follow model.skeleton's channel layout; un-driven channels hold
// rest values. Errors: bad animation index, non-finite frame time, more than
// 10^7 frames.
base::Result<mocap::Motion> AnimationToMotion(const GltfModel& model, int animation,
                                              double frame_time_s = 0.0);

}  // namespace deform
