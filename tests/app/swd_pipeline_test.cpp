// `--global swd` through FramePipeline on every BVH of ../shared/data (skipped when
// absent) and on the synthetic humanoid (deterministic for any thread count, finite; the
// walk does not tear, nor do the captures: largest edge growth under 3% of the body size,
// printed too); the mannequin of every such BVH
// is closed and its weights are valid; `patchskin inspect --artifacts` prints the figures.

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "app/motion_source.h"
#include "app/character.h"
#include "deform/pipeline/frame_pipeline.h"
#include "deform/global/skinning_job.h"
#include "deform/global/swd_rig.h"
#include "tools/synthetic.h"
#include "support/body_checks.h"
#include "support/data_paths.h"
#include "support/tolerances.h"

namespace {

namespace fs = std::filesystem;

// Every shared capture with its bound on the largest edge growth (fraction of the body
// size). Before the binding fixes (chain ends compete with far roots; a branch part never
// takes its trunk as nearest chain; the seam fade and the trunk binding look only at the
// trunk bones at the branch point) the figures were 0.015-0.017 (CMU), 0.06-0.09
// (LAFAN), 0.12-0.16 (Bandai walk), 0.70-0.87 (Bandai run), 0.31-0.51 (mocapbank). Three
// defects then kept LAFAN's Geno_bind at 0.035, Bandai's run at 0.11 and mocapbank at
// 0.19: the seam fade pulled LAFAN's raised upper arm onto the neck it lies against;
// the run was bound at its rest pose, which lies flat (its height counted the
// positioning root on the floor, so it did not look lower than the first frame); and
// mocapbank's spine ran on into an arm whose collar starts at the neck's point. Now
// the spine skips mirror pairs, the run is bound at frame 0, and each mannequin tube is
// bound to the chain it was made on without a seam fade (figures 0.012-0.015).
struct SharedCapture {
  const char* file;
  float max_growth;
};
const SharedCapture kSharedBvh[] = {
    {"bvh/cmu_cgspeed/01_01.bvh", testsupport::kSwdCaptureMaxEdgeGrowthFraction},
    {"bvh/cmu_cgspeed/01_03.bvh", testsupport::kSwdCaptureMaxEdgeGrowthFraction},
    {"bvh/bandai_namco/dataset-1_walk_normal_001.bvh", testsupport::kSwdCaptureMaxEdgeGrowthFraction},
    {"bvh/lafan1_resolved/Geno_stance.bvh", testsupport::kSwdCaptureMaxEdgeGrowthFraction},
    {"bvh/bvh_python/test_freebvh.bvh", testsupport::kSwdCaptureMaxEdgeGrowthFraction},
    {"bvh/lafan1_resolved/Geno_bind.bvh", testsupport::kSwdCaptureMaxEdgeGrowthFraction},
    {"bvh/bandai_namco/dataset-2_run_active_034.bvh", testsupport::kSwdCaptureMaxEdgeGrowthFraction},
    {"bvh/bvh_python/test_mocapbank.bvh", testsupport::kSwdCaptureMaxEdgeGrowthFraction},
};

// Every edge in exactly two triangles.
void ExpectClosed(const deform::Mesh& m, const std::string& what) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
  for (const glm::uvec3& t : m.triangles) {
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = t[e], b = t[(e + 1) % 3];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  }
  int bad = 0;
  for (const auto& [edge, n] : uses) bad += n != 2 ? 1 : 0;
  EXPECT_EQ(bad, 0) << what << ": edges not shared by exactly two triangles";
}

