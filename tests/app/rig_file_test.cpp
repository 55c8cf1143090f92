#include "app/rig_file.h"

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>

#include "app/motion_source.h"
#include "app/rig_patches.h"
#include "app/rig_setup.h"
#include "render/output/image_io.h"
#include "support/data_paths.h"
#include "support/run_process.h"

namespace {

constexpr const char* kGood = R"({
  "character": "mannequin",
  "motion": {"file": "bend.bvh"},
  "global": "dqs",
  "patches": [
    {"name": "left_elbow",
     "region": {"joint": "LeftForeArm", "radius": 14, "side": [0, 0, 1], "half_angle_deg": 120},
     "parametrization": "cylinder", "sampling": [9, 8], "grid": [6, 5], "border_width": 0.2},
    {"name": "belly", "region": {"vertices": [1, 2, 3]}, "parametrization": "plane"},
    {"name": "sketch", "region": {"view": "front", "rect": [0.1, 0.2, 0.3, 0.4]}}
  ],
  "render": {"size": [320, 200], "camera": "fixed", "overlays": ["skeleton"], "split": false,
             "compare": "ssd,dqs + patches", "wipe": true, "output": "out/x_####.png", "frames": "0:10"}
})";

TEST(RigFile, ParsesEveryFieldAndResolvesPathsAgainstTheRigFolder) {
  const base::Result<app::Rig> rig = app::ParseRig(kGood, "samples/data/rig.json");
  ASSERT_TRUE(rig.ok()) << rig.error().ToString();
  EXPECT_EQ(rig->character, "mannequin");
  EXPECT_EQ(rig->motion, "samples/data/bend.bvh");
  EXPECT_EQ(rig->global, "dqs");
  ASSERT_EQ(rig->patches.size(), 3u);
  const app::RigPatch& e = rig->patches[0];
  EXPECT_EQ(e.name, "left_elbow");
  EXPECT_EQ(e.region.kind, app::RigRegion::Kind::kJoint);
  EXPECT_EQ(e.region.joint, "LeftForeArm");
  EXPECT_EQ(e.region.radius, 14.0f);
  EXPECT_EQ(e.region.side, glm::vec3(0, 0, 1));
  EXPECT_TRUE(e.cylinder);
  EXPECT_EQ(e.sampling, glm::ivec2(9, 8));
  EXPECT_EQ(e.grid, glm::ivec2(6, 5));
  EXPECT_EQ(e.border_width, 0.2f);
  EXPECT_EQ(rig->patches[1].region.vertices, (std::vector<int>{1, 2, 3}));
  EXPECT_FALSE(rig->patches[1].cylinder);
  EXPECT_EQ(rig->patches[1].grid, glm::ivec2(6, 6));  // default
  EXPECT_EQ(rig->patches[2].region.kind, app::RigRegion::Kind::kScreen);
  EXPECT_EQ(rig->patches[2].region.rect, glm::vec4(0.1f, 0.2f, 0.3f, 0.4f));
  EXPECT_EQ(rig->render.size, glm::ivec2(320, 200));
  EXPECT_EQ(rig->render.camera, "fixed");
  EXPECT_FALSE(rig->render.split);
  EXPECT_EQ(rig->render.compare, "ssd,dqs + patches");
  EXPECT_TRUE(rig->render.wipe);
  EXPECT_EQ(rig->render.output, "samples/data/out/x_####.png");
}

