#include "app/bench_auto_layer.h"

#include <cstdio>
#include <string>

#include "app/auto_rig.h"
#include "app/bench_scenes.h"
#include "app/character.h"
#include "deform/pipeline/frame_pipeline.h"
#include "app/rig_setup.h"
#include "deform/patch/patch_binding.h"

namespace app::bench {
namespace {

using ::bench::Clock;
using ::bench::Now;

bool ReportAutoLayer(const base::Error& e, bool* failed) {
  std::fprintf(stderr, "bench: auto layer: %s\n", e.ToString().c_str());
  *failed = true;
  return false;
}

}  // namespace

void AddAutoLayerRows(const Budget& b, int frames, std::vector<Row>& rows, bool* failed) {
  base::Result<Character> character = LoadDemoCharacter(BodyKind::kGenerated);
  if (!character.ok()) return void(ReportAutoLayer(character.error(), failed));
  const Character& ch = *character;
  base::Result<deform::FramePipeline> global =
      deform::FramePipeline::Create(ch, deform::GlobalMethod::kSsd, 1);
  if (!global.ok()) return void(ReportAutoLayer(global.error(), failed));

  Row setup{"auto_layer_setup_s", "s", Clock::kCpu, {}, 1.0, "limit",
            "BuildAutoRig + ApplyRigLayers, demo walk (" + std::to_string(ch.skeleton.num_joints()) +
                " joints), generated body"};
  std::optional<deform::FramePipeline> layered;
  std::size_t patches = 0;
  Rig rig;
  for (int r = 0; r < b.runs; ++r) {
    const double t0 = Now(Clock::kCpu);
    base::Result<AutoRig> made = BuildAutoRig(ch, "generated", "demo_walk.bvh", "demo");
    if (!made.ok()) return void(ReportAutoLayer(made.error(), failed));
    base::Result<deform::FramePipeline> p =
        deform::FramePipeline::Create(ch, deform::GlobalMethod::kSsd, 1);
    if (!p.ok()) return void(ReportAutoLayer(p.error(), failed));
    if (base::Status s = ApplyRigLayers(made->rig, ch, *p); !s.ok()) {
      return void(ReportAutoLayer(s.error(), failed));
    }
    setup.runs.push_back(Now(Clock::kCpu) - t0);
    patches = made->rig.patches.size();
    rig = made->rig;
    layered.emplace(std::move(*p));
  }
  if (!layered) return;
  setup.note += ", " + std::to_string(patches) + " patches";

  deform::DeformedFrame frame;
  if (base::Status s = global->Evaluate(0.0, frame); !s.ok())
    return void(ReportAutoLayer(s.error(), failed));
  EndToEndFrame end_to_end(ch, frame, "auto");
  // CPU seconds of `frames` end-to-end frames of `pipeline`, from the start of the clip.
  const auto time_frames = [&](deform::FramePipeline& pipeline) {
    const double t0 = Now(Clock::kCpu);
    for (int f = 0; f < frames && !*failed; ++f) {
      const double time_s = f / 30.0;
      base::Status s = pipeline.Evaluate(time_s, frame);
      if (s.ok()) s = end_to_end.Draw(frame, f);
      if (!s.ok()) ReportAutoLayer(s.error(), failed);
    }
    return Now(Clock::kCpu) - t0;
  };
  Row overhead{"auto_layer_overhead", "%", Clock::kCpu, {}, 30.0, "limit",
               "end-to-end frame with --layer auto's " + std::to_string(patches) +
                   " patches vs ssd alone, 1280x720 2x2, PNG, 1 thread, " +
                   std::to_string(frames) + " frames each"};
  // The same patches' rebuilds on their own: the layer runs PatchRebuildJob
  // twice per patch and frame (the displaced grid and the reference grid);
  // its cost does not depend on where the control points are.
  base::Result<RigLayers> layers = BuildRigLayers(rig, ch);
  if (!layers.ok()) return void(ReportAutoLayer(layers.error(), failed));
  std::vector<std::vector<glm::vec3>> rebuilt;
  std::size_t bound = 0;
  for (const deform::PatchSetup& p : layers->patches) {
    rebuilt.emplace_back(p.bound.binding.size());
    bound += p.bound.binding.size();
  }
  const auto time_rebuilds = [&] {
    const double t0 = Now(Clock::kCpu);
    for (int f = 0; f < 2 * frames; ++f) {
      for (std::size_t k = 0; k < layers->patches.size(); ++k) {
        const deform::PatchSetup& p = layers->patches[k];
        *failed |= !deform::PatchRebuildJob{.control = p.rest_control,
                                            .bindings = p.bound.binding.view(),
                                            .positions = rebuilt[k]}
                        .Run();
      }
    }
    return Now(Clock::kCpu) - t0;
  };
  const std::string rebuild_note = "those patches' rebuilds (" + std::to_string(bound) +
                                   " bound vertices, 2 per patch and frame) / the layered frame";
  Row rebuild{"auto_layer_rebuild_share", "%", Clock::kCpu, {}, 1.0, "limit", rebuild_note};
  double base_s = 0.0, layer_s = 0.0;
  for (int r = 0; r < b.runs && !*failed; ++r) {
    const double base = time_frames(*global);
    const double with = time_frames(*layered);
    base_s += base;
    layer_s += with;
    overhead.runs.push_back(100.0 * (with / base - 1.0));
    rebuild.runs.push_back(100.0 * time_rebuilds() / with);
  }
  if (base_s > 0.0 && layer_s > 0.0) {
    char note[96];
    std::snprintf(note, sizeof(note), "; %.2f vs %.2f frames/s", frames * b.runs / base_s,
                  frames * b.runs / layer_s);
    overhead.note += note;
  }
  rows.push_back(std::move(setup));
  rows.push_back(std::move(overhead));
  rows.push_back(std::move(rebuild));
}

}  // namespace app::bench
