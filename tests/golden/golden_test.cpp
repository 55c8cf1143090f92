// Golden-image cases: each row renders an image and compares it with
// tests/golden/ref/<name>.png (see tests/support/golden.h). Rows loosen the
// default thresholds (OIIO's 0.004 / 0.02 % / 0.012) only with a written reason.
//
// The procedural test card (gradient, anti-aliased disc, translucent square,
// triangle, in plain float arithmetic) proves the harness itself; the render
// cases draw a lit sphere, a tessellated torus with every overlay, and an
// 8-frame turntable through render::Renderer. Run: ctest -L golden; update:
// GOLDEN_UPDATE=1.

#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "support/patch_layer_fixture.h"
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

// A closed triangle mesh with unit normals, built in the test.
struct TestMesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::uvec3> triangles;
};

// Torus around +Y: ring radius R, tube radius r, nu x nv quads (nu around the ring).
TestMesh Torus(float big_r, float small_r, int nu, int nv, glm::vec3 centre) {
  TestMesh m;
  const float two_pi = 2.0f * std::numbers::pi_v<float>;
  for (int i = 0; i < nu; ++i) {
    const float a = two_pi * static_cast<float>(i) / static_cast<float>(nu);
    const glm::vec3 radial(std::cos(a), 0.0f, std::sin(a));
    for (int j = 0; j < nv; ++j) {
      const float b = two_pi * static_cast<float>(j) / static_cast<float>(nv);
      const glm::vec3 n = std::cos(b) * radial + std::sin(b) * glm::vec3(0.0f, 1.0f, 0.0f);
      m.positions.push_back(centre + big_r * radial + small_r * n);
      m.normals.push_back(n);
    }
  }
  auto id = [&](int i, int j) {
    return static_cast<unsigned>(((i + nu) % nu) * nv + (j + nv) % nv);
  };
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {  // counter-clockwise seen from outside
      m.triangles.emplace_back(id(i, j), id(i, j + 1), id(i + 1, j));
      m.triangles.emplace_back(id(i + 1, j), id(i, j + 1), id(i + 1, j + 1));
    }
  }
  return m;
}

// UV sphere: `rings` latitude bands, `segments` longitudes.
TestMesh Sphere(float radius, int rings, int segments, glm::vec3 centre) {
  TestMesh m;
  const float pi = std::numbers::pi_v<float>;
  for (int i = 0; i <= rings; ++i) {
    const float theta = pi * static_cast<float>(i) / static_cast<float>(rings);
    for (int j = 0; j < segments; ++j) {
      const float phi = 2.0f * pi * static_cast<float>(j) / static_cast<float>(segments);
      const glm::vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta),
                        std::sin(theta) * std::sin(phi));
      m.positions.push_back(centre + radius * n);
      m.normals.push_back(n);
    }
  }
  auto id = [&](int i, int j) { return static_cast<unsigned>(i * segments + (j + segments) % segments); };
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      if (i > 0) m.triangles.emplace_back(id(i, j), id(i, j + 1), id(i + 1, j));
      if (i + 1 < rings) m.triangles.emplace_back(id(i + 1, j), id(i, j + 1), id(i + 1, j + 1));
    }
  }
  return m;
}

render::SceneMesh Scene(const TestMesh& m, glm::vec3 color) {
  return {.positions = m.positions, .normals = m.normals, .triangles = m.triangles,
          .base_color = color};
}

render::RenderSettings SmallSettings(int w, int h) {
  render::RenderSettings s;
  s.width = w;
  s.height = h;
  s.supersample = 2;
  s.threads = 2;
  return s;
}

render::Camera LookAt(glm::vec3 eye, glm::vec3 target, float aspect) {
  render::Camera c;
  c.eye = eye;
  c.target = target;
  c.fov_y_deg = 35.0f;
  c.aspect = aspect;
  c.near_plane = 0.1f;
  c.far_plane = 100.0f;
  return c;
}

