// `patchskin export`, run as a process, checked against the same pipeline
// evaluated here: the OBJ of frame N is the mesh `render` draws as frame N
// (bit for bit), the .glb gives each frame at its time, and the camera JSON is
// the camera render uses for the frame.

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/demo_data.h"
#include "app/frame_plan.h"
#include "app/motion_source.h"
#include "app/character.h"
#include "deform/pipeline/frame_pipeline.h"
#include "render/output/image_io.h"
#include "render/renderer.h"
#include "support/data_paths.h"
#include "support/exported_geometry.h"
#include "support/run_process.h"
#include "support/tolerances.h"

namespace {

using testsupport::SampleDataPath;
using testsupport::TestDir;

namespace fs = std::filesystem;

// The demo character, loaded as render loads it.
app::Character Demo() {
  app::MotionSourceOptions load;
  load.y_up = true;
  base::Result<app::MotionSource> src = app::LoadBvhText(app::DemoBvhText(), "demo_walk.bvh", load);
  EXPECT_TRUE(src.ok());
  base::Result<app::Character> ch =
      app::MakeCharacter(std::move(*src), {}, app::BodyKind::kGenerated);  // export's default body
  EXPECT_TRUE(ch.ok());
  return std::move(*ch);
}

void ExpectJsonVec(const nlohmann::json& j, const glm::vec3& v) {
  ASSERT_EQ(j.size(), 3u);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(j[static_cast<std::size_t>(c)].get<float>(), v[c]);
}

void ExpectJsonMat(const nlohmann::json& j, const glm::mat4& m, float tol) {
  ASSERT_EQ(j.size(), 16u);
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) {
      EXPECT_NEAR(j[static_cast<std::size_t>(4 * c + r)].get<float>(), m[c][r], tol)
          << "row " << r << " column " << c;
    }
  }
}

// The exit code of `patchskin ARGS` (one shell line); its stdout.txt and
// stderr.txt go to `dir`.
int PatchskinExit(const std::string& args, const fs::path& dir) {
  return testsupport::RunPatchskinLine(args, dir).exit_code;
}