TEST(RigFile, CameraIsAModeOrAnObject) {
  const auto rig = app::ParseRig(R"({"character": "mannequin", "motion": {"file": "/m.bvh"},
      "render": {"camera": {"mode": "fixed", "azimuth": 150, "elevation": -10, "distance": 80,
                            "zoom": 1.5, "look_at": "patch:left_elbow"}}})",
                                 "r.json");
  ASSERT_TRUE(rig.ok()) << rig.error().ToString();
  EXPECT_EQ(rig->render.camera, "fixed");
  ASSERT_TRUE(rig->render.azimuth_deg.has_value());
  EXPECT_EQ(*rig->render.azimuth_deg, 150.0f);
  ASSERT_TRUE(rig->render.elevation_deg.has_value());
  EXPECT_EQ(*rig->render.elevation_deg, -10.0f);
  EXPECT_EQ(rig->render.distance, 80.0f);
  EXPECT_EQ(rig->render.zoom, 1.5f);
  EXPECT_EQ(rig->render.look_at, "patch:left_elbow");
  const auto bad = app::ParseRig(R"({"character": "mannequin", "motion": {"file": "/m.bvh"},
      "render": {"camera": {"elevation": 95}}})",
                                 "r.json");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().ToString(),
            "r.json: render.camera.elevation: error: expected a number in -89..89, found 95");
  const auto unknown = app::ParseRig(R"({"character": "mannequin", "motion": {"file": "/m.bvh"},
      "render": {"camera": {"yaw": 5}}})",
                                     "r.json");
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().ToString().find("render.camera.yaw"), std::string::npos)
      << unknown.error().ToString();
}

TEST(RigFile, DefaultsOfAMinimalRig) {
  const auto rig = app::ParseRig(R"({"character": "mannequin", "motion": {"file": "/m.bvh"}})",
                                 "r.json");
  ASSERT_TRUE(rig.ok());
  EXPECT_EQ(rig->motion, "/m.bvh");
  EXPECT_EQ(rig->global, "ssd");
  EXPECT_TRUE(rig->patches.empty());
  EXPECT_TRUE(rig->render.split);
  EXPECT_TRUE(rig->render.compare.empty());
  EXPECT_FALSE(rig->render.wipe);
  EXPECT_EQ(rig->render.size, glm::ivec2(640, 360));
}

TEST(RigFile, JointMapResolvesAgainstTheRigFolder) {
  const auto rig = app::ParseRig(
      R"({"character": "body.glb", "motion": {"file": "walk.bvh", "joint_map": "maps/body.json"}})",
      "rigs/r.json");
  ASSERT_TRUE(rig.ok()) << rig.error().ToString();
  EXPECT_EQ(rig->joint_map, "rigs/maps/body.json");
  const auto none = app::ParseRig(R"({"character": "body.glb", "motion": {"file": "walk.bvh"}})", "r.json");
  ASSERT_TRUE(none.ok());
  EXPECT_TRUE(none->joint_map.empty());
}

TEST(RigFile, MotionUpIsYOrZ) {
  const auto z = app::ParseRig(R"({"character": "generated", "motion": {"file": "m.bvh", "up": "z"}})", "r.json");
  ASSERT_TRUE(z.ok()) << z.error().ToString();
  EXPECT_EQ(z->up, "z");
  const auto none = app::ParseRig(R"({"character": "generated", "motion": {"file": "m.bvh"}})", "r.json");
  ASSERT_TRUE(none.ok());
  EXPECT_TRUE(none->up.empty());
  const auto bad = app::ParseRig(R"({"character": "generated", "motion": {"file": "m.bvh", "up": "x"}})", "r.json");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().ToString().find("motion.up"), std::string::npos) << bad.error().ToString();
  EXPECT_NE(bad.error().ToString().find("expected \"y\" or \"z\""), std::string::npos) << bad.error().ToString();
}

