#pragma once
// Test helper: a rig file's character with a FramePipeline carrying its patches
// and elastic layer, as `patchskin render` builds the layered (right) half.

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "deform/pipeline/elastic_layer.h"
#include "app/motion_source.h"
#include "app/character.h"
#include "deform/pipeline/frame_pipeline.h"
#include "app/rig_file.h"
#include "app/rig_patches.h"
#include "app/rig_setup.h"
#include "support/data_paths.h"

namespace testsupport {

struct RigPipeline {
  app::Rig rig;
  std::unique_ptr<app::Character> character;   // stable address: the pipelines point to it
  std::optional<deform::FramePipeline> layered;  // global + patches (+ elastic)
  std::optional<deform::FramePipeline> global;   // global only
  std::vector<std::vector<int>> regions;       // per patch, its region's vertex indices
};

// Loads `rig` (its motion Y-up, as render does; `edit`, if set, may change the
// loaded motion first) and builds both pipelines with `threads` workers.
// Failures are reported as gtest failures; check HasFailure() after.
inline RigPipeline LoadRigPipeline(const app::Rig& rig, int threads = 1,
                                   const std::function<void(app::MotionSource&)>& edit = {}) {
  RigPipeline l;
  l.rig = rig;
  auto source = app::LoadMotionSource(rig.motion, {.y_up = true});
  if (!source.ok()) {
    ADD_FAILURE() << source.error().ToString();
    return l;
  }
  if (edit) edit(*source);
  auto character = app::MakeCharacter(std::move(*source), {}, app::RigBodyKind(rig));  // the body the rig names
  if (!character.ok()) {
    ADD_FAILURE() << character.error().ToString();
    return l;
  }
  l.character = std::make_unique<app::Character>(std::move(*character));
  auto patches = app::BuildRigPatches(l.rig, *l.character);
  if (!patches.ok()) {
    ADD_FAILURE() << patches.error().ToString();
    return l;
  }
  for (const deform::PatchSetup& p : *patches) l.regions.push_back(p.region);
  auto specs = app::ResolveRigElastic(l.rig, *l.character, *patches);
  if (!specs.ok()) {
    ADD_FAILURE() << specs.error().ToString();
    return l;
  }
  auto layered = deform::FramePipeline::Create(*l.character, deform::GlobalMethod::kSsd, threads);
  auto global = deform::FramePipeline::Create(*l.character, deform::GlobalMethod::kSsd, threads);
  if (!layered.ok() || !global.ok()) {
    ADD_FAILURE() << "FramePipeline::Create failed";
    return l;
  }
  l.layered.emplace(std::move(*layered));
  l.global.emplace(std::move(*global));
  base::Status s = l.layered->SetPatches(std::move(*patches));
  if (s.ok()) s = l.layered->SetElastic(std::move(*specs));
  if (!s.ok()) ADD_FAILURE() << s.error().ToString();
  return l;
}

inline RigPipeline LoadSampleRig(const std::string& name, int threads = 1) {
  auto rig = app::LoadRig(SampleDataPath(name).string());
  if (!rig.ok()) {
    ADD_FAILURE() << rig.error().ToString();
    return {};
  }
  return LoadRigPipeline(*rig, threads);
}

}  // namespace testsupport