render::Image LitSphere() {
  const TestMesh sphere = Sphere(1.0f, 48, 96, glm::vec3(0.0f, 1.0f, 0.0f));
  const render::SceneMesh mesh = Scene(sphere, glm::vec3(0.8f, 0.35f, 0.25f));
  return render::Render(LookAt({2.5f, 2.2f, 4.5f}, {0.0f, 0.9f, 0.0f}, 1.0f), {&mesh, 1}, {},
                        SmallSettings(192, 192));
}

render::Image TorusWithOverlays() {
  const TestMesh torus = Torus(1.0f, 0.35f, 40, 16, glm::vec3(0.0f, 0.6f, 0.0f));
  const render::SceneMesh mesh = Scene(torus, glm::vec3(0.3f, 0.55f, 0.8f));
  render::Overlays o;
  o.wireframe = true;
  render::LineOverlay bones;  // a little "skeleton" through the hole, partly hidden
  bones.endpoints = {{-1.6f, 0.6f, 0.0f}, {0.0f, 0.6f, 0.0f}, {0.0f, 0.6f, 0.0f},
                     {0.0f, 1.8f, 0.0f}, {0.0f, 0.6f, 0.0f}, {1.6f, 0.6f, 0.0f}};
  o.lines.push_back(bones);
  render::PointOverlay joints;
  joints.points = {{-1.6f, 0.6f, 0.0f}, {0.0f, 0.6f, 0.0f}, {0.0f, 1.8f, 0.0f}, {1.6f, 0.6f, 0.0f}};
  o.points.push_back(joints);
  o.text.push_back({.text = "frame 7", .origin_px = {8, 184}, .scale = 0.5});
  return render::Render(LookAt({0.0f, 2.8f, 4.2f}, {0.0f, 0.6f, 0.0f}, 256.0f / 192.0f), {&mesh, 1},
                        o, SmallSettings(256, 192));
}

// An asymmetric scene, so every orbit position looks different: a torus, a
// green ball on +X and a red ball on +Z.
render::Image TurntableFrame(int k, bool shadows = false) {
  static const TestMesh torus = Torus(0.8f, 0.3f, 36, 14, glm::vec3(0.0f, 0.9f, 0.0f));
  static const TestMesh ball_x = Sphere(0.35f, 16, 32, glm::vec3(1.1f, 0.35f, 0.0f));
  static const TestMesh ball_z = Sphere(0.25f, 16, 32, glm::vec3(0.0f, 0.25f, 1.2f));
  const render::SceneMesh meshes[3] = {Scene(torus, glm::vec3(0.85f, 0.75f, 0.3f)),
                                       Scene(ball_x, glm::vec3(0.2f, 0.6f, 0.3f)),
                                       Scene(ball_z, glm::vec3(0.8f, 0.15f, 0.1f))};
  render::Camera c = render::TurntablePath({0.0f, 0.55f, 0.0f}, 4.5f, 25.0f, 8)[static_cast<std::size_t>(k)];
  c.aspect = 1.0f;
  render::RenderSettings settings = SmallSettings(128, 128);
  settings.shadows = shadows;
  return render::Render(c, meshes, {}, settings);
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
      {"lit_sphere", LitSphere, {}},
      {"torus_overlays", TorusWithOverlays, {}},
      {"turntable_0", [] { return TurntableFrame(0); }, {}},
      {"turntable_1", [] { return TurntableFrame(1); }, {}},
      {"turntable_2", [] { return TurntableFrame(2); }, {}},
      {"turntable_3", [] { return TurntableFrame(3); }, {}},
      {"turntable_4", [] { return TurntableFrame(4); }, {}},
      {"turntable_5", [] { return TurntableFrame(5); }, {}},
      {"turntable_6", [] { return TurntableFrame(6); }, {}},
      {"turntable_7", [] { return TurntableFrame(7); }, {}},
      // With the key light's cast shadow (--shadows on): the torus's shadow
      // shows its hole, the balls' shadows meet them at the ground.
      {"turntable_2_shadows", [] { return TurntableFrame(2, true); }, {}},
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
