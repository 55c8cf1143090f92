#pragma once
// The scene half of the bench harness (the timing half and the render-only
// body scene: bench/harness/): what `patchskin bench` (app/bench_*.cpp) and
// the bench/ programs that time the app's character (pipeline_bench,
// example_demos_bench) build before they time anything. It lives in
// patchskin_app because it needs the character, rig and frame-drawing code;
// it never includes Google Benchmark.
//
//   LoadDemoCharacter   the built-in demo: demo_walk.bvh (compiled in), y up
//   BuildRigLayers      a rig's patches and resolved elastic specs on a character
//   LoadSampleRig       a rig file (samples/data/*.json): its motion's character + layers
//   EndToEndFrame       the bench frame: 1280x720, 2x2 samples, one thread, framed
//                       by the first frame's bounds; optionally written as a PNG
//   ElasticShareProbe   one output frame timed as (evaluate + draw) and as a second
//                       elastic layer advancing the same networks
//
// Set-up costs are not timed by anyone: one character build (~0.1 s for the
// tube mannequin, longer for the generated body), one patch fit per patch.

#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "app/character.h"
#include "app/rig_file.h"
#include "base/error.h"
#include "deform/pipeline/elastic_layer.h"
#include "deform/pipeline/frame_pipeline.h"
#include "render/camera.h"
#include "render/output/image_io.h"
#include "render/renderer.h"

namespace app::bench {

// The built-in demo's character: the walk on a body of `body`. Errors: the
// loader's and MakeCharacter's (none expected for the compiled-in motion).
base::Result<Character> LoadDemoCharacter(BodyKind body = BodyKind::kTubes);

// A rig's layers on a character, before they are installed on a pipeline.
struct RigLayers {
  std::vector<deform::PatchSetup> patches;        // BuildRigPatches
  std::vector<deform::ElasticPatchSpec> elastic;  // ResolveRigElastic; empty without elastic
};
// Errors: BuildRigPatches' and ResolveRigElastic's (they name the rig file and field).
base::Result<RigLayers> BuildRigLayers(const Rig& rig, const Character& character);

// A rig file with its own motion (loaded y up) and its layers on that character.
struct SampleRigScene {
  Rig rig;
  Character character;
  RigLayers layers;
};
// `path`: e.g. PATCHSKIN_SAMPLES_DIR "/belly_jump.json". Errors: LoadRig's,
// the motion loader's, MakeCharacter's, BuildRigLayers'.
base::Result<SampleRigScene> LoadSampleRig(const std::string& path);

class EndToEndFrame {
 public:
  // `first`: the frame whose bounds fix the camera. `png`: also write each
  // frame as a PNG (level 1) to a scratch file named by `tag`, removed by the
  // destructor. Cost per Draw: one render, plus one PNG encode when `png`.
  EndToEndFrame(const Character& character, const deform::DeformedFrame& first,
                const std::string& tag, bool png = true);
  ~EndToEndFrame();
  EndToEndFrame(const EndToEndFrame&) = delete;
  EndToEndFrame& operator=(const EndToEndFrame&) = delete;

  // Draws `frame` (labelled `number`) and writes it. Errors: the renderer's or the writer's.
  base::Status Draw(const deform::DeformedFrame& frame, int number);
  const render::Image& image() const { return image_; }

 private:
  const Character& character_;
  render::RenderSettings settings_;
  render::Camera camera_;
  render::Renderer renderer_, unused_;
  render::Image image_, scratch_;
  render::WriteOptions png_;
  std::string path_;  // empty: no PNG
};

// The elastic layer's share of a frame, as row elastic_share_two_patches and
// pipeline_bench's BM_BellyFrameShare measure it. Per 30 fps output frame, on
// the calling thread's CPU clock: (a) `pipeline`'s Evaluate (its elastic
// layer included) and the EndToEndFrame draw; (b) a separate
// deform::ElasticLayer, built from `layers`, advancing copies of the same
// networks to the same time from the clip frame's joint matrices.
class ElasticShareProbe {
 public:
  struct Split {
    double frame_s = 0.0;    // (a)
    double elastic_s = 0.0;  // (b)
  };
  // `pipeline` evaluates `character` with `layers` installed; both must
  // outlive the probe. Cost: one Evaluate at t = 0 (the camera), the clip's
  // #F x #J joint matrices. Errors: ElasticLayer::Create's, the pipeline's.
  static base::Result<std::unique_ptr<ElasticShareProbe>> Create(const Character& character,
                                                                 deform::FramePipeline& pipeline,
                                                                 const RigLayers& layers,
                                                                 const std::string& tag, bool png);

  // Output frame `number`, at number / 30 s: the wrap back to t = 0 (a
  // restart re-simulates) is the caller's. Errors: the pipeline's, the
  // renderer's, the writer's, the layer's.
  base::Result<Split> Frame(int number);
  int num_elastic_patches() const { return layer_->num_patches(); }

 private:
  ElasticShareProbe(const Character& character, deform::FramePipeline& pipeline);

  const Character& character_;
  deform::FramePipeline& pipeline_;
  std::unique_ptr<deform::ElasticLayer> layer_;
  std::vector<glm::mat4> clip_joints_;  // #F x #J model_from_joint, frame-major
  deform::DeformedFrame frame_;
  std::unique_ptr<EndToEndFrame> draw_;
  std::vector<std::vector<glm::vec3>> displacements_;
};

}  // namespace app::bench
