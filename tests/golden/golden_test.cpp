// Golden-image cases: each row renders an image and compares it with
// tests/golden/ref/<name>.png (see tests/support/golden.h). Rows loosen the
// default thresholds (OIIO's 0.004 / 0.02 % / 0.012) only with a written reason.
//
// Until the rasterizer lands, the one case draws a procedural test card (gradient,
// anti-aliased disc, translucent square, triangle) in plain float arithmetic, which
// proves the harness end to end. Run: ctest -L golden; update: GOLDEN_UPDATE=1.

#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "deform/patch_layer_fixture.h"
#include "render/camera.h"
#include "render/image.h"
#include "render/renderer.h"
#include "support/golden.h"

namespace {

// Fraction of a pixel's 4x4 sub-samples for which `inside(x, y)` holds.
float Coverage(int px, int py, const std::function<bool(float, float)>& inside) {
  int hits = 0;
  for (int sy = 0; sy < 4; ++sy) {
    for (int sx = 0; sx < 4; ++sx) {
      hits += inside(static_cast<float>(px) + (static_cast<float>(sx) + 0.5f) / 4.0f,
                     static_cast<float>(py) + (static_cast<float>(sy) + 0.5f) / 4.0f);
    }
  }
  return static_cast<float>(hits) / 16.0f;
}

glm::vec4 Over(glm::vec4 dst, glm::vec3 colour, float alpha) {
  return glm::vec4(glm::vec3(dst) * (1.0f - alpha) + colour * alpha, 1.0f);
}

render::Image TestCard(int w, int h) {
  render::Image img(w, h);
  const float fw = static_cast<float>(w);
  const float fh = static_cast<float>(h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const float u = (static_cast<float>(x) + 0.5f) / fw;
      const float v = (static_cast<float>(y) + 0.5f) / fh;
      glm::vec4 p(0.05f + 0.5f * u, 0.1f, 0.6f * v, 1.0f);  // gradient background
      const float disc = Coverage(x, y, [&](float sx, float sy) {
        const float dx = sx - 0.35f * fw;
        const float dy = sy - 0.5f * fh;
        return dx * dx + dy * dy < (0.3f * fh) * (0.3f * fh);
      });
      p = Over(p, glm::vec3(0.9f, 0.6f, 0.1f), disc);
      const float square = Coverage(x, y, [&](float sx, float sy) {
        return sx > 0.45f * fw && sx < 0.8f * fw && sy > 0.15f * fh && sy < 0.6f * fh;
      });
      p = Over(p, glm::vec3(0.1f, 0.8f, 0.9f), 0.5f * square);  // translucent
      const float tri = Coverage(x, y, [&](float sx, float sy) {
        // Inside the triangle (0.6w, 0.9h), (0.95w, 0.9h), (0.8w, 0.5h): three edge tests.
        auto edge = [](float ax, float ay, float bx, float by, float qx, float qy) {
          return (bx - ax) * (qy - ay) - (by - ay) * (qx - ax);
        };
        const float ax = 0.6f * fw, ay = 0.9f * fh, bx = 0.95f * fw, by = 0.9f * fh;
        const float cx = 0.8f * fw, cy = 0.5f * fh;
        return edge(ax, ay, bx, by, sx, sy) <= 0.0f && edge(bx, by, cx, cy, sx, sy) <= 0.0f &&
               edge(cx, cy, ax, ay, sx, sy) <= 0.0f;
      });
      p = Over(p, glm::vec3(0.95f, 0.95f, 0.95f), tri);
      img.at(x, y) = p;
    }
  }
  return img;
}

// The left elbow of the mannequin bent 120 degrees (bend ramp), seen from
// above: SSD alone on the left, SSD + elbow and knee patches on the right.
render::Image ElbowSplit(int w, int h) {
  const testfixture::LayeredBody b = testfixture::MakeLayeredBody();
  std::vector<deform::PatchSetup> patches;
  patches.push_back(*testfixture::MakePatch(b, testfixture::ElbowSpec(b)));
  const std::vector<glm::mat4> pose = testfixture::BendPose(b, 120.0f);
  const testfixture::LayeredFrame f = testfixture::EvaluateLayered(b, patches, pose);
  const glm::vec3 elbow = testfixture::JointPos(pose, b.elbow);
  deform::Bounds box;
  box.Extend(elbow - glm::vec3(14.0f));
  box.Extend(elbow + glm::vec3(14.0f));
  const float aspect = static_cast<float>(w / 2) / static_cast<float>(h);
  const render::Camera camera =
      render::FrameBounds(box, 35.0f, aspect, glm::normalize(glm::vec3(-0.2f, -1.0f, -0.3f)), 1.0f);
  render::RenderSettings settings;
  settings.width = w / 2;
  settings.height = h;
  settings.supersample = 2;
  settings.threads = 1;
  settings.ground = false;
  render::Image out(w, h);
  for (int side = 0; side < 2; ++side) {
    const std::vector<glm::vec3>& pos = side == 0 ? f.global : f.layered;
    std::vector<glm::vec3> normals(pos.size());
    deform::ComputeVertexNormals(pos, b.mesh.bind.triangles, normals);
    const render::SceneMesh mesh{.positions = pos, .normals = normals,
                                 .triangles = b.mesh.bind.triangles};
    const render::Image half = render::Render(camera, {&mesh, 1}, {}, settings);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w / 2; ++x) out.at(side * (w / 2) + x, y) = half.at(x, y);
    }
  }
  for (int y = 0; y < h; ++y) out.at(w / 2, y) = glm::vec4(1.0f);  // divider
  return out;
}

struct GoldenCase {
  std::string name;
  std::function<render::Image()> render;
  render::CompareThresholds thresholds;  // defaults unless a reason is given
};

const std::vector<GoldenCase>& Cases() {
  static const std::vector<GoldenCase> cases = {
      {"synthetic_test_card", [] { return TestCard(160, 96); }, {}},
      {"patch_elbow_split_120", [] { return ElbowSplit(256, 128); }, {}},
  };
  return cases;
}

// gtest prints the case by name, not as bytes.
void PrintTo(const GoldenCase& c, std::ostream* os) { *os << c.name; }

class GoldenTest : public ::testing::TestWithParam<GoldenCase> {};

TEST_P(GoldenTest, MatchesReference) {
  testsupport::ExpectMatchesGolden(GetParam().render(), GetParam().name, GetParam().thresholds);
}

INSTANTIATE_TEST_SUITE_P(Cases, GoldenTest, ::testing::ValuesIn(Cases()),
                         [](const auto& test_info) { return test_info.param.name; });

}  // namespace