TEST(RigFile, BuiltInBodiesAreNamesNotFiles) {
  for (const char* body : {"generated", "tubes", "mannequin"}) {
    const std::string text = std::string(R"({"character": ")") + body + R"(", "motion": {"file": "m.bvh"}})";
    const auto rig = app::ParseRig(text, "rigs/r.json");
    ASSERT_TRUE(rig.ok()) << rig.error().ToString();
    EXPECT_EQ(rig->character, body);  // not resolved against the rig's folder
    EXPECT_EQ(app::RigBodyKind(*rig),
              std::string(body) == "generated" ? app::BodyKind::kGenerated : app::BodyKind::kTubes);
  }
  const auto file = app::ParseRig(R"({"character": "generated.glb"})", "rigs/r.json");
  ASSERT_TRUE(file.ok()) << file.error().ToString();
  EXPECT_EQ(file->character, "rigs/generated.glb");
  const auto no_motion = app::ParseRig(R"({"character": "generated"})", "r.json");
  ASSERT_FALSE(no_motion.ok());
  EXPECT_NE(no_motion.error().ToString().find("generated body needs a BVH motion"), std::string::npos)
      << no_motion.error().ToString();
}

struct BadRig {
  const char* text;
  const char* message;  // the whole formatted error
};

// One row per check: the exact message names the file, the field path and what was expected.
const BadRig kBadRigs[] = {
    {R"({"character": "mannequin",)", "r.json:1:27: error: invalid JSON: syntax error while "
                                      "parsing object key - unexpected end of input; expected "
                                      "string literal"},
    {R"([1])", "r.json: rig: error: expected an object, found an array [1]"},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "colour": 1})",
     "r.json: colour: error: unknown field (expected one of: character, motion, global, "
     "patches, render)"},
    {R"({"motion": {"file": "m.bvh"}})",
     "r.json: character: error: missing (\"generated\", \"tubes\" or a glTF file)"},
    {R"({"character": "mannequin"})",
     "r.json: motion: error: missing (a generated body needs a BVH motion: {\"file\": ...})"},
    {R"({"character": 3, "motion": {"file": "m.bvh"}})",
     "r.json: character: error: expected a non-empty string, found 3"},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh", "fps": -1}})",
     "r.json: motion.fps: error: expected a number in 0..10000, found -1"},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "global": "lbs2"})",
     "r.json: global: error: expected one of \"ssd\", \"dqs\", \"swd\", found \"lbs2\""},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "patches": [{"name": "a",
        "region": {"joint": "J", "radius": 5}}, {"name": "b", "region": {"joint": "J",
        "radius": 5}, "grid": "6x6"}]})",
     "r.json: patches[1].grid: error: expected an array of two integers in 4..64, found \"6x6\""},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "patches": [{"name": "a",
        "region": {"joint": "J", "radius": 5}, "grid": [3, 6]}]})",
     "r.json: patches[0].grid: error: expected an array of two integers in 4..64, found an "
     "array [3,6]"},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "patches": [{"name": "a",
        "region": {"joint": "J", "radius": 5}, "grid": [8, 8], "sampling": [6, 6]}]})",
     "r.json: patches[0].sampling: error: expected at least the grid (8x8) each way, found 6x6"},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "patches": [{"name": "a",
        "region": {"joint": "J"}}]})",
     "r.json: patches[0].region.radius: error: missing (model units, > 0)"},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "patches": [{"name": "a",
        "region": {"joint": "J", "radius": 5, "vertices": [1, 2, 3]}}]})",
     "r.json: patches[0].region: error: expected exactly one of \"joint\" (with \"radius\"), "
     "\"vertices\" or \"view\" (with \"rect\")"},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "patches": [{"name": "a",
        "region": {"vertices": [1, -2, 3]}}]})",
     "r.json: patches[0].region.vertices[1]: error: expected a vertex index (integer >= 0), "
     "found -2"},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "patches": [{"name": "a",
        "region": {"view": "top", "rect": [0, 0, 1, 1]}}]})",
     "r.json: patches[0].region.view: error: expected one of \"front\", \"back\", \"left\", "
     "\"right\", found \"top\""},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "patches": [{"name": "a",
        "region": {"view": "front", "rect": [0.5, 0, 0.2, 1]}}]})",
     "r.json: patches[0].region.rect: error: expected x0 < x1 and y0 < y1, found an array "
     "[0.5,0,0.2,1]"},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "patches": [{"name": "a",
        "region": {"joint": "J", "radius": 5}, "parametrization": "sphere"}]})",
     "r.json: patches[0].parametrization: error: expected one of \"cylinder\", \"plane\", found "
     "\"sphere\""},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "patches": [{"name": "a",
        "region": {"joint": "J", "radius": 5}, "examples": {}}]})",
     "r.json: patches[0].examples: error: expected an array of examples, found an object"},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "patches": [{"name": "a",
        "region": {"joint": "J", "radius": 5}, "elastic": 3}]})",
     "r.json: patches[0].elastic: error: expected an object, found 3"},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "patches": [{"name": "a",
        "region": {"joint": "J", "radius": 5}, "elastic": {"stiffness": 3}}]})",
     "r.json: patches[0].elastic.stiffness: error: unknown field (expected one of: joint, mass, "
     "frequency_hz, damping_ratio, structural_ratio, shear_ratio, bending_ratio, "
     "spring_damping_s, time_step_s, gain, gravity, preroll_s, max_displacement, "
     "max_acceleration_mps2, units_per_metre, cutoff_hz, force_model)"},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "patches": [{"name": "a",
        "region": {"joint": "J", "radius": 5}, "elastic": {"frequency_hz": 0}}]})",
     "r.json: patches[0].elastic.frequency_hz: error: expected a number in 0.1..30, found 0"},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "patches": [{"name": "a",
        "region": {"joint": "J", "radius": 5}, "elastic": {"damping_ratio": "high"}}]})",
     "r.json: patches[0].elastic.damping_ratio: error: expected a number in 0..10, found "
     "\"high\""},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "patches": [{"name": "a",
        "region": {"joint": "J", "radius": 5}, "elastic": {"time_step_s": 1}}]})",
     "r.json: patches[0].elastic.time_step_s: error: expected a number in 0.0001..0.05, found 1"},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "patches": [{"name": "a",
        "region": {"joint": "J", "radius": 5}, "elastic": {"gravity": 1}}]})",
     "r.json: patches[0].elastic.gravity: error: expected true or false, found 1"},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "patches": [{"name": "a",
        "region": {"joint": "J", "radius": 5}, "elastic": {"joint": ""}}]})",
     "r.json: patches[0].elastic.joint: error: expected a non-empty string, found \"\""},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "patches": [{"name": "a",
        "region": {"joint": "J", "radius": 5}, "elastic": {"force_model": "cubic"}}]})",
     "r.json: patches[0].elastic.force_model: error: expected one of \"linear\", \"length\", "
     "found \"cubic\""},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "patches": [{"name": "a",
        "region": {"joint": "J", "radius": 5}, "grid": [20, 8], "sampling": [20, 8],
        "elastic": {}}]})",
     "r.json: patches[0].elastic: error: expected a grid of at most 16x16 control points for an "
     "elastic patch, found 20x8"},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "patches": [{"name": "a",
        "region": {"joint": "J", "radius": 5}}, {"name": "a", "region": {"joint": "K",
        "radius": 5}}]})",
     "r.json: patches[1].name: error: expected a unique name, found \"a\" twice"},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "patches": [{"name": "a",
        "region": {"joint": "J", "radius": 5}, "border_width": 0.7}]})",
     "r.json: patches[0].border_width: error: expected a number in 0..0.5, found 0.7"},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "render": {"size": [8, 8]}})",
     "r.json: render.size: error: expected an array of two integers in 16..16384, found an "
     "array [8,8]"},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "render": {"overlays":
        ["bones"]}})",
     "r.json: render.overlays[0]: error: expected one of \"skeleton\", \"wire\", \"patches\", "
     "\"delta\", found \"bones\""},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "render": {"split": 1}})",
     "r.json: render.split: error: expected true or false, found 1"},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "render": {"wipe": "yes"}})",
     "r.json: render.wipe: error: expected true or false, found \"yes\""},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "render": {"output": "../x_####.png"}})",
     "r.json: render.output: error: expected a relative path inside the rig's output folder, "
     "found '../x_####.png' (a '..' component)"},
    {R"({"character": "mannequin", "motion": {"file": "m.bvh"}, "render": {"output": "/tmp/x_####.png"}})",
     "r.json: render.output: error: expected a relative path inside the rig's output folder, "
     "found '/tmp/x_####.png' (an absolute path)"},
};

