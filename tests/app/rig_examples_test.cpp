// Example shapes through the rig file (issue 6): parsing `examples` and
// `pose_space`, sculpting at the example pose, and dS(theta) in the pipeline.

#include "app/rig_examples.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "app/motion_source.h"
#include "app/character.h"
#include "deform/pipeline/frame_pipeline.h"
#include "app/rig_file.h"
#include "app/rig_patches.h"
#include "app/rig_setup.h"
#include "deform/shapes/example_shapes.h"
#include "deform/global/skinning_job.h"
#include "mocap/pose.h"
#include "support/data_paths.h"
#include "support/tolerances.h"

namespace {

namespace fs = std::filesystem;

// The left elbow patch of samples/data/elbow_knee.json, on bend.bvh (elbows
// 0 -> 150 degrees over frames 0..60), with `extra` appended to the patch.
std::string ElbowRig(const std::string& extra) {
  return R"({"character": "mannequin", "motion": {"file": "bend.bvh"}, "patches": [
    {"name": "left_elbow",
     "region": {"joint": "LeftForeArm", "radius": 14, "side": [0, 0, 1], "half_angle_deg": 120},
     "sampling": [8, 8], "grid": [6, 6], "border_width": 0.1)" +
         extra + "}]}";
}

struct ElbowFixture {
  app::Character character;
  std::vector<deform::PatchSetup> patches;
};

std::optional<ElbowFixture> LoadElbowFixture() {
  const std::string bvh = testsupport::SampleDataPath("bend.bvh").string();
  auto source = app::LoadMotionSource(bvh, {.y_up = true});
  if (!source.ok()) return std::nullopt;
  auto character = app::MakeCharacter(std::move(*source));
  if (!character.ok()) return std::nullopt;
  ElbowFixture f{std::move(*character), {}};
  auto rig = app::ParseRig(ElbowRig(""), "r.json");
  if (!rig.ok()) return std::nullopt;
  auto patches = app::BuildRigPatches(*rig, f.character);
  if (!patches.ok()) return std::nullopt;
  f.patches = std::move(*patches);
  return f;
}

// Bound vertices of the patch with the full border weight (beta = 1), the
// `count` nearest the centre of those, so the patch moves them alone.
std::vector<int> InteriorVertices(const deform::PatchSetup& p, int count) {
  glm::dvec2 centre(0.0);
  std::vector<std::size_t> inner;
  for (std::size_t b = 0; b < p.bound.binding.size(); ++b) {
    if (p.border_weight[b] >= 1.0f) {
      inner.push_back(b);
      centre += glm::dvec2(p.bound.binding.u[b], p.bound.binding.v[b]);
    }
  }
  centre /= static_cast<double>(inner.size());
  auto dist = [&](std::size_t b) {
    return glm::length(glm::dvec2(p.bound.binding.u[b], p.bound.binding.v[b]) - centre);
  };
  std::sort(inner.begin(), inner.end(), [&](std::size_t a, std::size_t b) { return dist(a) < dist(b); });
  std::vector<int> out;
  // Every third record: neighbours would ask for nearly coincident constraints.
  for (std::size_t k = 0; k < inner.size() && static_cast<int>(out.size()) < count; k += 3) {
    out.push_back(p.bound.binding.vertex[inner[k]]);
  }
  return out;
}

// Runs the rig's patch (with its examples when `with_examples`) at `time_s`.
struct Evaluated {
  std::vector<glm::vec3> global_patches;  // patches, no examples
  std::vector<glm::vec3> with_examples;   // patches + dS
};

base::Result<deform::FramePipeline> MakePipeline(const ElbowFixture& f, const app::Rig* rig) {
  auto pipeline = deform::FramePipeline::Create(f.character, deform::GlobalMethod::kSsd, 1);
  if (!pipeline.ok()) return pipeline;
  if (base::Status s = pipeline->SetPatches(f.patches); !s.ok()) return s.error();
  if (rig) {
    auto spaces = app::BuildRigPoseSpaces(*rig, f.character, f.patches, deform::GlobalMethod::kSsd);
    if (!spaces.ok()) return std::move(spaces).error();
    if (base::Status s = pipeline->SetPoseSpaces(std::move(spaces->patches)); !s.ok()) {
      return s.error();
    }
  }
  return pipeline;
}

std::string Vec(const glm::dvec3& v) {
  std::ostringstream s;
  s.precision(9);
  s << "[" << v.x << ", " << v.y << ", " << v.z << "]";
  return s.str();
}

TEST(RigExamples, ParsesExamplesAndPoseSpace) {
  const auto rig = app::ParseRig(ElbowRig(R"(, "examples": [
      {"pose": {"frame": 45}, "edits": [{"vertex": 12, "move": [0, 0, 1.5]},
                                        {"point": [0.5, 0.25], "move": [1, 2, 3], "frame": "world"}]},
      {"pose": {"joints": {"LeftForeArm": [0, -90, 0], "LeftArm": [10, 0, 0]}},
       "edits": [{"vertex": 7, "move": [0, -1, 0], "frame": "bind"}]}],
    "pose_space": {"features": "euler", "kernel": "inverse-multiquadric", "kappa": 1.5,
                   "width": 0.7, "joints": ["LeftForeArm"]})"),
                                 "r.json");
  ASSERT_TRUE(rig.ok()) << rig.error().ToString();
  const app::RigPatch& p = rig->patches[0];
  ASSERT_EQ(p.examples.size(), 2u);
  EXPECT_EQ(p.examples[0].pose.frame, 45);
  ASSERT_EQ(p.examples[0].edits.size(), 2u);
  EXPECT_EQ(p.examples[0].edits[0].vertex, 12);
  EXPECT_EQ(p.examples[0].edits[0].move, glm::dvec3(0, 0, 1.5));
  EXPECT_FALSE(p.examples[0].edits[0].world);
  EXPECT_EQ(p.examples[0].edits[1].vertex, -1);
  EXPECT_EQ(p.examples[0].edits[1].point, glm::dvec2(0.5, 0.25));
  EXPECT_TRUE(p.examples[0].edits[1].world);
  EXPECT_EQ(p.examples[0].edits[1].path, "patches[0].examples[0].edits[1]");
  EXPECT_EQ(p.examples[1].pose.frame, -1);
  ASSERT_EQ(p.examples[1].pose.joints.size(), 2u);
  EXPECT_EQ(p.examples[1].pose.joints[0].first, "LeftArm");  // sorted by name
  EXPECT_EQ(p.examples[1].pose.joints[0].second, glm::vec3(10, 0, 0));
  EXPECT_EQ(p.examples[1].pose.joints[1].first, "LeftForeArm");
  EXPECT_EQ(p.examples[1].pose.joints[1].second, glm::vec3(0, -90, 0));
  EXPECT_EQ(p.pose_space.features, "euler");
  EXPECT_EQ(p.pose_space.kernel, "inverse-multiquadric");
  EXPECT_EQ(p.pose_space.kappa, 1.5);
  EXPECT_EQ(p.pose_space.width, 0.7);
  EXPECT_EQ(p.pose_space.joints, std::vector<std::string>{"LeftForeArm"});
}

