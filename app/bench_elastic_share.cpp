#include "app/bench_elastic_share.h"

#include <cmath>
#include <cstdio>
#include <memory>
#include <span>
#include <string>
#include <utility>

#include "app/bench_frame.h"
#include "app/demo_data.h"
#include "deform/pipeline/elastic_layer.h"
#include "app/motion_source.h"
#include "app/character.h"
#include "deform/pipeline/frame_pipeline.h"
#include "app/rig_file.h"
#include "app/rig_patches.h"
#include "app/rig_setup.h"
#include "mocap/kinematics.h"

namespace app::bench {
namespace {

// belly_jump.json's and jowl.json's patches on one mannequin (the motion
// entry is required by the parser; the demo walk is evaluated instead).
constexpr const char* kTwoPatchRig = R"({
  "character": "mannequin",
  "motion": {"file": "demo_walk.bvh"},
  "patches": [
    {"name": "belly",
     "region": {"joint": "Spine1", "radius": 16, "side": [0, 0, 1], "half_angle_deg": 70},
     "parametrization": "cylinder", "sampling": [10, 10], "grid": [6, 6], "border_width": 0.15,
     "elastic": {"frequency_hz": 4, "damping_ratio": 0.15, "max_displacement": 8}},
    {"name": "jowl",
     "region": {"joint": "Head", "radius": 15, "side": [0, 0, 1], "half_angle_deg": 75},
     "parametrization": "cylinder", "sampling": [8, 8], "grid": [5, 5], "border_width": 0.15,
     "elastic": {"frequency_hz": 5, "damping_ratio": 0.25, "gain": 1.5, "max_displacement": 5}}
  ]
})";

bool ReportElasticShare(const base::Error& e, bool* failed) {
  std::fprintf(stderr, "bench: elastic share: %s\n", e.ToString().c_str());
  *failed = true;
  return false;
}

}  // namespace

void AddElasticShareRow(const Budget& b, int frames, std::vector<Row>& rows, bool* failed) {
  base::Result<MotionSource> src = LoadBvhText(DemoBvhText(), "demo_walk.bvh", {.y_up = true});
  if (!src.ok()) return void(ReportElasticShare(src.error(), failed));
  base::Result<Character> character = MakeCharacter(std::move(*src));
  if (!character.ok()) return void(ReportElasticShare(character.error(), failed));
  const Character& ch = *character;
  base::Result<Rig> rig = ParseRig(kTwoPatchRig, "bench_two_elastic_patches.json");
  if (!rig.ok()) return void(ReportElasticShare(rig.error(), failed));
  base::Result<deform::FramePipeline> pipeline =
      deform::FramePipeline::Create(ch, deform::GlobalMethod::kSsd, 1);
  if (!pipeline.ok()) return void(ReportElasticShare(pipeline.error(), failed));
  if (base::Status s = ApplyRigLayers(*rig, ch, *pipeline); !s.ok()) {
    return void(ReportElasticShare(s.error(), failed));
  }
  // The same two networks again, advanced on their own.
  base::Result<std::vector<deform::PatchSetup>> patches = BuildRigPatches(*rig, ch);
  if (!patches.ok()) return void(ReportElasticShare(patches.error(), failed));
  base::Result<std::vector<deform::ElasticPatchSpec>> specs = ResolveRigElastic(*rig, ch, *patches);
  if (!specs.ok()) return void(ReportElasticShare(specs.error(), failed));
  base::Result<std::unique_ptr<deform::ElasticLayer>> layer =
      deform::ElasticLayer::Create(ch, *patches, std::move(*specs));
  if (!layer.ok()) return void(ReportElasticShare(layer.error(), failed));
  if ((*layer)->num_patches() != 2) {
    return void(ReportElasticShare(base::MakeError(base::ErrorCode::kInternal, {"bench", 0, 0, {}},
                                                   "expected two elastic patches"),
                                   failed));
  }

  // Joint matrices of every clip frame (the layer's driving rotations).
  const std::size_t nj = static_cast<std::size_t>(ch.skeleton.num_joints());
  std::vector<mocap::JointTransform> locals(nj);
  std::vector<glm::mat4> model(static_cast<std::size_t>(ch.motion.num_frames) * nj);
  if (base::JobStatus s = mocap::ModelMatricesJob{.skeleton = &ch.skeleton,
                                                  .motion = &ch.motion,
                                                  .locals = locals,
                                                  .model_from_joint = model}
                              .Run();
      !s) {
    return void(ReportElasticShare(
        base::MakeError(base::ErrorCode::kInternal, {"bench", 0, 0, {}}, s.what), failed));
  }

  deform::DeformedFrame frame;
  if (base::Status s = pipeline->Evaluate(0.0, frame); !s.ok())
    return void(ReportElasticShare(s.error(), failed));
  EndToEndFrame end_to_end(ch, frame, "share");
  std::vector<std::vector<glm::vec3>> displacements(rig->patches.size());
  const double dt = 1.0 / 30.0;
  const double clip_dt = ch.motion.frame_time_s;
  const std::size_t clip_frames = static_cast<std::size_t>(ch.motion.num_frames);
  int f = 0;
  Row row{"elastic_share_two_patches", "%", Clock::kCpu, {}, 1.0, "limit",
          "elastic layer (6x6 + 5x5 patches) / end-to-end frame: evaluate, 1280x720 2x2 render, "
          "PNG, 1 thread"};
  for (int r = 0; r < b.runs && !*failed; ++r) {
    double elastic_s = 0.0, frame_s = 0.0;
    for (int i = 0; i < frames; ++i, ++f) {
      if (f * dt > ch.motion.duration_s()) f = 0;  // a restart re-simulates from t = 0
      const double time_s = f * dt;
      const double t0 = Now(Clock::kCpu);
      base::Status s = pipeline->Evaluate(time_s, frame);
      if (s.ok()) s = end_to_end.Draw(frame, f);
      const double t1 = Now(Clock::kCpu);
      std::size_t clip = static_cast<std::size_t>(std::lround(time_s / clip_dt));
      if (clip >= clip_frames) clip = clip_frames - 1;
      if (s.ok()) {
        s = (*layer)->Advance(time_s, std::span<const glm::mat4>(&model[clip * nj], nj),
                              displacements);
      }
      const double t2 = Now(Clock::kCpu);
      if (!s.ok()) {
        ReportElasticShare(s.error(), failed);
        break;
      }
      frame_s += t1 - t0;
      elastic_s += t2 - t1;
    }
    row.runs.push_back(100.0 * elastic_s / frame_s);
  }
  rows.push_back(std::move(row));
}

}  // namespace app::bench