TEST(RigFile, ElasticDefaultsAndEveryField) {
  const auto defaults = app::ParseRig(R"({"character": "mannequin", "motion": {"file": "m.bvh"},
      "patches": [{"name": "a", "region": {"joint": "J", "radius": 5}, "elastic": {}},
                  {"name": "b", "region": {"joint": "J", "radius": 5}}]})",
                                      "r.json");
  ASSERT_TRUE(defaults.ok()) << defaults.error().ToString();
  ASSERT_TRUE(defaults->patches[0].elastic.has_value());
  EXPECT_FALSE(defaults->patches[1].elastic.has_value());
  const app::RigElastic& d = *defaults->patches[0].elastic;
  const deform::MassSpringParams library;
  EXPECT_EQ(d.joint, "");
  EXPECT_EQ(d.units_per_metre, 0.0f);
  EXPECT_EQ(d.cutoff_hz, 10.0);
  EXPECT_EQ(d.params.frequency_hz, library.frequency_hz);
  EXPECT_EQ(d.params.damping_ratio, library.damping_ratio);
  EXPECT_EQ(d.params.time_step_s, library.time_step_s);
  EXPECT_EQ(d.params.preroll_s, 1.0);  // the rig's default: start settled
  EXPECT_TRUE(d.params.gravity);

  const auto full = app::ParseRig(R"({"character": "mannequin", "motion": {"file": "m.bvh"},
      "patches": [{"name": "a", "region": {"joint": "J", "radius": 5}, "grid": [5, 7],
        "elastic": {"joint": "Hips", "mass": 2, "frequency_hz": 5, "damping_ratio": 0.25,
                    "structural_ratio": 2, "shear_ratio": 0.75, "bending_ratio": 0.5,
                    "spring_damping_s": 0.002, "time_step_s": 0.002, "gain": 1.5,
                    "gravity": false, "preroll_s": 2, "max_displacement": 4,
                    "max_acceleration_mps2": 300, "units_per_metre": 1, "cutoff_hz": 0,
                    "force_model": "length"}}]})",
                                  "r.json");
  ASSERT_TRUE(full.ok()) << full.error().ToString();
  const app::RigElastic& e = *full->patches[0].elastic;
  EXPECT_EQ(e.joint, "Hips");
  EXPECT_EQ(e.params.mass, 2.0f);
  EXPECT_EQ(e.params.frequency_hz, 5.0f);
  EXPECT_EQ(e.params.damping_ratio, 0.25f);
  EXPECT_EQ(e.params.structural_ratio, 2.0f);
  EXPECT_EQ(e.params.shear_ratio, 0.75f);
  EXPECT_EQ(e.params.bending_ratio, 0.5f);
  EXPECT_EQ(e.params.spring_damping_s, 0.002f);
  EXPECT_EQ(e.params.time_step_s, 0.002);
  EXPECT_EQ(e.params.gain, 1.5f);
  EXPECT_FALSE(e.params.gravity);
  EXPECT_EQ(e.params.preroll_s, 2.0);
  EXPECT_EQ(e.params.max_displacement, 4.0f);
  EXPECT_EQ(e.params.max_acceleration_mps2, 300.0f);
  EXPECT_EQ(e.units_per_metre, 1.0f);
  EXPECT_EQ(e.cutoff_hz, 0.0);
  EXPECT_EQ(e.params.force_model, deform::SpringForceModel::kLength);
}

