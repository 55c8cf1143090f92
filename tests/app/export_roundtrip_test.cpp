// `patchskin export` read back with the project's own importer
// (deform/io/gltf_import.h, morph targets and rigid mesh nodes; GltfMeshSampler):
// a patch rig and a plain BVH, each exported over several frames, give back at
// every key time the vertices the pipeline computed for that frame, and the
// key times are frame / fps. The OBJ of a patch rig, drawn with its camera
// JSON, is the frame `render` draws for the rig.

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/frame_plan.h"
#include "app/motion_source.h"
#include "app/character.h"
#include "deform/pipeline/frame_pipeline.h"
#include "app/rig_file.h"
#include "app/rig_setup.h"
#include "deform/io/gltf_import.h"
#include "deform/io/gltf_mesh_sampler.h"
#include "render/output/image_io.h"
#include "render/renderer.h"
#include "support/data_paths.h"
#include "support/exported_geometry.h"
#include "support/run_process.h"
#include "support/tolerances.h"

namespace {

using testsupport::TestDir;

namespace fs = std::filesystem;

// A rig with one cylinder patch on the left elbow of the mannequin driven by
// bend.bvh, with one example shape (a patch without any adds nothing), unsplit
// so render draws exactly the layered mesh.
fs::path WriteElbowRig(const fs::path& dir) {
  const fs::path rig = dir / "elbow.json";
  std::ofstream(rig) << R"({"character": "mannequin", "motion": {"file": ")"
                     << testsupport::SampleDataPath("bend.bvh").string() << R"("},
    "global": "ssd",
    "patches": [{"name": "left_elbow",
                 "region": {"joint": "LeftForeArm", "radius": 14, "side": [0, 0, 1], "half_angle_deg": 120},
                 "parametrization": "cylinder", "sampling": [8, 8], "grid": [6, 6],
                 "examples": [{"pose": {"frame": 45},
                               "edits": [{"point": [0.5, 0.5], "move": [0, 0, 1.5]}]}]}],
    "render": {"size": [96, 64], "camera": "fixed", "split": false}})";
  return rig;
}

// The character of a rig and a pipeline with the rig's layers, as export builds them.
struct RigRun {
  app::Rig rig;
  std::unique_ptr<app::Character> character;
  std::optional<deform::FramePipeline> pipeline;
};

RigRun LoadRigRun(const fs::path& rig_path) {
  RigRun r;
  auto rig = app::LoadRig(rig_path.string());
  EXPECT_TRUE(rig.ok()) << rig.error().ToString();
  r.rig = std::move(*rig);
  auto src = app::LoadMotionSource(r.rig.motion, {.y_up = true});
  EXPECT_TRUE(src.ok()) << src.error().ToString();
  auto ch = app::MakeCharacter(std::move(*src));
  EXPECT_TRUE(ch.ok());
  r.character = std::make_unique<app::Character>(std::move(*ch));
  auto p = deform::FramePipeline::Create(*r.character, deform::GlobalMethod::kSsd, 1);
  EXPECT_TRUE(p.ok());
  r.pipeline.emplace(std::move(*p));
  EXPECT_TRUE(app::ApplyRigLayers(r.rig, *r.character, *r.pipeline).ok());
  return r;
}

base::Result<deform::GltfModel> ReadExport(const fs::path& glb) {
  deform::GltfReadOptions options;
  options.require_skin = false;  // an export holds plain (morphed or per-frame) meshes
  return deform::ReadGltf(glb.string(), options);
}

