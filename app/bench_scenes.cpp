#include "app/bench_scenes.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <utility>

#include "app/demo_data.h"
#include "app/frame_render.h"
#include "app/motion_source.h"
#include "app/rig_patches.h"
#include "app/rig_setup.h"
#include "bench/harness/timing.h"
#include "mocap/kinematics.h"

namespace app::bench {

base::Result<Character> LoadDemoCharacter(BodyKind body) {
  base::Result<MotionSource> src = LoadBvhText(DemoBvhText(), "demo_walk.bvh", {.y_up = true});
  if (!src.ok()) return src.error();
  return MakeCharacter(std::move(*src), {}, body);
}

base::Result<RigLayers> BuildRigLayers(const Rig& rig, const Character& character) {
  base::Result<std::vector<deform::PatchSetup>> patches = BuildRigPatches(rig, character);
  if (!patches.ok()) return patches.error();
  base::Result<std::vector<deform::ElasticPatchSpec>> elastic =
      ResolveRigElastic(rig, character, *patches);
  if (!elastic.ok()) return elastic.error();
  return RigLayers{std::move(*patches), std::move(*elastic)};
}

base::Result<SampleRigScene> LoadSampleRig(const std::string& path) {
  base::Result<Rig> rig = LoadRig(path);
  if (!rig.ok()) return rig.error();
  base::Result<MotionSource> src = LoadMotionSource(rig->motion, {.y_up = true});
  if (!src.ok()) return src.error();
  base::Result<Character> character = MakeCharacter(std::move(*src));
  if (!character.ok()) return character.error();
  base::Result<RigLayers> layers = BuildRigLayers(*rig, *character);
  if (!layers.ok()) return layers.error();
  return SampleRigScene{std::move(*rig), std::move(*character), std::move(*layers)};
}

EndToEndFrame::EndToEndFrame(const Character& character, const deform::DeformedFrame& first,
                             const std::string& tag, bool png)
    : character_(character),
      camera_(render::FrameBounds(first.bounds, 35.0f, 1280.0f / 720.0f,
                                  glm::vec3(0.0f, 0.0f, -1.0f))) {
  settings_.width = 1280;
  settings_.height = 720;
  settings_.supersample = 2;
  settings_.threads = 1;
  png_.png_compression = 1;
  if (png) {
    path_ = (std::filesystem::temp_directory_path() /
             ("patchskin_bench_" + tag + "_" + std::to_string(getpid()) + ".png"))
                .string();
  }
}

EndToEndFrame::~EndToEndFrame() {
  std::error_code ec;
  if (!path_.empty()) std::filesystem::remove(path_, ec);
}

base::Status EndToEndFrame::Draw(const deform::DeformedFrame& frame, int number) {
  FrameDrawOptions draw;
  draw.frame_number = number;
  base::Status s = DrawCharacterFrame(character_, frame, nullptr, camera_, settings_, draw,
                                      renderer_, unused_, scratch_, image_);
  if (!s.ok() || path_.empty()) return s;
  return render::WriteImage(image_, path_, png_);
}

ElasticShareProbe::ElasticShareProbe(const Character& character, deform::FramePipeline& pipeline)
    : character_(character), pipeline_(pipeline) {}

base::Result<std::unique_ptr<ElasticShareProbe>> ElasticShareProbe::Create(
    const Character& character, deform::FramePipeline& pipeline, const RigLayers& layers,
    const std::string& tag, bool png) {
  std::unique_ptr<ElasticShareProbe> probe(new ElasticShareProbe(character, pipeline));
  base::Result<std::unique_ptr<deform::ElasticLayer>> layer =
      deform::ElasticLayer::Create(character, layers.patches, layers.elastic);
  if (!layer.ok()) return layer.error();
  probe->layer_ = std::move(*layer);
  // Joint matrices of every clip frame: the separate layer's driving rotations.
  const std::size_t nj = static_cast<std::size_t>(character.skeleton.num_joints());
  std::vector<mocap::JointTransform> locals(nj);
  probe->clip_joints_.resize(static_cast<std::size_t>(character.motion.num_frames) * nj);
  if (base::JobStatus s = mocap::ModelMatricesJob{.skeleton = &character.skeleton,
                                                  .motion = &character.motion,
                                                  .locals = locals,
                                                  .model_from_joint = probe->clip_joints_}
                              .Run();
      !s) {
    return base::MakeError(base::ErrorCode::kInternal, {"bench", 0, 0, {}}, s.what);
  }
  if (base::Status s = pipeline.Evaluate(0.0, probe->frame_); !s.ok()) return s.error();
  probe->draw_ = std::make_unique<EndToEndFrame>(character, probe->frame_, tag, png);
  probe->displacements_.resize(layers.patches.size());
  return probe;
}

base::Result<ElasticShareProbe::Split> ElasticShareProbe::Frame(int number) {
  const double time_s = number * (1.0 / 30.0);
  const double t0 = ::bench::Now(::bench::Clock::kCpu);
  base::Status s = pipeline_.Evaluate(time_s, frame_);
  if (s.ok()) s = draw_->Draw(frame_, number);
  const double t1 = ::bench::Now(::bench::Clock::kCpu);
  if (!s.ok()) return s.error();
  const std::size_t nj = static_cast<std::size_t>(character_.skeleton.num_joints());
  const std::size_t clip =
      std::min(static_cast<std::size_t>(std::lround(time_s / character_.motion.frame_time_s)),
               clip_joints_.size() / nj - 1);
  s = layer_->Advance(time_s, std::span<const glm::mat4>(&clip_joints_[clip * nj], nj),
                      displacements_);
  const double t2 = ::bench::Now(::bench::Clock::kCpu);
  if (!s.ok()) return s.error();
  return Split{t1 - t0, t2 - t1};
}

}  // namespace app::bench