TEST(RigFile, BadRigsGiveExactMessages) {
  for (const BadRig& bad : kBadRigs) {
    const base::Result<app::Rig> rig = app::ParseRig(bad.text, "r.json");
    ASSERT_FALSE(rig.ok()) << bad.text;
    EXPECT_EQ(rig.error().ToString(), bad.message) << bad.text;
  }
}

TEST(RigFile, MissingFileIsAnIoError) {
  const auto rig = app::LoadRig("/nonexistent/rig.json");
  ASSERT_FALSE(rig.ok());
  EXPECT_EQ(rig.error().code, base::ErrorCode::kIo);
}

namespace fs = std::filesystem;

TEST(RigFile, RenderCommandRendersTheSampleRigAsASplitFrame) {
  const fs::path dir = testsupport::TestOutputPath("rig_file/render/x").parent_path();
  fs::remove_all(dir);
  fs::create_directories(dir);
  const testsupport::ProcessResult r = testsupport::RunPatchskinLine(
      "render '" + testsupport::SampleDataPath("elbow_knee.json").string() +
          "' --frames 45:45 --no-video --no-sheet --quiet --out '" + (dir / "f_####.png").string() +
          "'",
      dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto img = render::ReadImage((dir / "f_0045.png").string());
  ASSERT_TRUE(img.ok());
  EXPECT_EQ(img->width, 1280);  // the rig's render.size
  EXPECT_EQ(img->height, 720);
}

TEST(RigFile, RenderCommandReportsABadJointWithItsFieldPath) {
  const fs::path dir = testsupport::TestOutputPath("rig_file/bad_joint/x").parent_path();
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path rig = dir / "bad.json";
  std::ofstream(rig)
      << R"({"character": "mannequin", "motion": {"file": ")"
      << testsupport::SampleDataPath("bend.bvh").string()
      << R"("}, "patches": [{"name": "e", "region": {"joint": "Elbow", "radius": 9}}]})";
  const testsupport::ProcessResult r = testsupport::RunPatchskinLine(
      "render '" + rig.string() + "' --no-video --no-sheet --quiet --out '" +
          (dir / "f_####.png").string() + "'",
      dir);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("bad.json: patches[0].region.joint: error: expected a joint of "), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir / "f_0000.png"));  // no partial output
}

