#pragma once
// The per-frame pipeline: the one place that decides the order of the stages
// (ALGORITHMS.md section 0, STYLE.md section 3):
//
//   SampleLocals(t) -> LocalToModel -> GlobalDeform (SSD | DQS | SWD)
//     -> [patch layer: PoseSpace dS -> MassSpring dE -> PatchRebuild -> BorderBlend]
//     -> Normals (global ones, turned where the layer moved the surface) -> (render)
//
// Why this order: every later stage reads the joint matrices; the global
// deformation must move the skin (and, with patches, the control points)
// before the local layer adds displacements in the frames the global layer
// defines; normals come last because every stage before moves vertices.
// Sampling is by time, not frame index, so --fps resampling and chunked
// renders evaluate exactly the same poses.

#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "app/elastic_layer.h"
#include "deform/shapes/example_shapes.h"
#include "deform/body/mannequin.h"
#include "deform/mesh.h"
#include "deform/patch/patch_layer.h"
#include "base/error.h"
#include "mocap/motion.h"
#include "mocap/skeleton.h"

namespace app {

struct MotionSource;
struct CharacterTextures;  // app/frame_render.h

enum class GlobalMethod { kSsd, kDqs, kSwd };
const char* GlobalMethodName(GlobalMethod method);
// "ssd", "dqs", "swd" (also "lbs" for ssd); kInvalidArgument otherwise.
base::Result<GlobalMethod> ParseGlobalMethod(const std::string& name);

// What gets deformed: a skeleton, its motion, and a skinned mesh bound to it
// (the glTF's own mesh, or a mannequin generated from a BVH skeleton).
struct Character {
  std::string source;                  // file name (or "demo"), for messages and metadata
  mocap::Skeleton skeleton;
  mocap::Motion motion;
  deform::SkinnedMesh mesh;
  glm::mat4 world_from_model{1.0f};    // glTF: node transform of the skinned mesh is ignored
                                       // (glTF rule), so identity; kept for other sources
  bool closed_surface = false;         // the bind mesh is closed and outward (deform::IsClosedOutward)
  bool bound_at_first_frame = false;   // BVH: the rest pose was not a body pose, so the
                                       // mannequin was built and bound at frame 0
  std::vector<base::Warning> warnings;
  // The renderer's mip pyramids of mesh.materials' textures, built once (null: untextured).
  std::shared_ptr<const CharacterTextures> textures;
};

// Builds a Character from a loaded source: glTF keeps its mesh; BVH gets a
// mannequin, bound at the rest pose unless the rest pose is much lower than the
// first frame's pose (rest poses that lie flat, e.g. Bandai Namco's), in which
// case it is bound at frame 0 (deform::ChooseBindPose: heights of the body's
// joints, without a root that only positions it). With SWD each mannequin tube is
// bound to the sweep of the chain it was generated on (body_chain_coords).
// Which body a BVH skeleton gets: the tube mannequin (deform/body/mannequin.h; rig files name
// its vertices) or the generated body (deform/body/generated_body.h: one smooth closed
// skin with bone-heat weights, read from the body cache when it was built before).
enum class BodyKind { kTubes, kGenerated };
// "tubes" or "generated"; kInvalidArgument (naming --body) otherwise.
base::Result<BodyKind> ParseBodyKind(const std::string& name);

base::Result<Character> MakeCharacter(MotionSource&& source,
                                      const deform::MannequinOptions& mannequin = {},
                                      BodyKind body = BodyKind::kTubes);

// The model-space joint matrices (#J) of the pose the character's mesh was made
// in: the rest pose, or frame 0 when bound_at_first_frame; a skinned mesh's own
// bind matrices replace those of its skin joints.
base::Result<std::vector<glm::mat4>> BindModelFromJoint(const Character& character);

// One evaluated frame, in world space.
struct DeformedFrame {
  std::vector<glm::vec3> positions;        // #V
  std::vector<glm::vec3> normals;          // #V unit normals
  std::vector<glm::vec3> joint_positions;  // #J
  deform::Bounds bounds;                   // of positions
};

// Evaluates a Character frame by frame. Owns its scratch buffers (reused
// between frames); not thread-safe itself, uses `threads` workers inside.
class FramePipeline {
 public:
  FramePipeline(FramePipeline&&) noexcept;
  FramePipeline& operator=(FramePipeline&&) noexcept;
  ~FramePipeline();

  // Precomputes what the method needs (palettes, SWD bindings).
  static base::Result<FramePipeline> Create(const Character& character, GlobalMethod method,
                                            int threads);

  // Deforms the character at `time_s` seconds from the motion's first frame
  // (clamped to the motion). Never allocates after the first call.
  base::Status Evaluate(double time_s, DeformedFrame& out);

  GlobalMethod method() const;
  // The character this pipeline deforms (the one given to Create) and its
  // worker count (resolved: >= 1).
  const Character& character() const;
  int threads() const;

  // Adds the patch layer (ALGORITHMS.md 0, 3.7, 3.8), applied after the global
  // step: control points carried by the same method (SSD, DQS or SWD), bound
  // vertices rebuilt and blended. The layer adds only what the local layer
  // changes, P(Q) - P(G) (deform::ApplyPatchLayer with a reference grid), and
  // normals are the global ones turned by the layer's change of the geometric
  // normals: patches without examples or elastic layer give the global frame
  // bit for bit, and outside the patch regions' one-rings nothing differs.
  // Patches must be built on this character's bind mesh. With SWD every control
  // point is bound to the sweeps of its nearest region vertex
  // (deform::BindPointsLikeVertices) and carried by deform::SwdJob.
  base::Status SetPatches(std::vector<deform::PatchSetup> patches);
  int num_patches() const;

  // Adds example shapes to the patches (ALGORITHMS.md 0 step 2, 4.3, 5): per
  // frame and patch, theta from the sampled local pose -> dS(theta) by the
  // patch's RBF -> Q = G + A dS on the carried control points, before any
  // elastic displacement and the rebuild. One entry per patch set by
  // SetPatches (inactive entries: no examples); kInvalidArgument otherwise or
  // when a model's size disagrees with its patch; kUnsupported with SWD (its
  // control-point frames A are not defined yet). Empty clears them.
  base::Status SetPoseSpaces(std::vector<deform::PatchPoseSpace> spaces);
  // Adds the elastic layer dE (ALGORITHMS.md 6, app/elastic_layer.h) to some of
  // the patches set by SetPatches (call it after them): each frame, before the
  // rebuild, the carried control points of patch spec.patch get R_drv e. The
  // state is carried across Evaluate calls; an earlier time than the last one
  // re-simulates from the motion's start, so any frame order gives the same
  // frames. Errors: those of ElasticLayer::Create.
  base::Status SetElastic(std::vector<ElasticPatchSpec> specs);
  // One report per elastic patch (empty without them), as of the last Evaluate.
  std::vector<ElasticPatchReport> elastic_report() const;

 private:
  struct Impl;
  explicit FramePipeline(std::unique_ptr<Impl> impl);
  static base::JobStatus AddExampleShapes(Impl& m, std::size_t patch);
  std::unique_ptr<Impl> impl_;
};

}  // namespace app