TEST(ExportCommand, ObjFramesAreThePipelineFramesAndCamerasAreRenders) {
  const fs::path dir = TestDir();
  ASSERT_EQ(PatchskinExit("export --frames 10:40:10 --global dqs --with-camera --size 320x200 "
                          "--quiet --out '" +
                              (dir / "mesh_####.obj").string() + "'",
                          dir),
            0)
      << testsupport::SlurpFile(dir / "stderr.txt");

  const app::Character ch = Demo();
  base::Result<app::FramePlan> plan = app::PlanFrames(ch.motion, {.frames = "10:40:10"});
  ASSERT_TRUE(plan.ok());
  ASSERT_EQ(plan->frames.size(), 4u);
  base::Result<deform::FramePipeline> pipeline =
      deform::FramePipeline::Create(ch, deform::GlobalMethod::kDqs, 1);
  ASSERT_TRUE(pipeline.ok());
  base::Result<render::CameraPlan> cameras =
      app::PlanCameras(pipeline->character(), *plan, "follow", 15.0f, {320, 200});
  ASSERT_TRUE(cameras.ok());

  deform::DeformedFrame frame;
  for (const app::OutputFrame& of : plan->frames) {
    char name[64];
    std::snprintf(name, sizeof(name), "mesh_%04d.obj", of.number);
    const testsupport::ParsedObj obj = testsupport::ParseObjFile((dir / name).string());
    ASSERT_TRUE(obj.error.empty()) << obj.error;
    ASSERT_TRUE(pipeline->Evaluate(of.time_s, frame));
    ASSERT_EQ(obj.positions.size(), frame.positions.size());
    for (std::size_t i = 0; i < frame.positions.size(); ++i) {
      ASSERT_EQ(obj.positions[i], frame.positions[i]) << name << " vertex " << i;
      ASSERT_EQ(obj.normals[i], frame.normals[i]) << name << " vertex " << i;
    }
    EXPECT_EQ(obj.triangles, ch.mesh.bind.triangles);

    std::snprintf(name, sizeof(name), "camera_%04d.json", of.number);
    const nlohmann::json j = nlohmann::json::parse(testsupport::SlurpFile(dir / name));
    const render::Camera cam = cameras->At(of.camera);
    EXPECT_EQ(j["frame"].get<int>(), of.number);
    EXPECT_EQ(j["width"].get<int>(), 320);
    EXPECT_EQ(j["height"].get<int>(), 200);
    EXPECT_EQ(j["fov_y_deg"].get<float>(), render::kFovYDeg);
    EXPECT_EQ(j["aspect"].get<float>(), 320.0f / 200.0f);
    EXPECT_EQ(j["near"].get<float>(), cam.near_plane);
    EXPECT_EQ(j["far"].get<float>(), cam.far_plane);
    ExpectJsonVec(j["eye"], cam.eye);
    ExpectJsonVec(j["target"], cam.target);
    ExpectJsonVec(j["up"], cam.up);
    // The matrices are the standard look-at and OpenGL perspective of those values.
    const glm::mat4 view = glm::lookAt(cam.eye, cam.target, cam.up);
    const glm::mat4 proj = glm::perspective(glm::radians(cam.fov_y_deg), 320.0f / 200.0f,
                                            cam.near_plane, cam.far_plane);
    ExpectJsonMat(j["view"], view, testsupport::kFloatTol * 100.0f);
    ExpectJsonMat(j["projection"], proj, testsupport::kFloatTol);
    // And the body is in the picture.
    const glm::vec4 c = proj * view * glm::vec4(frame.bounds.center(), 1.0f);
    EXPECT_LT(std::abs(c.x / c.w), 1.0f);
    EXPECT_LT(std::abs(c.y / c.w), 1.0f);
  }
  for (const auto& e : fs::directory_iterator(dir)) {
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
  }
}

// One rule for a rig's settings, as render's: the rig's size, frames and
// method apply unless the option is given, and then the option wins.
TEST(ExportCommand, ARigsSettingsApplyUnlessTheOptionIsGiven) {
  const fs::path dir = TestDir();
  const fs::path rig = dir / "bend_tubes.json";
  std::ofstream(rig)
      << R"({"character": "tubes", "motion": {"file": ")" << SampleDataPath("bend.bvh").string()
      << R"("}, "global": "ssd", "render": {"size": [640, 360], "frames": "20:21"}})";
  const auto run = [&](const std::string& options, const std::string& out) {
    return PatchskinExit("export '" + rig.string() + "' --with-camera --quiet " + options +
                             " --out '" + (dir / out / "mesh_####.obj").string() + "'",
                         dir);
  };
  ASSERT_EQ(run("", "rig"), 0) << testsupport::SlurpFile(dir / "stderr.txt");
  EXPECT_EQ(testsupport::FilesIn(dir / "rig").size(), 4u);  // frames 20 and 21, mesh and camera
  const nlohmann::json rig_camera =
      nlohmann::json::parse(testsupport::SlurpFile(dir / "rig" / "camera_0021.json"));
  EXPECT_EQ(rig_camera["width"].get<int>(), 640);
  EXPECT_EQ(rig_camera["height"].get<int>(), 360);

  ASSERT_EQ(run("--size 320x200 --frames 21:21 --global dqs", "given"), 0)
      << testsupport::SlurpFile(dir / "stderr.txt");
  EXPECT_EQ(testsupport::FilesIn(dir / "given").size(), 2u);
  const nlohmann::json given_camera =
      nlohmann::json::parse(testsupport::SlurpFile(dir / "given" / "camera_0021.json"));
  EXPECT_EQ(given_camera["width"].get<int>(), 320);
  EXPECT_EQ(given_camera["height"].get<int>(), 200);
  // The elbows are bent by frame 21: DQS moves the skin differently from SSD.
  const testsupport::ParsedObj ssd =
      testsupport::ParseObjFile((dir / "rig" / "mesh_0021.obj").string());
  const testsupport::ParsedObj dqs =
      testsupport::ParseObjFile((dir / "given" / "mesh_0021.obj").string());
  ASSERT_TRUE(ssd.error.empty() && dqs.error.empty()) << ssd.error << dqs.error;
  ASSERT_EQ(ssd.positions.size(), dqs.positions.size());
  EXPECT_NE(ssd.positions, dqs.positions);
}