float MaxAbs(const std::vector<glm::vec3>& v) {
  float m = 1.0f;
  for (const glm::vec3& p : v) m = std::max({m, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
  return m;
}

TEST(ExportRoundTrip, PatchRigGlbReadsBackWithOurImporter) {
  const fs::path dir = TestDir();
  const fs::path rig = WriteElbowRig(dir);
  const testsupport::ProcessResult run = testsupport::RunPatchskin(
      {"export", rig.string(), "--frames", "0:60:6", "--layout", "morph", "--quiet", "--out",
       (dir / "elbow.glb").string()},
      dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;

  RigRun ref = LoadRigRun(rig);
  ASSERT_EQ(ref.pipeline->num_patches(), 1);
  auto global_only = deform::FramePipeline::Create(*ref.character, deform::GlobalMethod::kSsd, 1);
  ASSERT_TRUE(global_only.ok());
  auto plan = app::PlanFrames(ref.character->motion, {.frames = "0:60:6"});
  ASSERT_TRUE(plan.ok());
  ASSERT_EQ(plan->frames.size(), 11u);

  auto model = ReadExport(dir / "elbow.glb");
  ASSERT_TRUE(model.ok()) << model.error().ToString();
  ASSERT_EQ(model->morph.num_targets, 11);
  ASSERT_EQ(model->animations.size(), 1u);
  ASSERT_EQ(model->animations[0].weights_channels.size(), 1u);
  // Frame timing: key k at k x (frame time x step) seconds, stored as float.
  const deform::GltfWeightsChannel& keys = model->animations[0].weights_channels[0];
  const double key_step_s = plan->frame_time_s * plan->range.step;
  ASSERT_EQ(keys.num_keys(), 11);
  for (int k = 0; k < keys.num_keys(); ++k) {
    EXPECT_EQ(keys.times_s[static_cast<std::size_t>(k)], static_cast<float>(k * key_step_s)) << k;
  }
  EXPECT_NEAR(model->animations[0].duration_s, 10 * key_step_s, 1e-6);

  auto sampler = deform::GltfMeshSampler::Create(*model);
  ASSERT_TRUE(sampler.ok()) << sampler.error().ToString();
  deform::DeformedFrame frame, plain;
  const std::size_t nv = ref.character->mesh.bind.positions.size();
  std::vector<glm::vec3> p(nv), n(nv);
  float patch_effect = 0.0f;
  for (std::size_t k = 0; k < plan->frames.size(); ++k) {
    const app::OutputFrame& of = plan->frames[k];
    ASSERT_TRUE(ref.pipeline->Evaluate(of.time_s, frame).ok());
    ASSERT_TRUE(global_only->Evaluate(of.time_s, plain).ok());
    ASSERT_TRUE(sampler->Sample(0, of.time_s - plan->frames.front().time_s, p, n).ok());
    // base + (frame - base) in float: a couple of ulps of the largest coordinate.
    const float tol = testsupport::kMorphRoundTripTol * MaxAbs(frame.positions);
    float worst = 0.0f, worst_normal = 0.0f;
    for (std::size_t v = 0; v < nv; ++v) {
      worst = std::max(worst, glm::length(p[v] - frame.positions[v]));
      worst_normal = std::max(worst_normal, glm::length(n[v] - frame.normals[v]));
      patch_effect = std::max(patch_effect, glm::length(frame.positions[v] - plain.positions[v]));
    }
    EXPECT_LE(worst, tol) << "frame " << of.number;
    EXPECT_LE(worst_normal, testsupport::kMorphRoundTripTol * 4.0f) << "frame " << of.number;
  }
  // The export carries the rig's layer: the elbow differs from global-only skinning.
  EXPECT_GT(patch_effect, 0.01f);
}

// Baked layout: one mesh per frame on its own node, shown by a STEP scale
// animation. Read as rigid mesh nodes, frame k's block of vertices is frame k
// (exact: identity node transforms) at key k, and every other block has
// scale 0 (collapsed onto its node's origin).
TEST(ExportRoundTrip, BvhBakedGlbShowsOneFramePerKey) {
  const fs::path dir = TestDir();
  const testsupport::ProcessResult run = testsupport::RunPatchskin(
      {"export", testsupport::SampleDataPath("bend.bvh").string(), "--frames", "10:30:5",
       "--layout", "baked", "--global", "dqs", "--quiet", "--out", (dir / "bend.glb").string()},
      dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;

  auto src =
      app::LoadMotionSource(testsupport::SampleDataPath("bend.bvh").string(), {.y_up = true});
  ASSERT_TRUE(src.ok());
  auto ch = app::MakeCharacter(std::move(*src), {}, app::BodyKind::kGenerated);  // export's default body
  ASSERT_TRUE(ch.ok());
  auto pipeline = deform::FramePipeline::Create(*ch, deform::GlobalMethod::kDqs, 1);
  ASSERT_TRUE(pipeline.ok());
  auto plan = app::PlanFrames(ch->motion, {.frames = "10:30:5"});
  ASSERT_TRUE(plan.ok());
  const std::size_t frames = plan->frames.size();
  ASSERT_EQ(frames, 5u);

  auto model = ReadExport(dir / "bend.glb");
  ASSERT_TRUE(model.ok()) << model.error().ToString();
  const std::size_t nv = ch->mesh.bind.positions.size();
  ASSERT_EQ(model->mesh.bind.positions.size(), frames * nv);
  EXPECT_EQ(model->morph.num_targets, 0);
  auto sampler = deform::GltfMeshSampler::Create(*model);
  ASSERT_TRUE(sampler.ok()) << sampler.error().ToString();
  std::vector<glm::vec3> p(frames * nv), n(frames * nv);
  deform::DeformedFrame frame;
  const double key_step_s = plan->frame_time_s * plan->range.step;
  for (std::size_t k = 0; k < frames; ++k) {
    ASSERT_TRUE(pipeline->Evaluate(plan->frames[k].time_s, frame).ok());
    // At key k and half-way to key k+1 (STEP holds).
    const double key = static_cast<double>(k);
    for (const double t : {key * key_step_s, (key + 0.5) * key_step_s}) {
      ASSERT_TRUE(sampler->Sample(0, t, p, n).ok());
      for (std::size_t block = 0; block < frames; ++block) {
        for (std::size_t v = 0; v < nv; ++v) {
          const glm::vec3 got = p[block * nv + v];
          if (block == k) {
            ASSERT_EQ(got, frame.positions[v]) << "key " << k << " vertex " << v;
          } else {
            ASSERT_EQ(got, glm::vec3(0.0f)) << "key " << k << " block " << block;
          }
        }
      }
    }
  }
}

// The OBJ of a patch rig drawn with its exported camera is the frame `render`
// draws for that rig, pixel for pixel.
TEST(ExportRoundTrip, PatchRigObjIsWhatRenderDrew) {
  const fs::path dir = TestDir();
  const fs::path rig = WriteElbowRig(dir);
  testsupport::ProcessResult run = testsupport::RunPatchskin(
      {"render", rig.string(), "--frames", "45:45", "--supersample", "1", "--no-sheet", "--no-video",
       "--quiet", "--out", (dir / "frame_####.png").string()},
      dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  run = testsupport::RunPatchskin({"export", rig.string(), "--frames", "45:45", "--with-camera", "--quiet",
                                   "--out", (dir / "mesh_####.obj").string()},
                                  dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;

  const testsupport::ParsedObj obj = testsupport::ParseObjFile((dir / "mesh_0045.obj").string());
  ASSERT_TRUE(obj.error.empty()) << obj.error;
  RigRun ref = LoadRigRun(rig);
  // Same vertices as the layered pipeline, bit for bit, in the same order.
  deform::DeformedFrame frame;
  auto plan = app::PlanFrames(ref.character->motion, {.frames = "45:45"});
  ASSERT_TRUE(plan.ok());
  ASSERT_TRUE(ref.pipeline->Evaluate(plan->frames[0].time_s, frame).ok());
  ASSERT_EQ(obj.positions, frame.positions);
  ASSERT_EQ(obj.normals, frame.normals);
  EXPECT_EQ(obj.triangles, ref.character->mesh.bind.triangles);

  const nlohmann::json j = nlohmann::json::parse(testsupport::SlurpFile(dir / "camera_0045.json"));
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
  EXPECT_EQ(settings.width, 96);  // the rig's render.size
  settings.supersample = 1;
  settings.threads = 1;
  settings.ground_at_scene_min = false;
  settings.ground_y = j["ground_y"].get<float>();
  const render::SceneMesh body{.positions = obj.positions, .normals = obj.normals,
                               .triangles = obj.triangles,
                               .vertex_colors = ref.character->mesh.bind.colors};
  render::Overlays overlays;  // render labels every frame with its number
  overlays.text.push_back({.text = "frame 45", .origin_px = {10, settings.height - 12}});
  render::Renderer renderer;
  render::Image image;
  ASSERT_TRUE(renderer.Render(cam, {&body, 1}, overlays, settings, image));
  ASSERT_TRUE(render::WriteImage(image, (dir / "from_obj.png").string(), {}));
  auto a = render::ReadImage((dir / "frame_0045.png").string());
  auto b = render::ReadImage((dir / "from_obj.png").string());
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(a->width, b->width);
  ASSERT_EQ(a->height, b->height);
  int differing = 0;
  for (int y = 0; y < a->height; ++y) {
    for (int x = 0; x < a->width; ++x) differing += a->at(x, y) != b->at(x, y) ? 1 : 0;
  }
  EXPECT_EQ(differing, 0);
}

// --scale multiplies the written positions and the camera's lengths: the
// scaled scene seen by the scaled camera projects every vertex where the
// unscaled one did.
TEST(ExportRoundTrip, ScaleMultipliesPositionsAndCameraLengths) {
  const fs::path dir = TestDir();
  for (const std::string scale : {"1", "0.01"}) {
    const testsupport::ProcessResult run =
        testsupport::RunPatchskin({"export", testsupport::SampleDataPath("bend.bvh").string(),
                                   "--frames", "20:20", "--with-camera", "--scale", scale,
                                   "--quiet", "--out", (dir / scale / "mesh_####.obj").string()},
                                  dir);
    ASSERT_EQ(run.exit_code, 0) << run.err;
  }
  const testsupport::ParsedObj a = testsupport::ParseObjFile((dir / "1" / "mesh_0020.obj").string());
  const testsupport::ParsedObj b = testsupport::ParseObjFile((dir / "0.01" / "mesh_0020.obj").string());
  ASSERT_TRUE(a.error.empty() && b.error.empty()) << a.error << b.error;
  ASSERT_EQ(a.positions.size(), b.positions.size());
  for (std::size_t v = 0; v < a.positions.size(); ++v) ASSERT_EQ(b.positions[v], a.positions[v] * 0.01f) << v;
  EXPECT_EQ(a.normals, b.normals);
  const nlohmann::json ja = nlohmann::json::parse(testsupport::SlurpFile(dir / "1" / "camera_0020.json"));
  const nlohmann::json jb = nlohmann::json::parse(testsupport::SlurpFile(dir / "0.01" / "camera_0020.json"));
  EXPECT_EQ(jb["near"].get<float>(), ja["near"].get<float>() * 0.01f);
  EXPECT_EQ(jb["ground_y"].get<float>(), ja["ground_y"].get<float>() * 0.01f);
  auto matrix = [](const nlohmann::json& j) {
    glm::mat4 m;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) m[c][r] = j[static_cast<std::size_t>(4 * c + r)].get<float>();
    return m;
  };
  const glm::mat4 clip_a = matrix(ja["projection"]) * matrix(ja["view"]);
  const glm::mat4 clip_b = matrix(jb["projection"]) * matrix(jb["view"]);
  for (std::size_t v = 0; v < a.positions.size(); v += 97) {
    const glm::vec4 pa = clip_a * glm::vec4(a.positions[v], 1.0f);
    const glm::vec4 pb = clip_b * glm::vec4(b.positions[v], 1.0f);
    EXPECT_NEAR(pa.x / pa.w, pb.x / pb.w, testsupport::kFloatTol * 10.0f) << v;
    EXPECT_NEAR(pa.y / pa.w, pb.y / pb.w, testsupport::kFloatTol * 10.0f) << v;
  }
  const testsupport::ProcessResult bad =
      testsupport::RunPatchskin({"export", testsupport::SampleDataPath("bend.bvh").string(),
                                 "--scale", "-1", "--quiet", "--out", (dir / "bad.glb").string()},
                                dir);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.FirstErrLine().find("--scale"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir / "bad.glb"));
}

TEST(ExportRoundTrip, BadRigIsRefusedWithoutOutput) {
  const fs::path dir = TestDir();
  const fs::path rig = dir / "bad.json";
  std::ofstream(rig)
      << R"({"character": "mannequin", "motion": {"file": ")"
      << testsupport::SampleDataPath("bend.bvh").string()
      << R"("}, "patches": [{"name": "e", "region": {"joint": "Elbow", "radius": 9}}]})";
  const testsupport::ProcessResult run = testsupport::RunPatchskin(
      {"export", rig.string(), "--quiet", "--out", (dir / "out.glb").string()}, dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.FirstErrLine().find("bad.json: patches[0].region.joint: error:"), std::string::npos) << run.err;
  EXPECT_FALSE(fs::exists(dir / "out.glb"));
  for (const auto& e : fs::directory_iterator(dir)) {
    EXPECT_EQ(e.path().filename().string().find(".patchskin-glb"), std::string::npos) << e.path();
  }
}

}  // namespace