// max_growth: bound on testsupport::MaxEdgeGrowthFraction at the first, middle and last frame (0:
// print only).
void CheckCharacter(const app::Character& c, const std::string& what, float max_growth) {
  {  // At the bind pose the rig rebuilds the mesh (ALGORITHMS.md 2.3).
    auto bind = deform::BindModelFromJoint(c);
    ASSERT_TRUE(bind.ok());
    auto rig = deform::BuildSwdRig(c.skeleton, *bind, c.mesh.bind,
                                   {.vertex_chains = c.mesh.body_chain_coords});
    ASSERT_TRUE(rig.ok()) << rig.error().ToString();
    std::vector<glm::quat> rot(bind->size());
    std::vector<glm::vec3> joints(bind->size());
    std::vector<glm::vec3> pos(c.mesh.bind.positions.size());
    ASSERT_TRUE((deform::SwdRigJob{.rig = &*rig, .model_from_joint = *bind, .vertex_begin = 0,
                                   .joint_rotations = rot, .joint_positions = joints,
                                   .keep_volume = false, .positions = pos, .normals = {}}
                     .Run()));
    float err = 0.0f;
    for (std::size_t v = 0; v < pos.size(); ++v) {
      err = std::max(err, glm::distance(pos[v], c.mesh.bind.positions[v]));
    }
    const glm::vec3 e = deform::ComputeBounds(c.mesh.bind.positions).size();
    EXPECT_LT(err / std::max({e.x, e.y, e.z}), testsupport::kSwdRebuildRelTol) << what;
  }
  ExpectClosed(c.mesh.bind, what);
  const base::Status w = deform::CheckSkinWeights(
      c.mesh.weights, static_cast<int>(c.mesh.skin_joints.size()), c.mesh.bind.num_vertices());
  EXPECT_TRUE(w.ok()) << what << ": " << w.error().ToString();
  auto one = deform::FramePipeline::Create(c, deform::GlobalMethod::kSwd, 1);
  ASSERT_TRUE(one.ok()) << what << ": " << one.error().ToString();
  auto two = deform::FramePipeline::Create(c, deform::GlobalMethod::kSwd, 2);
  ASSERT_TRUE(two.ok());
  deform::DeformedFrame a, b;
  const double duration = c.motion.duration_s();
  for (double t : {0.0, 0.5 * duration, duration}) {
    ASSERT_TRUE(one->Evaluate(t, a).ok());
    ASSERT_TRUE(two->Evaluate(t, b).ok());
    ASSERT_EQ(a.positions.size(), b.positions.size());
    EXPECT_EQ(0, std::memcmp(a.positions.data(), b.positions.data(),
                             a.positions.size() * sizeof(glm::vec3)))
        << what << ": thread count changed the result at t = " << t;
    for (const glm::vec3& p : a.positions) {
      ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) << what;
    }
    // No tearing: no edge of the closed body gets much longer (shoulders, hips).
    const float growth = testsupport::MaxEdgeGrowthFraction(c.mesh.bind, a.positions);
    std::printf("%s t = %.2f s: largest edge growth %.4f of the body size\n", what.c_str(), t, growth);
    if (max_growth > 0.0f) {
      EXPECT_LT(growth, max_growth) << what << " at t = " << t;
    }
  }
}

TEST(SwdPipeline, EveryBvhOfTheSharedData) {
  for (const SharedCapture& capture : kSharedBvh) {
    const char* rel = capture.file;
    const fs::path path = testsupport::SharedDataPath(rel);
    PATCHSKIN_REQUIRE_SHARED_FILE(path);
    app::MotionSourceOptions load;
    load.y_up = true;
    auto src = app::LoadMotionSource(path.string(), load);
    ASSERT_TRUE(src.ok()) << src.error().ToString();
    auto c = app::MakeCharacter(std::move(*src));
    ASSERT_TRUE(c.ok()) << c.error().ToString();
    CheckCharacter(*c, rel, capture.max_growth);
  }
}

TEST(SwdPipeline, SyntheticHumanoidWalkAndBend) {
  for (int which = 0; which < 2; ++which) {
    app::MotionSource src;
    src.format = "bvh";
    src.skeleton = synthetic::MakeHumanoidSkeleton();
    auto motion = which == 0 ? synthetic::MakeWalkMotion(src.skeleton)
                             : synthetic::MakeBendRamp(src.skeleton);
    ASSERT_TRUE(motion.ok());
    src.motion = std::move(*motion);
    auto c = app::MakeCharacter(std::move(src));
    ASSERT_TRUE(c.ok());
        // The bend ramp's growth is printed only: at 150 degrees the outer elbow and knee
    // stretch by design (SwdRig.BentElbowsAndKneesDoNotTear checks 120 degrees).
    CheckCharacter(*c, which == 0 ? "walk" : "bend ramp",
                   which == 0 ? testsupport::kSwdMaxEdgeGrowthFraction : 0.0f);
  }
}

std::string RunPatchskin(const std::string& args, int* exit_code) {
  const fs::path out = testsupport::TestOutputPath("swd_pipeline/stdout.txt");
  const std::string cmd = std::string("'") + PATCHSKIN_BINARY + "' " + args + " >'" +
                          out.string() + "' 2>&1";
  const int status = std::system(cmd.c_str());
  *exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(out);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(SwdPipeline, InspectPrintsArtifactFigures) {
  const fs::path path = testsupport::SharedDataPath("bvh/cmu_cgspeed/01_01.bvh");
  PATCHSKIN_REQUIRE_SHARED_FILE(path);
  int code = -1;
  const std::string out = RunPatchskin("inspect --artifacts '" + path.string() + "'", &code);
  EXPECT_EQ(code, 0) << out;
  EXPECT_NE(out.find("bend 150"), std::string::npos) << out;
  EXPECT_NE(out.find("twist 180"), std::string::npos) << out;
  EXPECT_NE(out.find("SWD"), std::string::npos) << out;
  // CMU's clavicle (3.58) is longer than its forearm (3.48): the elbow is still found,
  // and the twisted wrist is LeftHand, not the zero-length LeftFingerBase under it.
  for (const char* line : {"arm      LeftForeArm              bend 150",
                           "arm      RightForeArm             bend 150",
                           "leg      LeftLeg                  bend 150",
                           "arm      LeftHand                 twist 180"}) {
    EXPECT_NE(out.find(line), std::string::npos) << line << "\n" << out;
  }
  EXPECT_EQ(out.find("LeftArm "), std::string::npos) << out;
}

}  // namespace