TEST(ExportCommand, GlbGivesEachFrameAtItsTime) {
  const fs::path dir = TestDir();
  ASSERT_EQ(PatchskinExit(
                "export --frames 0:20:4 --quiet --out '" + (dir / "walk.glb").string() + "'", dir),
            0)
      << testsupport::SlurpFile(dir / "stderr.txt");
  EXPECT_NE(testsupport::SlurpFile(dir / "stdout.txt").find("morph"), std::string::npos);
  tinygltf::Model m;
  std::string msg;
  ASSERT_TRUE(testsupport::LoadGlb((dir / "walk.glb").string(), m, msg)) << msg;

  const app::Character ch = Demo();
  base::Result<app::FramePlan> plan = app::PlanFrames(ch.motion, {.frames = "0:20:4"});
  ASSERT_TRUE(plan.ok());
  base::Result<deform::FramePipeline> pipeline =
      deform::FramePipeline::Create(ch, deform::GlobalMethod::kSsd, 1);
  ASSERT_TRUE(pipeline.ok());
  deform::DeformedFrame frame;
  const double t0 = plan->frames.front().time_s;
  // Positions in file units (cm for the demo): the morph round-off scales with them.
  const float tol = testsupport::kMorphRoundTripTol * 200.0f;
  for (const app::OutputFrame& of : plan->frames) {
    ASSERT_TRUE(pipeline->Evaluate(of.time_s, frame));
    const testsupport::GlbFrame g = testsupport::EvaluateGlb(m, of.time_s - t0);
    ASSERT_EQ(g.visible_meshes, 1);
    ASSERT_EQ(g.positions.size(), frame.positions.size());
    float worst = 0.0f;
    for (std::size_t i = 0; i < g.positions.size(); ++i) {
      worst = std::max(worst, glm::length(g.positions[i] - frame.positions[i]));
    }
    EXPECT_LE(worst, tol) << "frame " << of.number;
  }
}