TEST(RigFile, ScreenRegionBuildsAFrontPatchOnTheBelly) {
  const std::string bvh = testsupport::SampleDataPath("bend.bvh").string();
  auto source = app::LoadMotionSource(bvh, {.y_up = true});
  ASSERT_TRUE(source.ok()) << source.error().ToString();
  auto character = app::MakeCharacter(std::move(*source));
  ASSERT_TRUE(character.ok());
  const auto rig = app::ParseRig(
      R"({"character": "mannequin", "motion": {"file": "b.bvh"}, "patches": [{"name": "belly",
          "region": {"view": "front", "rect": [0.44, 0.42, 0.56, 0.52]},
          "parametrization": "plane", "grid": [5, 5]}]})",
      "r.json");
  ASSERT_TRUE(rig.ok()) << rig.error().ToString();
  const auto patches = app::BuildRigPatches(*rig, *character);
  ASSERT_TRUE(patches.ok()) << patches.error().ToString();
  ASSERT_EQ(patches->size(), 1u);
  const deform::PatchSetup& p = (*patches)[0];
  EXPECT_GT(p.num_bound(), 20);
  std::vector<glm::vec3> normals(character->mesh.bind.positions.size());
  deform::ComputeVertexNormals(character->mesh.bind.positions, character->mesh.bind.triangles,
                               normals);
  for (const int v : p.region) EXPECT_GT(normals[static_cast<std::size_t>(v)].z, 0.0f) << v;
  // A cylinder needs a joint axis.
  const auto cyl = app::ParseRig(
      R"({"character": "mannequin", "motion": {"file": "b.bvh"}, "patches": [{"name": "v",
          "region": {"vertices": [1, 2, 3]}}]})",
      "r.json");
  ASSERT_TRUE(cyl.ok());
  EXPECT_EQ(app::BuildRigPatches(*cyl, *character).error().ToString(),
            "r.json: patches[0].parametrization: error: expected \"plane\" for a vertex-list or "
            "screen region (a cylinder needs a joint for its axis), found \"cylinder\"");
}

}  // namespace
