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

#include "deform/global/global_skinning.h"
#include "deform/pipeline/character.h"
#include "deform/pipeline/elastic_layer.h"
#include "deform/shapes/example_shapes.h"
#include "deform/mesh.h"
#include "deform/patch/patch_layer.h"
#include "base/error.h"
#include "mocap/motion.h"
#include "mocap/skeleton.h"

namespace deform {

// One evaluated frame, in world space.
struct DeformedFrame {
  std::vector<glm::vec3> positions;        // #V
  std::vector<glm::vec3> normals;          // #V unit normals
  std::vector<glm::vec3> joint_positions;  // #J
  Bounds bounds;                           // of positions
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
  // changes, P(Q) - P(G) (ApplyPatchLayer with a reference grid), and
  // normals are the global ones turned by the layer's change of the geometric
  // normals: patches without examples or elastic layer give the global frame
  // bit for bit, and outside the patch regions' one-rings nothing differs.
  // Patches must be built on this character's bind mesh. With SWD every control
  // point is bound to the sweeps of its nearest region vertex
  // (BindPointsLikeVertices) and carried by SwdJob.
  base::Status SetPatches(std::vector<PatchSetup> patches);
  int num_patches() const;

  // Adds example shapes to the patches (ALGORITHMS.md 0 step 2, 4.3, 5): per
  // frame and patch, theta from the sampled local pose -> dS(theta) by the
  // patch's RBF -> Q = G + A dS on the carried control points, before any
  // elastic displacement and the rebuild. One entry per patch set by
  // SetPatches (inactive entries: no examples); kInvalidArgument otherwise or
  // when a model's size disagrees with its patch; kUnsupported with SWD (its
  // control-point frames A are not defined yet). Empty clears them.
  base::Status SetPoseSpaces(std::vector<PatchPoseSpace> spaces);
  // Adds the elastic layer dE (ALGORITHMS.md 6, elastic_layer.h) to some of
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

}  // namespace deform