// The strongest form of "the OBJ is what render drew": render frame 12 with
// `patchskin render`, then draw the exported OBJ from the exported camera JSON
// with the same renderer settings; the two PNGs must be identical.
TEST(ExportCommand, ObjDrawnWithItsCameraJsonIsTheRenderedFrame) {
  const fs::path dir = TestDir();
  const std::string common = " --frames 12:12 --size 96x64 --camera fixed --quiet ";
  ASSERT_EQ(PatchskinExit("render" + common + "--supersample 1 --no-sheet --no-video --out '" +
                              (dir / "frame_####.png").string() + "'",
                          dir),
            0)
      << testsupport::SlurpFile(dir / "stderr.txt");
  ASSERT_EQ(PatchskinExit("export" + common + "--with-camera --out '" +
                              (dir / "mesh_####.obj").string() + "'",
                          dir),
            0)
      << testsupport::SlurpFile(dir / "stderr.txt");

  const testsupport::ParsedObj obj = testsupport::ParseObjFile((dir / "mesh_0012.obj").string());
  ASSERT_TRUE(obj.error.empty()) << obj.error;
  const nlohmann::json j = nlohmann::json::parse(testsupport::SlurpFile(dir / "camera_0012.json"));
  render::Camera cam;
  for (int c = 0; c < 3; ++c) {
    const auto i = static_cast<std::size_t>(c);
    cam.eye[c] = j["eye"][i].get<float>();
    cam.target[c] = j["target"][i].get<float>();
    cam.up[c] = j["up"][i].get<float>();
  }
  cam.fov_y_deg = j["fov_y_deg"].get<float>();
  cam.near_plane = j["near"].get<float>();
  cam.far_plane = j["far"].get<float>();
  cam.aspect = j["aspect"].get<float>();
  render::RenderSettings settings;
  settings.width = j["width"].get<int>();
  settings.height = j["height"].get<int>();
  settings.supersample = 1;
  settings.threads = 1;
  settings.ground_at_scene_min = false;
  settings.ground_y = j["ground_y"].get<float>();
  const app::Character ch = Demo();  // only for the vertex colours render uses
  const render::SceneMesh body{.positions = obj.positions, .normals = obj.normals,
                               .triangles = obj.triangles, .vertex_colors = ch.mesh.bind.colors};
  render::Overlays overlays;  // render labels every frame with its number
  overlays.text.push_back({.text = "frame 12", .origin_px = {10, settings.height - 12}});
  render::Renderer renderer;
  render::Image image;
  ASSERT_TRUE(renderer.Render(cam, {&body, 1}, overlays, settings, image));
  ASSERT_TRUE(render::WriteImage(image, (dir / "from_obj.png").string(), {}));

  base::Result<render::Image> a = render::ReadImage((dir / "frame_0012.png").string());
  base::Result<render::Image> b = render::ReadImage((dir / "from_obj.png").string());
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(a->width, b->width);
  ASSERT_EQ(a->height, b->height);
  int differing = 0;
  for (int y = 0; y < a->height; ++y) {
    for (int x = 0; x < a->width; ++x) {
      if (a->at(x, y) != b->at(x, y)) ++differing;
    }
  }
  EXPECT_EQ(differing, 0);
}

// --scale 0 converts the detected units (the demo is in centimetres) to metres,
// as inspect --scale 0 does: the same bytes as --scale 0.01.
TEST(ExportCommand, ScaleZeroConvertsTheDetectedUnitsToMetres) {
  const fs::path dir = TestDir();
  for (const char* scale : {"0", "0.01", "1"}) {
    ASSERT_EQ(
        PatchskinExit(std::string("export --frames 12:12 --quiet --scale ") + scale + " --out '" +
                          (dir / (std::string("s") + scale + "_####.obj")).string() + "'",
                      dir),
        0)
        << testsupport::SlurpFile(dir / "stderr.txt");
  }
  const std::string automatic = testsupport::SlurpFile(dir / "s0_0012.obj"),
                    metres = testsupport::SlurpFile(dir / "s0.01_0012.obj");
  ASSERT_FALSE(automatic.empty());
  EXPECT_EQ(automatic, metres);
  EXPECT_NE(automatic, testsupport::SlurpFile(dir / "s1_0012.obj"));
}

TEST(ExportCommand, BadArgumentsAreRefused) {
  const fs::path dir = TestDir();
  EXPECT_EQ(PatchskinExit("export --quiet --out '" + (dir / "mesh.obj").string() + "'", dir), 2);
  EXPECT_NE(testsupport::SlurpFile(dir / "stderr.txt").find("placeholder"), std::string::npos);
  EXPECT_EQ(PatchskinExit("export --quiet --out '" + (dir / "mesh_####.ply").string() + "'", dir),
            2);
  EXPECT_EQ(
      PatchskinExit("export --quiet --frames 5:2 --out '" + (dir / "a.glb").string() + "'", dir),
      2);
  EXPECT_NE(testsupport::SlurpFile(dir / "stderr.txt").find("--frames"), std::string::npos);
  EXPECT_EQ(
      PatchskinExit("export --quiet --layout x --out '" + (dir / "a.glb").string() + "'", dir), 2);
  EXPECT_FALSE(fs::exists(dir / "a.glb"));
}

}  // namespace