struct BadExample {
  const char* extra;
  const char* message;
};

const BadExample kBadExamples[] = {
    {R"(, "examples": [{"pose": {"frame": 3, "joints": {"A": [0, 0, 0]}}, "edits": []}])",
     "r.json: patches[0].examples[0].pose: error: expected exactly one of \"frame\" (a frame of "
     "the motion) or \"joints\" (joint name -> [x, y, z] degrees)"},
    {R"(, "examples": [{"pose": {"frame": -3}, "edits": []}])",
     "r.json: patches[0].examples[0].pose.frame: error: expected a frame index (integer >= 0), "
     "found -3"},
    {R"(, "examples": [{"pose": {"joints": {"A": [0, 0]}}, "edits": []}])",
     "r.json: patches[0].examples[0].pose.joints.A: error: expected an array of 3 numbers in "
     "-360..360, found an array [0,0]"},
    {R"(, "examples": [{"pose": {"frame": 3}}])",
     "r.json: patches[0].examples[0].edits: error: missing (an array of edits, or \"auto\": "
     "\"volume\" | \"rest\")"},
    {R"(, "examples": [{"pose": {"frame": 3}, "auto": "area"}])",
     "r.json: patches[0].examples[0].auto: error: expected \"volume\" or \"rest\", found \"area\""},
    {R"(, "examples": [{"pose": {"frame": 3}, "auto": "rest"}, {"pose": {"frame": 3}, "auto": "volume"}])",
     "r.json: patches[0].examples[1].pose: error: duplicates the pose of patches[0].examples[0] "
     "(one example per pose: merge their edits)"},
    {R"(, "examples": [{"pose": {"frame": 3}, "edits": []}])",
     "r.json: patches[0].examples[0].edits: error: expected an array of 1..256 edits, found an "
     "array []"},
    {R"(, "examples": [{"pose": {"frame": 3}, "edits": [{"vertex": 1, "point": [0, 0],
        "move": [0, 0, 1]}]}])",
     "r.json: patches[0].examples[0].edits[0]: error: expected exactly one of \"vertex\" (a mesh "
     "vertex index) or \"point\" ([u, v] on the patch)"},
    {R"(, "examples": [{"pose": {"frame": 3}, "edits": [{"point": [0.5, 1.5], "move": [0, 0, 1]}]}])",
     "r.json: patches[0].examples[0].edits[0].point: error: expected an array of 2 numbers in "
     "0..1, found an array [0.5,1.5]"},
    {R"(, "examples": [{"pose": {"frame": 3}, "edits": [{"vertex": 4}]}])",
     "r.json: patches[0].examples[0].edits[0].move: error: missing ([dx, dy, dz] model units)"},
    {R"(, "examples": [{"pose": {"frame": 3}, "edits": [{"vertex": 4, "move": [0, 0, 1],
        "frame": "local"}]}])",
     "r.json: patches[0].examples[0].edits[0].frame: error: expected \"bind\" or \"world\", found "
     "\"local\""},
    {R"(, "examples": [{"pose": {"frame": 3}, "edits": [{"vertex": 4, "move": [0, 0, 1],
        "scale": 2}]}])",
     "r.json: patches[0].examples[0].edits[0].scale: error: unknown field (expected one of: "
     "vertex, point, move, frame, radius)"},
    {R"(, "examples": [{"pose": {"frame": 3}, "edits": [{"point": [0.5, 0.5], "move": [0, 0, 1],
        "radius": 0}]}])",
     "r.json: patches[0].examples[0].edits[0].radius: error: expected a brush radius in 0.01..2 "
     "((u, v) units), found 0"},
    {R"(, "examples": [{"pose": {"frame": 3}, "edits": [{"point": [0.5, 0.5], "move": [0, 0, 1],
        "radius": "wide"}]}])",
     "r.json: patches[0].examples[0].edits[0].radius: error: expected a brush radius in 0.01..2 "
     "((u, v) units), found \"wide\""},
    {R"(, "examples": [{"pose": {"frame": 3}, "edits": [{"vertex": 4, "move": [0, 0, 1]}]},
                       {"pose": {"frame": 3}, "edits": [{"vertex": 5, "move": [0, 0, 1]}]}])",
     "r.json: patches[0].examples[1].pose: error: duplicates the pose of patches[0].examples[0] "
     "(one example per pose: merge their edits)"},
    {R"(, "pose_space": {"features": "quaternion"})",
     "r.json: patches[0].pose_space.features: error: expected one of \"euler\", \"rotvec\", "
     "\"swingtwist\", found \"quaternion\""},
    {R"(, "pose_space": {"kappa": 0})",
     "r.json: patches[0].pose_space.kappa: error: expected a number in 0.001..10, found 0"},
    {R"(, "pose_space": {"joints": []})",
     "r.json: patches[0].pose_space.joints: error: expected a non-empty array of joint names, "
     "found an array []"},
};