namespace {

// A .glb's JSON chunk and binary chunk, read by hand (not through tinygltf, which wrote it).
struct Glb {
  nlohmann::json json;
  std::string bin;

  std::vector<float> Floats(int accessor) const {
    const nlohmann::json& a = json["accessors"][static_cast<std::size_t>(accessor)];
    const nlohmann::json& view = json["bufferViews"][a["bufferView"].get<std::size_t>()];
    const std::size_t width = a["type"] == "SCALAR" ? 1 : a["type"] == "VEC3" ? 3 : 4;
    std::vector<float> out(a["count"].get<std::size_t>() * width);
    const std::size_t offset = view.value("byteOffset", std::size_t{0}) + a.value("byteOffset", std::size_t{0});
    EXPECT_LE(offset + out.size() * sizeof(float), bin.size());
    std::memcpy(out.data(), bin.data() + offset, out.size() * sizeof(float));
    return out;
  }
};

Glb ReadGlb(const fs::path& path) {
  const std::string bytes = testsupport::SlurpFile(path);
  Glb g;
  std::uint32_t json_length = 0, bin_length = 0;
  EXPECT_GE(bytes.size(), 28u);
  std::memcpy(&json_length, bytes.data() + 12, 4);
  g.json = nlohmann::json::parse(bytes.substr(20, json_length));
  std::memcpy(&bin_length, bytes.data() + 20 + json_length, 4);
  g.bin = bytes.substr(28 + json_length, bin_length);
  return g;
}

// Issue 27: `export --with-camera` to a .glb carries the render's camera as a glTF camera
// node keyed at every frame, in both layouts: at key k its position is the eye of
// camera_####.json and its node transform inverted is that file's view matrix.
TEST(ExportRoundTrip, GlbCarriesTheRenderCameraAsAnAnimatedNode) {
  const fs::path dir = TestDir();
  for (const std::string layout : {"morph", "baked"}) {
    SCOPED_TRACE(layout);
    const fs::path out = dir / ("camera_" + layout) / "bend.glb";
    const testsupport::ProcessResult run = testsupport::RunPatchskin(
        {"export", testsupport::SampleDataPath("bend.bvh").string(), "--frames", "10:30:10",
         "--with-camera", "--scale", "0.01", "--layout", layout, "--quiet", "--out", out.string()},
        dir);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const Glb glb = ReadGlb(out);
    ASSERT_EQ(glb.json["cameras"].size(), 1u);
    const nlohmann::json& lens = glb.json["cameras"][0]["perspective"];
    int node = -1;
    for (std::size_t n = 0; n < glb.json["nodes"].size(); ++n) {
      if (glb.json["nodes"][n].contains("camera")) node = static_cast<int>(n);
    }
    ASSERT_GE(node, 0);
    const auto& roots = glb.json["scenes"][0]["nodes"];
    EXPECT_NE(std::find(roots.begin(), roots.end(), node), roots.end()) << "the camera is not in the scene";
    std::vector<float> times, translations, rotations;
    for (const nlohmann::json& anim : glb.json["animations"]) {
      for (const nlohmann::json& c : anim["channels"]) {
        if (c["target"]["node"] != node) continue;
        const nlohmann::json& sampler = anim["samplers"][c["sampler"].get<std::size_t>()];
        times = glb.Floats(sampler["input"]);
        (c["target"]["path"] == "translation" ? translations : rotations) = glb.Floats(sampler["output"]);
      }
    }
    ASSERT_EQ(times.size(), 3u);
    ASSERT_EQ(translations.size(), 9u);
    ASSERT_EQ(rotations.size(), 12u);
    for (int k = 0; k < 3; ++k) {
      const int number = 10 + 10 * k;
      char name[32];
      std::snprintf(name, sizeof(name), "camera_%04d.json", number);
      const nlohmann::json cam = nlohmann::json::parse(testsupport::SlurpFile(out.parent_path() / name));
      EXPECT_NEAR(times[static_cast<std::size_t>(k)], cam["time_s"].get<float>() - 10.0f / 30.0f, 1e-5f) << k;
      EXPECT_NEAR(lens["yfov"].get<float>(), glm::radians(cam["fov_y_deg"].get<float>()), 1e-6f);
      EXPECT_NEAR(lens["znear"].get<float>(), cam["near"].get<float>(), 1e-7f);
      const glm::vec3 eye(translations[3 * k], translations[3 * k + 1], translations[3 * k + 2]);
      const glm::quat q(rotations[4 * k + 3], rotations[4 * k], rotations[4 * k + 1], rotations[4 * k + 2]);
      for (int i = 0; i < 3; ++i) EXPECT_NEAR(eye[i], cam["eye"][static_cast<std::size_t>(i)].get<float>(), 1e-6f);
      const glm::mat4 view = glm::inverse(glm::translate(glm::mat4(1.0f), eye) * glm::mat4_cast(q));
      for (int c = 0; c < 4; ++c) {
        for (int r = 0; r < 4; ++r) {
          EXPECT_NEAR(view[c][r], cam["view"][static_cast<std::size_t>(4 * c + r)].get<float>(), 1e-4f)
              << "key " << k << " view[" << c << "][" << r << "]";
        }
      }
    }
  }
}

}  // namespace
