// The comparison `ssd` | `ssd + patches` is honest (issue 24): a patch layer
// with nothing to add (no examples and no elastic layer, or examples whose
// edits are all zero) renders the same frames as the rig without patches, and
// with example shapes on, every pixel that differs lies on the patch region
// (its vertices and their one-ring), never on the rest of the body.
//
// Tolerance: none. The layer adds P(Q) - P(G) and turns the global normals by
// the change of the geometric normals; both are exactly zero when Q == G, so
// positions, normals and pixels agree bit for bit ("rounding only" with no
// rounding left: the two pipelines run the same float operations).

#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <span>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "app/frame_render.h"
#include "app/motion_source.h"
#include "app/character.h"
#include "deform/pipeline/frame_pipeline.h"
#include "app/rig_file.h"
#include "app/rig_patches.h"
#include "app/rig_setup.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "support/example_demos.h"

namespace {

constexpr int kWidth = 320;
constexpr int kHeight = 180;

struct Bodies {
  app::Rig rig;
  std::optional<app::Character> character;
  std::optional<deform::FramePipeline> global;
  std::optional<deform::FramePipeline> layered;
};

// samples/data/<demo>.json with `edit` applied to its rig, on the mannequin.
template <typename Edit>
void LoadBodies(const std::string& demo, Edit edit, Bodies& b) {
  auto rig = app::LoadRig(testsupport::SampleDataPath(demo + ".json").string());
  ASSERT_TRUE(rig.ok()) << rig.error().ToString();
  b.rig = std::move(*rig);
  edit(b.rig);
  auto source = app::LoadMotionSource(b.rig.motion, {.y_up = true});
  ASSERT_TRUE(source.ok()) << source.error().ToString();
  auto character = app::MakeCharacter(std::move(*source));
  ASSERT_TRUE(character.ok()) << character.error().ToString();
  b.character.emplace(std::move(*character));
  auto method = app::ParseGlobalMethod(b.rig.global);
  ASSERT_TRUE(method.ok());
  auto global = deform::FramePipeline::Create(*b.character, *method, 1);
  auto layered = deform::FramePipeline::Create(*b.character, *method, 1);
  ASSERT_TRUE(global.ok() && layered.ok());
  b.global.emplace(std::move(*global));
  b.layered.emplace(std::move(*layered));
  const base::Status s = app::ApplyRigLayers(b.rig, *b.character, *b.layered);
  ASSERT_TRUE(s.ok()) << s.error().ToString();
  ASSERT_GT(b.layered->num_patches(), 0);
}

render::Image Draw(const app::Character& ch, const deform::DeformedFrame& f,
                   const render::Camera& camera, std::span<const glm::vec3> colors = {}) {
  render::RenderSettings settings;
  settings.width = kWidth;
  settings.height = kHeight;
  settings.supersample = 2;
  settings.threads = 1;
  // The key light's cast shadow would carry a changed shape's shadow onto
  // other surfaces: a real effect of the patch, but not one of its pixels.
  settings.shadows = false;
  if (!colors.empty()) {
    const render::SceneMesh mesh{.positions = f.positions, .normals = f.normals,
                                 .triangles = ch.mesh.bind.triangles, .vertex_colors = colors};
    return render::Render(camera, {&mesh, 1}, {}, settings);
  }
  render::Renderer renderer, unused_renderer;
  render::Image image, unused;
  const base::Status s = app::DrawCharacterFrame(ch, f, nullptr, camera, settings, {}, renderer,
                                                 unused_renderer, unused, image);
  EXPECT_TRUE(s.ok());
  return image;
}

// Evaluates frames 0, 20, ..., of both bodies and expects identical positions,
// normals and pixels.
void ExpectIdenticalFrames(Bodies& b) {
  const app::Character& ch = *b.character;
  const int frames = ch.motion.num_frames;
  ASSERT_GT(frames, 1);
  deform::DeformedFrame g, l;
  for (int frame = 0; frame < frames; frame += 20) {
    const double t = frame * ch.motion.frame_time_s;
    ASSERT_TRUE(b.global->Evaluate(t, g).ok());
    ASSERT_TRUE(b.layered->Evaluate(t, l).ok());
    ASSERT_EQ(g.positions, l.positions) << "frame " << frame;
    ASSERT_EQ(g.normals, l.normals) << "frame " << frame;
    const render::Camera whole = render::FrameBounds(g.bounds, 35.0f, static_cast<float>(kWidth) / kHeight,
                                                     glm::vec3(0.0f, 0.0f, -1.0f), 1.0f);
    const render::Image a = Draw(ch, g, whole);
    const render::Image c = Draw(ch, l, whole);
    ASSERT_EQ(a.rgba, c.rgba) << "frame " << frame;
  }
}

TEST(LayerNullControl, PatchesWithoutExamplesOrElasticRenderTheGlobalFrames) {
  for (const char* demo : {"biceps", "knee", "belly_jump"}) {
    SCOPED_TRACE(demo);
    Bodies b;
    LoadBodies(
        demo,
        [](app::Rig& rig) {
          for (app::RigPatch& p : rig.patches) {
            p.examples.clear();
            p.elastic.reset();
          }
        },
        b);
    if (HasFatalFailure()) return;
    ExpectIdenticalFrames(b);
  }
}

TEST(LayerNullControl, ExamplesWhoseEditsAreAllZeroRenderTheGlobalFrames) {
  for (const char* demo : {"biceps", "knee"}) {
    SCOPED_TRACE(demo);
    Bodies b;
    LoadBodies(
        demo,
        [](app::Rig& rig) {
          for (app::RigPatch& p : rig.patches) {
            for (app::RigExample& e : p.examples) {
              for (app::RigEdit& edit : e.edits) edit.move = glm::dvec3(0.0);
            }
          }
        },
        b);
    if (HasFatalFailure()) return;
    ExpectIdenticalFrames(b);
  }
}

// Pixels whose colour changes when the vertices `marked` turn red: where their
// triangles show in `f`, grown by one pixel (the supersampled edges).
std::vector<bool> MarkedPixels(const app::Character& ch, const deform::DeformedFrame& f,
                               const render::Camera& camera, const std::vector<bool>& marked) {
  const std::size_t nv = f.positions.size();
  std::vector<glm::vec3> plain(nv, glm::vec3(0.8f)), red(nv, glm::vec3(0.8f));
  for (std::size_t v = 0; v < nv; ++v) {
    if (marked[v]) red[v] = glm::vec3(1.0f, 0.0f, 0.0f);
  }
  const render::Image a = Draw(ch, f, camera, plain);
  const render::Image b = Draw(ch, f, camera, red);
  std::vector<bool> mask(static_cast<std::size_t>(kWidth * kHeight), false);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      if (a.at(x, y) == b.at(x, y)) continue;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int u = x + dx, w = y + dy;
          if (u >= 0 && u < kWidth && w >= 0 && w < kHeight) mask[static_cast<std::size_t>(w * kWidth + u)] = true;
        }
      }
    }
  }
  return mask;
}

