// Golden frames of the elastic layer (issue 7): the sample rigs
// samples/data/belly_jump.json (belly patch, synthetic jump) and jowl.json
// (jowl patch, head shake), evaluated frame by frame from the motion's start as
// `patchskin render` does, drawn side by side (left: SSD alone, right: SSD +
// the elastic patch) through app::DrawCharacterFrame, framed close on the patch
// from a direction per case.

#include <cmath>
#include <ostream>
#include <string>

#include <gtest/gtest.h>

#include "app/frame_render.h"
#include "render/camera.h"
#include "support/elastic_rig.h"
#include "support/golden.h"

namespace {

constexpr int kElasticWidth = 320;
constexpr int kElasticHeight = 180;

struct ElasticCase {
  std::string name;
  std::string rig;
  int frame;
  glm::vec3 eye_direction;  // from the patch towards the camera (model space, Y up)
};

void PrintTo(const ElasticCase& c, std::ostream* os) { *os << c.name; }

// Frame `frame` of the rig, evaluated after every earlier frame (the state
// carried), seen from the front-left, framing the patch region twice its size.
render::Image RenderElasticFrame(const ElasticCase& c) {
  testsupport::RigPipeline l = testsupport::LoadSampleRig(c.rig);
  if (::testing::Test::HasFailure()) return {};
  const double dt = l.character->motion.frame_time_s;
  deform::DeformedFrame left, right;
  for (int f = 0; f <= c.frame; ++f) {
    EXPECT_TRUE(l.layered->Evaluate(f * dt, right).ok());
  }
  EXPECT_TRUE(l.global->Evaluate(c.frame * dt, left).ok());
  deform::Bounds region;
  for (int v : l.regions.front()) region.Extend(left.positions[static_cast<std::size_t>(v)]);
  deform::Bounds framed;
  framed.Extend(region.center() - region.size());
  framed.Extend(region.center() + region.size());
  // Two renders, 160 x 180 each, with the same camera: SSD alone on the left,
  // SSD + the elastic patch on the right, side by side (the split view would
  // cut the patch in two).
  const int half = kElasticWidth / 2;
  const float aspect = static_cast<float>(half) / static_cast<float>(kElasticHeight);
  const float elevation = 0.15f;
  const glm::vec3 view_dir =
      -glm::normalize(glm::normalize(c.eye_direction) * std::cos(elevation) +
                      glm::vec3(0.0f, std::sin(elevation), 0.0f));
  const render::Camera camera = render::FrameBounds(framed, 35.0f, aspect, view_dir);
  render::RenderSettings settings;
  settings.width = half;
  settings.height = kElasticHeight;
  settings.supersample = 2;
  settings.threads = 1;
  settings.ground_at_scene_min = false;
  settings.ground_y = left.bounds.min.y;
  render::Renderer renderer, unused_renderer;
  render::Image image(kElasticWidth, kElasticHeight), part, scratch;
  for (int side = 0; side < 2; ++side) {
    const app::FrameDrawOptions options{.frame_number = c.frame, .left_label = "", .right_label = ""};
    EXPECT_TRUE(app::DrawCharacterFrame(*l.character, side == 0 ? left : right, nullptr, camera,
                                        settings, options, renderer, unused_renderer, scratch,
                                        part)
                    .ok());
    for (int y = 0; y < kElasticHeight; ++y) {
      for (int x = 0; x < half; ++x) {
        // A dark one-pixel divider between the two renders.
        image.at(side * half + x, y) =
            (side == 1 && x == 0) ? glm::vec4(0.1f, 0.1f, 0.1f, 1.0f) : part.at(x, y);
      }
    }
  }
  return image;
}

class ElasticGoldenTest : public ::testing::TestWithParam<ElasticCase> {};

TEST_P(ElasticGoldenTest, MatchesReference) {
  const render::Image image = RenderElasticFrame(GetParam());
  ASSERT_FALSE(HasFailure());
  testsupport::ExpectMatchesGolden(image, GetParam().name, {});
}

// Jump: touchdown at 1.50 s (frame 45), legs absorbing until 1.66 s (frame 50).
// Head shake: stops at full speed at 1.5 s (frame 90).
INSTANTIATE_TEST_SUITE_P(Frames, ElasticGoldenTest,
                         ::testing::Values(ElasticCase{"elastic_belly_jump_47", "belly_jump.json", 47,
                                                                       {-0.5f, 0.0f, 1.0f}},
                                           ElasticCase{"elastic_belly_jump_52", "belly_jump.json", 52,
                                                                       {-0.5f, 0.0f, 1.0f}},
                                           ElasticCase{"elastic_jowl_shake_93", "jowl.json", 93,
                                                                       {1.0f, 0.0f, 0.45f}},
                                           ElasticCase{"elastic_jowl_shake_97", "jowl.json", 97,
                                                                       {1.0f, 0.0f, 0.45f}}),
                         [](const auto& test_info) { return test_info.param.name; });

}  // namespace