TEST(RigExamples, BadExamplesGiveExactMessages) {
  for (const BadExample& bad : kBadExamples) {
    const auto rig = app::ParseRig(ElbowRig(bad.extra), "r.json");
    ASSERT_FALSE(rig.ok()) << bad.extra;
    EXPECT_EQ(rig.error().ToString(), bad.message) << bad.extra;
  }
}

TEST(RigExamples, BuildErrorsNameTheFieldPath) {
  const auto f = LoadElbowFixture();
  ASSERT_TRUE(f.has_value());
  struct Case {
    std::string extra;
    std::string message;
  };
  const int inner = InteriorVertices(f->patches[0], 1).at(0);
  const std::vector<Case> cases = {
      {R"(, "examples": [{"pose": {"frame": 61}, "edits": [{"vertex": 1, "move": [0, 0, 1]}]}])",
       "r.json: patches[0].examples[0].pose.frame: error: expected a frame in 0..60 of the motion, "
       "found 61"},
      {R"(, "examples": [{"pose": {"joints": {"Elbow": [0, 9, 0]}}, "edits": [{"vertex": 1,
          "move": [0, 0, 1]}]}])",
       "r.json: patches[0].examples[0].pose.joints.Elbow: error: expected a joint of "},
      {R"(, "examples": [{"pose": {"frame": 30}, "edits": [{"vertex": 0, "move": [0, 0, 1]}]}])",
       "r.json: patches[0].examples[0].edits[0]: error: vertex 0 is not bound to this patch"},
      {R"(, "examples": [{"pose": {"frame": 30}, "edits": [{"vertex": 99999999, "move": [0, 0, 1]}]}])",
       "r.json: patches[0].examples[0].edits[0]: error: expected a vertex index below "},
      // Two poses 1e-5 degrees apart: below the RBF's duplicate tolerance.
      {R"(, "examples": [
          {"pose": {"joints": {"LeftForeArm": [0, -90, 0]}}, "edits": [{"vertex": )" +
           std::to_string(inner) + R"(, "move": [0, 0, 1]}]},
          {"pose": {"joints": {"LeftForeArm": [0, -90.00001, 0]}}, "edits": [{"vertex": )" +
           std::to_string(inner) + R"(, "move": [0, 0, 2]}]}])",
       "r.json: patches[0].examples[1].pose: error: example 'patches[0].examples[1]' (index 1) "
       "duplicates example 'patches[0].examples[0]' (index 0): their poses are "},
      {R"(, "examples": [{"pose": {"frame": 30}, "edits": [{"vertex": 1, "move": [0, 0, 1]}]}],
          "pose_space": {"joints": ["Hips2"]})",
       "r.json: patches[0].pose_space.joints[0]: error: expected a joint of "},
  };
  for (const Case& c : cases) {
    const auto rig = app::ParseRig(ElbowRig(c.extra), "r.json");
    ASSERT_TRUE(rig.ok()) << rig.error().ToString();
    const auto spaces =
        app::BuildRigPoseSpaces(*rig, f->character, f->patches, deform::GlobalMethod::kSsd);
    ASSERT_FALSE(spaces.ok()) << c.extra;
    EXPECT_EQ(spaces.error().ToString().rfind(c.message, 0), 0u)
        << spaces.error().ToString() << "\nexpected to start with\n" << c.message;
  }
}

// The requested moves land: at the example's pose the edited vertices (two,
// solved together) sit at (patches without examples) + move; at rest nothing
// changes; in between the change is continuous.
TEST(RigExamples, VertexEditsLandAtTheirExamplePoseAndNothingMovesAtRest) {
  const auto f = LoadElbowFixture();
  ASSERT_TRUE(f.has_value());
  const std::vector<int> v = InteriorVertices(f->patches[0], 2);
  ASSERT_EQ(v.size(), 2u);
  const glm::dvec3 move0(0.0, 0.0, 1.2), move1(0.3, -0.5, 0.4);
  const int frame = 45;
  const auto rig = app::ParseRig(
      ElbowRig(R"(, "examples": [{"pose": {"frame": )" + std::to_string(frame) +
               R"(}, "edits": [{"vertex": )" + std::to_string(v[0]) + R"(, "move": )" + Vec(move0) +
               R"(, "frame": "world"}, {"vertex": )" + std::to_string(v[1]) + R"(, "move": )" +
               Vec(move1) + R"(, "frame": "world"}]}])"),
      "r.json");
  ASSERT_TRUE(rig.ok()) << rig.error().ToString();
  auto plain = MakePipeline(*f, nullptr);
  auto sculpted = MakePipeline(*f, &*rig);
  ASSERT_TRUE(plain.ok()) << plain.error().ToString();
  ASSERT_TRUE(sculpted.ok()) << sculpted.error().ToString();
  const double tol = 1e-4 * f->patches[0].bound.report.patch_diagonal;
  const double t = frame * f->character.motion.frame_time_s;
  deform::DeformedFrame a, b;
  ASSERT_TRUE(plain->Evaluate(t, a).ok());
  ASSERT_TRUE(sculpted->Evaluate(t, b).ok());
  for (int k = 0; k < 2; ++k) {
    const auto i = static_cast<std::size_t>(v[static_cast<std::size_t>(k)]);
    const glm::dvec3 moved = glm::dvec3(b.positions[i]) - glm::dvec3(a.positions[i]);
    const glm::dvec3 want = k == 0 ? move0 : move1;
    EXPECT_LT(glm::length(moved - want), tol) << "vertex " << i << " moved " << Vec(moved);
  }
  // At rest (frame 0 of bend.bvh) dS = 0 up to the float round-off of the
  // RBF sum (its weights cancel there only in exact arithmetic).
  ASSERT_TRUE(plain->Evaluate(0.0, a).ok());
  ASSERT_TRUE(sculpted->Evaluate(0.0, b).ok());
  double worst = 0.0;
  for (std::size_t i = 0; i < a.positions.size(); ++i) {
    worst = std::max(worst, static_cast<double>(glm::length(b.positions[i] - a.positions[i])));
  }
  EXPECT_LT(worst, testsupport::kRestRoundoffRel * f->patches[0].bound.report.patch_diagonal);
}

// A bind-frame move turns with the forearm: for a vertex skinned to the
// forearm alone the world move is the forearm's rotation from bind to the
// example pose applied to it, computed here from the joint matrices.
TEST(RigExamples, BindFrameMoveTurnsWithTheLimb) {
  const auto f = LoadElbowFixture();
  ASSERT_TRUE(f.has_value());
  const app::Character& ch = f->character;
  const int forearm = ch.skeleton.FindJoint("LeftForeArm");
  int skin = -1;
  for (std::size_t s = 0; s < ch.mesh.skin_joints.size(); ++s) {
    if (ch.mesh.skin_joints[s] == forearm) skin = static_cast<int>(s);
  }
  ASSERT_GE(skin, 0);
  const deform::PatchSetup& p = f->patches[0];
  const int k = ch.mesh.weights.influences;
  int vertex = -1;
  for (std::size_t b = 0; b < p.bound.binding.size() && vertex < 0; ++b) {
    const int i = p.bound.binding.vertex[b];
    for (int j = 0; j < k; ++j) {
      const auto idx = static_cast<std::size_t>(i * k + j);
      if (ch.mesh.weights.joints[idx] == skin && ch.mesh.weights.weights[idx] == 1.0f &&
          p.border_weight[b] >= 1.0f) {
        vertex = i;
      }
    }
  }
  ASSERT_GE(vertex, 0) << "no vertex of the patch is skinned to the forearm alone";
  const glm::dvec3 move(0.0, 0.0, -0.8);  // bind frame: towards the back at the T-pose
  const int frame = 60;
  const auto rig = app::ParseRig(
      ElbowRig(R"(, "examples": [{"pose": {"frame": )" + std::to_string(frame) +
               R"(}, "edits": [{"vertex": )" + std::to_string(vertex) + R"(, "move": )" +
               Vec(move) + "}]}]"),
      "r.json");
  ASSERT_TRUE(rig.ok()) << rig.error().ToString();
  auto plain = MakePipeline(*f, nullptr);
  auto sculpted = MakePipeline(*f, &*rig);
  ASSERT_TRUE(plain.ok() && sculpted.ok());
  deform::DeformedFrame a, b;
  const double t = frame * ch.motion.frame_time_s;
  ASSERT_TRUE(plain->Evaluate(t, a).ok());
  ASSERT_TRUE(sculpted->Evaluate(t, b).ok());
  // Forearm rotation: model_from_joint at the pose times its inverse at bind.
  const auto nj = static_cast<std::size_t>(ch.skeleton.num_joints());
  std::vector<mocap::JointTransform> locals(nj);
  std::vector<glm::mat4> posed(nj), bind(nj);
  mocap::RestPose(ch.skeleton, locals);
  ASSERT_TRUE((mocap::LocalToModelJob{.parents = ch.skeleton.parents, .locals = locals,
                                      .model_from_joint = bind}.Run()));
  ASSERT_TRUE((mocap::LocalPoseJob{&ch.skeleton, ch.motion.frame(frame), locals}.Run()));
  ASSERT_TRUE((mocap::LocalToModelJob{.parents = ch.skeleton.parents, .locals = locals,
                                      .model_from_joint = posed}.Run()));
  const auto fj = static_cast<std::size_t>(forearm);
  const glm::dmat3 turn = glm::dmat3(glm::mat3(posed[fj])) * glm::inverse(glm::dmat3(glm::mat3(bind[fj])));
  const glm::dvec3 want = turn * move;
  const auto i = static_cast<std::size_t>(vertex);
  const glm::dvec3 moved = glm::dvec3(b.positions[i]) - glm::dvec3(a.positions[i]);
  EXPECT_LT(glm::length(moved - want), 1e-4 * p.bound.report.patch_diagonal)
      << "moved " << Vec(moved) << ", expected " << Vec(want);
  EXPECT_GT(glm::length(want - move), 0.5);  // the pose really turned it
}

// Two examples (frames 30 and 60): exact at both; between and around them the
// displacement of the edited vertex is continuous: halving the time step
// halves the largest change between neighbouring samples (a jump would not).
TEST(RigExamples, TwoExamplesAreExactAndContinuousBetween) {
  const auto f = LoadElbowFixture();
  ASSERT_TRUE(f.has_value());
  const int vertex = InteriorVertices(f->patches[0], 1).at(0);
  const glm::dvec3 m30(0.0, 0.0, 1.0), m60(0.0, 0.8, 0.0);
  const auto rig = app::ParseRig(
      ElbowRig(R"(, "examples": [
          {"pose": {"frame": 30}, "edits": [{"vertex": )" + std::to_string(vertex) +
               R"(, "move": )" + Vec(m30) + R"(, "frame": "world"}]},
          {"pose": {"frame": 60}, "edits": [{"vertex": )" + std::to_string(vertex) +
               R"(, "move": )" + Vec(m60) + R"(, "frame": "world"}]}])"),
      "r.json");
  ASSERT_TRUE(rig.ok()) << rig.error().ToString();
  auto plain = MakePipeline(*f, nullptr);
  auto sculpted = MakePipeline(*f, &*rig);
  ASSERT_TRUE(plain.ok() && sculpted.ok());
  const double dt = f->character.motion.frame_time_s;
  const auto i = static_cast<std::size_t>(vertex);
  deform::DeformedFrame a, b;
  auto offset = [&](double t) {
    EXPECT_TRUE(plain->Evaluate(t, a).ok());
    EXPECT_TRUE(sculpted->Evaluate(t, b).ok());
    return glm::dvec3(b.positions[i]) - glm::dvec3(a.positions[i]);
  };
  const double tol = 1e-4 * f->patches[0].bound.report.patch_diagonal;
  EXPECT_LT(glm::length(offset(30 * dt) - m30), tol);
  EXPECT_LT(glm::length(offset(60 * dt) - m60), tol);
  auto max_step = [&](int steps_per_frame) {
    double worst = 0.0;
    glm::dvec3 prev = offset(0.0);
    for (int s = 1; s <= 60 * steps_per_frame; ++s) {
      const glm::dvec3 cur = offset(s * dt / steps_per_frame);
      worst = std::max(worst, glm::length(cur - prev));
      prev = cur;
    }
    return worst;
  };
  const double coarse = max_step(2), fine = max_step(4);
  EXPECT_GT(coarse, 0.0);
  EXPECT_GT(coarse / fine, 1.6) << "coarse " << coarse << " fine " << fine;
  EXPECT_LT(coarse, 0.25 * glm::length(m30));
}

}  // namespace

namespace {

// The closed-form SSD control-point rotations (one or two bones) agree with
// the SVD polar decomposition of SsdControlRotations, at every pose of the
// bend.
TEST(RigExamples, ControlRotationsMatchThePolarDecomposition) {
  const auto f = LoadElbowFixture();
  ASSERT_TRUE(f.has_value());
  const app::Character& ch = f->character;
  const deform::PatchSetup& p = f->patches[0];
  const auto nj = static_cast<std::size_t>(ch.skeleton.num_joints());
  std::vector<mocap::JointTransform> locals(nj);
  std::vector<glm::mat4> model(nj), palette(ch.mesh.skin_joints.size());
  std::vector<glm::quat> fast(p.rest_control.size()), svd(p.rest_control.size());
  double worst = 0.0;
  for (int frame = 0; frame < ch.motion.num_frames; frame += 5) {
    ASSERT_TRUE((mocap::LocalPoseJob{&ch.skeleton, ch.motion.frame(frame), locals}.Run()));
    ASSERT_TRUE((mocap::LocalToModelJob{.parents = ch.skeleton.parents, .locals = locals,
                                        .model_from_joint = model}.Run()));
    ASSERT_TRUE(deform::BuildSkinningPalette(model, ch.mesh, palette));
    ASSERT_TRUE(deform::PatchControlRotations(p, {.model_from_bind = palette}, fast));
    const deform::SkinWeights& w = p.control_weights;
    ASSERT_TRUE(deform::SsdControlRotations(palette, w.influences, w.joints, w.weights, svd));
    for (std::size_t c = 0; c < fast.size(); ++c) {
      // Angle between the rotations ~ 2 |q1 - (+-q2)| (no acos: it amplifies round-off).
      const glm::quat sign = glm::dot(fast[c], svd[c]) < 0.0f ? -svd[c] : svd[c];
      const glm::quat diff = fast[c] - sign;
      worst = std::max(worst, 2.0 * static_cast<double>(glm::length(glm::vec4(diff.x, diff.y, diff.z, diff.w))));
    }
  }
  EXPECT_LT(worst, testsupport::kRotationTolRad);
}

}  // namespace

namespace {

// The shoulder demo's patch (samples/data/shoulder.json, 9x6, on the generated
// body with bone-heat weights): at least 30 of its 54 control points blend
// three bones, so PatchControlRotations takes Newton's
// polar iteration there. Against the SVD of each control point's blend, at
// every 5th frame of shoulder.bvh (arm raised and lowered).
TEST(RigExamples, ShoulderThreeBoneRotationsMatchTheSvd) {
  auto rig = app::LoadRig(testsupport::SampleDataPath("shoulder.json").string());
  ASSERT_TRUE(rig.ok()) << rig.error().ToString();
  auto source = app::LoadMotionSource(rig->motion, {.y_up = true});
  ASSERT_TRUE(source.ok()) << source.error().ToString();
  auto character = app::MakeCharacter(std::move(*source), {}, app::RigBodyKind(*rig));
  ASSERT_TRUE(character.ok()) << character.error().ToString();
  auto patches = app::BuildRigPatches(*rig, *character);
  ASSERT_TRUE(patches.ok()) << patches.error().ToString();
  const app::Character& ch = *character;
  const deform::PatchSetup& p = (*patches)[0];
  const deform::SkinWeights& w = p.control_weights;
  const auto k = static_cast<std::size_t>(w.influences);
  int three_bone = 0;
  for (std::size_t c = 0; c < p.rest_control.size(); ++c) {
    int bones = 0;
    for (std::size_t i = 0; i < k; ++i) bones += w.weights[c * k + i] != 0.0f;
    three_bone += bones >= 3;
  }
  EXPECT_GE(three_bone, 30);
  const auto nj = static_cast<std::size_t>(ch.skeleton.num_joints());
  std::vector<mocap::JointTransform> locals(nj);
  std::vector<glm::mat4> model(nj), palette(ch.mesh.skin_joints.size());
  std::vector<glm::quat> fast(p.rest_control.size());
  double worst = 0.0;
  for (int frame = 0; frame < ch.motion.num_frames; frame += 5) {
    ASSERT_TRUE((mocap::LocalPoseJob{&ch.skeleton, ch.motion.frame(frame), locals}.Run()));
    ASSERT_TRUE((mocap::LocalToModelJob{.parents = ch.skeleton.parents, .locals = locals,
                                        .model_from_joint = model}.Run()));
    ASSERT_TRUE(deform::BuildSkinningPalette(model, ch.mesh, palette));
    ASSERT_TRUE(deform::PatchControlRotations(p, {.model_from_bind = palette}, fast));
    for (std::size_t c = 0; c < fast.size(); ++c) {
      glm::dmat3 blend(0.0);
      for (std::size_t i = 0; i < k; ++i) {
        blend += static_cast<double>(w.weights[c * k + i]) *
                 glm::dmat3(glm::mat3(palette[w.joints[c * k + i]]));
      }
      const glm::quat svd(glm::quat_cast(deform::PolarRotationSvd(blend)));
      const glm::quat sign = glm::dot(fast[c], svd) < 0.0f ? -svd : svd;
      const glm::quat diff = fast[c] - sign;
      worst = std::max(worst, 2.0 * static_cast<double>(glm::length(glm::vec4(diff.x, diff.y, diff.z, diff.w))));
    }
  }
  EXPECT_LT(worst, testsupport::kRotationTolRad);
}

}  // namespace

namespace {

// Vertices that moved by more than `frac` x |move| between two frames.
int CountMoved(const deform::DeformedFrame& a, const deform::DeformedFrame& b, double threshold) {
  int n = 0;
  for (std::size_t i = 0; i < a.positions.size(); ++i) {
    if (glm::length(b.positions[i] - a.positions[i]) > threshold) ++n;
  }
  return n;
}

// A brush edit (issue 26) makes a shape, not a bump: at its example pose the
// surface point under the brush moves by the move, and many more skin
// vertices follow than with the same edit without a radius.
TEST(RigExamples, BrushEditMovesTheNeighbourhoodSmoothly) {
  auto f = LoadElbowFixture();
  ASSERT_TRUE(f.has_value());
  // A 10 x 10 grid: on the fixture's 6 x 6 every basis function already spans
  // a third of the patch, so a plain edit is as wide as a brush there.
  auto fine = [](std::string rig) {
    rig.replace(rig.find(R"("sampling": [8, 8], "grid": [6, 6])"), 34,
                R"("sampling": [14, 14], "grid": [10, 10])");
    return rig;
  };
  {
    auto rig = app::ParseRig(fine(ElbowRig("")), "r.json");
    ASSERT_TRUE(rig.ok()) << rig.error().ToString();
    auto patches = app::BuildRigPatches(*rig, f->character);
    ASSERT_TRUE(patches.ok()) << patches.error().ToString();
    f->patches = std::move(*patches);
  }
  const int frame = 45;
  const glm::dvec3 move(0.0, 0.0, 1.0);
  auto edit = [&](const std::string& radius) {
    return fine(ElbowRig(R"(, "examples": [{"pose": {"frame": )" + std::to_string(frame) +
                    R"(}, "edits": [{"point": [0.5, 0.5], "move": )" + Vec(move) +
                    R"(, "frame": "world")" + radius + "}]}]"));
  };
  const auto plain_rig = app::ParseRig(edit(""), "r.json");
  const auto brush_rig = app::ParseRig(edit(R"(, "radius": 0.8)"), "r.json");
  ASSERT_TRUE(plain_rig.ok()) << plain_rig.error().ToString();
  ASSERT_TRUE(brush_rig.ok()) << brush_rig.error().ToString();
  EXPECT_EQ(brush_rig->patches[0].examples[0].edits[0].radius, 0.8);
  auto none = MakePipeline(*f, nullptr);
  auto plain = MakePipeline(*f, &*plain_rig);
  auto brush = MakePipeline(*f, &*brush_rig);
  ASSERT_TRUE(none.ok() && plain.ok() && brush.ok());
  const double t = frame * f->character.motion.frame_time_s;
  deform::DeformedFrame a, b, c;
  ASSERT_TRUE(none->Evaluate(t, a).ok());
  ASSERT_TRUE(plain->Evaluate(t, b).ok());
  ASSERT_TRUE(brush->Evaluate(t, c).ok());
  double peak_plain = 0.0, peak_brush = 0.0;
  for (std::size_t i = 0; i < a.positions.size(); ++i) {
    peak_plain = std::max(peak_plain, static_cast<double>(glm::length(b.positions[i] - a.positions[i])));
    peak_brush = std::max(peak_brush, static_cast<double>(glm::length(c.positions[i] - a.positions[i])));
  }
  const int moved_plain = CountMoved(a, b, 0.25);
  const int moved_brush = CountMoved(a, c, 0.25);
  std::printf("vertices moved > 0.25 of the move: plain %d, brush %d; peak plain %.3f brush %.3f\n",
              moved_plain, moved_brush, peak_plain, peak_brush);
  EXPECT_GT(moved_brush, 2 * moved_plain);
  EXPECT_NEAR(peak_brush, 1.0, 0.1);  // the surface point moves by |move|; vertices near it too
}

}  // namespace