TEST(LayerNullControl, ExamplesChangeOnlyThePixelsOfTheirPatchRegion) {
  Bodies b;
  LoadBodies(
      "biceps", [](app::Rig&) {}, b);
  if (HasFatalFailure()) return;
  const app::Character& ch = *b.character;
  // Seen from above, the biceps' front is the silhouette (as the golden frames).
  // The region of every patch and its one-ring: the vertices whose position
  // or normal the layer may change.
  const auto patches = app::BuildRigPatches(b.rig, ch);
  ASSERT_TRUE(patches.ok());
  std::vector<bool> region(static_cast<std::size_t>(ch.mesh.bind.num_vertices()), false);
  for (const deform::PatchSetup& p : *patches) {
    for (const int v : p.bound.binding.vertex) region[static_cast<std::size_t>(v)] = true;
  }
  std::vector<bool> ring = region;
  for (const glm::uvec3& t : ch.mesh.bind.triangles) {
    if (region[t.x] || region[t.y] || region[t.z]) ring[t.x] = ring[t.y] = ring[t.z] = true;
  }
  deform::DeformedFrame g, l;
  const double t = 48 * ch.motion.frame_time_s;  // an example pose: the biceps at its largest
  ASSERT_TRUE(b.global->Evaluate(t, g).ok());
  ASSERT_TRUE(b.layered->Evaluate(t, l).ok());
  float moved = 0.0f;
  for (std::size_t v = 0; v < g.positions.size(); ++v) {
    moved = std::max(moved, glm::length(g.positions[v] - l.positions[v]));
  }
  std::printf("biceps frame 48: the layer moves the skin by up to %.3f model units\n", moved);
  deform::Bounds box;
  for (const int v : (*patches)[0].region) box.Extend(g.positions[static_cast<std::size_t>(v)]);
  box.Extend(box.min - glm::vec3(25.0f));
  box.Extend(box.max + glm::vec3(25.0f));
  const render::Camera camera = render::FrameBounds(
      box, 35.0f, static_cast<float>(kWidth) / kHeight, glm::normalize(glm::vec3(0.1f, -1.0f, -0.25f)), 1.0f);
  const render::Image a = Draw(ch, g, camera);
  const render::Image c = Draw(ch, l, camera);
  const std::vector<bool> in_global = MarkedPixels(ch, g, camera, ring);
  const std::vector<bool> in_layered = MarkedPixels(ch, l, camera, ring);
  int differing = 0, outside = 0;
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      if (a.at(x, y) == c.at(x, y)) continue;
      ++differing;
      const auto i = static_cast<std::size_t>(y * kWidth + x);
      if (!in_global[i] && !in_layered[i]) ++outside;
    }
  }
  std::printf("biceps frame 48: %d pixels differ, %d of them outside the patch region\n", differing,
              outside);
  EXPECT_GT(differing, 100);  // the examples show
  EXPECT_EQ(outside, 0);
}

}  // namespace
