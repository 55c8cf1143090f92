#include "app/bench_elastic_share.h"

#include <cstdio>
#include <memory>
#include <string>
#include <utility>

#include "app/bench_scenes.h"
#include "app/character.h"
#include "app/rig_file.h"
#include "app/rig_setup.h"
#include "deform/pipeline/frame_pipeline.h"

namespace app::bench {
namespace {

using ::bench::Clock;

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
  base::Result<Character> character = LoadDemoCharacter();
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
  // The same two networks again, advanced on their own by the probe.
  base::Result<RigLayers> layers = BuildRigLayers(*rig, ch);
  if (!layers.ok()) return void(ReportElasticShare(layers.error(), failed));
  base::Result<std::unique_ptr<ElasticShareProbe>> probe =
      ElasticShareProbe::Create(ch, *pipeline, *layers, "share", /*png=*/true);
  if (!probe.ok()) return void(ReportElasticShare(probe.error(), failed));
  if ((*probe)->num_elastic_patches() != 2) {
    return void(ReportElasticShare(base::MakeError(base::ErrorCode::kInternal, {"bench", 0, 0, {}},
                                                   "expected two elastic patches"),
                                   failed));
  }

  const double dt = 1.0 / 30.0;
  int f = 0;
  Row row{"elastic_share_two_patches", "%", Clock::kCpu, {}, 1.0, "limit",
          "elastic layer (6x6 + 5x5 patches) / end-to-end frame: evaluate, 1280x720 2x2 render, "
          "PNG, 1 thread"};
  for (int r = 0; r < b.runs && !*failed; ++r) {
    double elastic_s = 0.0, frame_s = 0.0;
    for (int i = 0; i < frames; ++i, ++f) {
      if (f * dt > ch.motion.duration_s()) f = 0;  // a restart re-simulates from t = 0
      base::Result<ElasticShareProbe::Split> split = (*probe)->Frame(f);
      if (!split.ok()) {
        ReportElasticShare(split.error(), failed);
        break;
      }
      frame_s += split->frame_s;
      elastic_s += split->elastic_s;
    }
    row.runs.push_back(100.0 * elastic_s / frame_s);
  }
  rows.push_back(std::move(row));
}

}  // namespace app::bench
