#include "deform/shapes/pose_space.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "mocap/joint_angles.h"
#include "support/tolerances.h"

namespace {

using deform::PoseExample;
using deform::PoseSpaceJob;
using deform::RbfKernel;
using deform::RbfModel;
using deform::RbfOptions;
using deform::RbfPoseSpace;
using testsupport::kRbfExactTol;

constexpr int kControl = 12;  // #C of the synthetic examples
constexpr float kPi = std::numbers::pi_v<float>;

// Five well-spread example poses in a 3-feature space with random displacements.
std::vector<PoseExample> MakeExamples(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> disp(-1.0f, 1.0f);
  const std::vector<std::vector<float>> poses = {{0.9f, 0.1f, 0.0f},
                                                 {0.0f, 1.1f, 0.2f},
                                                 {-0.3f, 0.2f, 1.0f},
                                                 {0.8f, 0.9f, -0.4f},
                                                 {-1.0f, -0.5f, 0.3f}};
  std::vector<PoseExample> out;
  for (size_t e = 0; e < poses.size(); ++e) {
    PoseExample ex{.name = "pose" + std::to_string(e), .features = poses[e]};
    for (int c = 0; c < kControl; ++c)
      ex.displacement.emplace_back(disp(rng), disp(rng), disp(rng));
    out.push_back(ex);
  }
  return out;
}

std::vector<glm::vec3> Eval(const RbfModel& model, std::span<const float> x) {
  std::vector<glm::vec3> out(static_cast<size_t>(model.num_values / 3));
  const PoseSpaceJob job{.model = &model, .features = x, .displacement = out};
  EXPECT_TRUE(job.Run().ok());
  return out;
}

float MaxDiff(std::span<const glm::vec3> a, std::span<const glm::vec3> b) {
  float m = 0.0f;
  for (size_t i = 0; i < a.size(); ++i) m = std::max(m, glm::length(a[i] - b[i]));
  return m;
}

const RbfKernel kAllKernels[] = {RbfKernel::kGaussian, RbfKernel::kInverseMultiquadric,
                                 RbfKernel::kMultiquadric, RbfKernel::kPolyharmonic3};

TEST(RbfPoseSpace, ExactAtEveryExampleAndZeroAtRestForEveryKernel) {
  const std::vector<PoseExample> examples = MakeExamples(3);
  for (RbfKernel kernel : kAllKernels) {
    SCOPED_TRACE(deform::RbfKernelName(kernel));
    auto model = RbfPoseSpace::Fit(examples, 3, kControl, {.kernel = kernel});
    ASSERT_TRUE(model.ok()) << model.error().ToString();
    EXPECT_EQ(model->kernel, kernel);
    EXPECT_EQ(model->num_centres, 6);
    for (const PoseExample& ex : examples) {
      EXPECT_LT(MaxDiff(Eval(*model, ex.features), ex.displacement), kRbfExactTol);
    }
    const std::vector<float> rest(3, 0.0f);
    const std::vector<glm::vec3> zero(kControl, glm::vec3(0.0f));
    EXPECT_LT(MaxDiff(Eval(*model, rest), zero), kRbfExactTol);
  }
}

TEST(RbfPoseSpace, JobMatchesDoubleReference) {
  const std::vector<PoseExample> examples = MakeExamples(5);
  for (RbfKernel kernel : kAllKernels) {
    auto model = RbfPoseSpace::Fit(examples, 3, kControl, {.kernel = kernel});
    ASSERT_TRUE(model.ok());
    const std::vector<float> x = {0.3f, -0.2f, 0.45f};
    const std::vector<glm::vec3> job = Eval(*model, x);
    const std::vector<double> ref = model->EvaluateReference(x);
    for (int c = 0; c < kControl; ++c) {
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(job[static_cast<size_t>(c)][k], ref[static_cast<size_t>(3 * c + k)],
                    kRbfExactTol);
      }
    }
  }
}

// Continuity: along a path between two examples, the largest jump between
// consecutive samples halves when the step halves (Lipschitz, no jumps).
TEST(RbfPoseSpace, ContinuousBetweenExamples) {
  const std::vector<PoseExample> examples = MakeExamples(7);
  for (RbfKernel kernel : kAllKernels) {
    SCOPED_TRACE(deform::RbfKernelName(kernel));
    auto model = RbfPoseSpace::Fit(examples, 3, kControl, {.kernel = kernel});
    ASSERT_TRUE(model.ok());
    auto max_jump = [&](int steps) {
      float jump = 0.0f;
      std::vector<glm::vec3> prev;
      for (int s = 0; s <= steps; ++s) {
        const float t = static_cast<float>(s) / static_cast<float>(steps);
        std::vector<float> x(3);
        for (size_t d = 0; d < 3; ++d)
          x[d] = (1 - t) * examples[0].features[d] + t * examples[3].features[d];
        std::vector<glm::vec3> cur = Eval(*model, x);
        if (!prev.empty()) jump = std::max(jump, MaxDiff(cur, prev));
        prev = std::move(cur);
      }
      return jump;
    };
    const float coarse = max_jump(200), fine = max_jump(400);
    EXPECT_GT(coarse, 0.0f);
    EXPECT_LT(coarse, 0.1f);  // 200 steps over a change of order 1
    EXPECT_NEAR(fine / coarse, 0.5f, 0.1f);
  }
}

TEST(RbfPoseSpace, OneExampleRisesSmoothlyFromRest) {
  PoseExample ex{.name = "bent", .features = {0.8f, 0.0f, 0.0f}};
  ex.displacement.assign(kControl, glm::vec3(0.0f, 0.0f, 0.5f));
  auto model = RbfPoseSpace::Fit(std::span(&ex, 1), 3, kControl);
  ASSERT_TRUE(model.ok());
  EXPECT_EQ(model->num_centres, 2);
  float prev = -1.0f;
  for (int s = 0; s <= 40; ++s) {
    const float t = static_cast<float>(s) / 40.0f;
    const std::vector<float> x = {0.8f * t, 0.0f, 0.0f};
    const float z = Eval(*model, x)[0].z;
    EXPECT_GT(z, prev);  // strictly rising from rest to the example
    prev = z;
  }
  EXPECT_NEAR(Eval(*model, std::vector<float>{0, 0, 0})[0].z, 0.0f, kRbfExactTol);
  EXPECT_NEAR(prev, 0.5f, kRbfExactTol);
}

TEST(RbfPoseSpace, RestOnlyGivesZero) {
  auto model = RbfPoseSpace::Fit({}, 2, kControl);
  ASSERT_TRUE(model.ok());
  EXPECT_EQ(model->num_centres, 1);
  const std::vector<glm::vec3> out = Eval(*model, std::vector<float>{0.5f, -1.0f});
  EXPECT_EQ(MaxDiff(out, std::vector<glm::vec3>(kControl, glm::vec3(0.0f))), 0.0f);
}

TEST(RbfPoseSpace, DuplicateRejectedNamingBoth) {
  std::vector<PoseExample> examples = MakeExamples(1);
  examples[3].features = examples[1].features;
  examples[3].features[2] += 5e-5f;
  examples[3].name = "elbow_again";
  examples[3].loc.file = "rig.json";
  examples[3].loc.line = 14;
  auto model = RbfPoseSpace::Fit(examples, 3, kControl);
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(model.error().code, base::ErrorCode::kInvalidArgument);
  const std::string msg = model.error().ToString();
  EXPECT_NE(msg.find("rig.json:14"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'elbow_again' (index 3)"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'pose1' (index 1)"), std::string::npos) << msg;
}

TEST(RbfPoseSpace, EditNearAnExampleUpdatesIt) {
  std::vector<PoseExample> examples = MakeExamples(6);
  PoseExample edit{.name = "again", .features = examples[2].features};
  edit.features[0] += 2e-5f;
  edit.displacement.assign(kControl, glm::vec3(0.25f));
  EXPECT_EQ(deform::AddOrUpdateExample(examples, edit), 2);
  EXPECT_EQ(examples.size(), 5u);
  EXPECT_EQ(examples[2].displacement[0], glm::vec3(0.25f));
  edit.features[0] += 0.5f;
  EXPECT_EQ(deform::AddOrUpdateExample(examples, edit), 5);
  auto model = RbfPoseSpace::Fit(examples, 3, kControl);
  ASSERT_TRUE(model.ok());
  EXPECT_LT(MaxDiff(Eval(*model, examples[2].features), examples[2].displacement), kRbfExactTol);
}

TEST(RbfPoseSpace, ConditionNumberReportedAndGrowsWithWidth) {
  const std::vector<PoseExample> examples = MakeExamples(2);
  double prev = 0.0;
  for (double kappa : {0.5, 1.0, 2.0, 4.0}) {
    auto model = RbfPoseSpace::Fit(examples, 3, kControl, {.kappa = kappa});
    ASSERT_TRUE(model.ok());
    EXPECT_GE(model->condition, 1.0);
    EXPECT_GT(model->condition, prev) << "kappa " << kappa;
    RecordProperty("condition_kappa_" + std::to_string(kappa), std::to_string(model->condition));
    prev = model->condition;
  }
  // Above the warning threshold (lowered here; the default is 1e10) a warning is added.
  auto wide = RbfPoseSpace::Fit(examples, 3, kControl, {.kappa = 60.0, .warn_condition = 1e6});
  ASSERT_TRUE(wide.ok());
  EXPECT_GT(wide->condition, 1e6);
  ASSERT_FALSE(wide->warnings.empty());
  EXPECT_NE(wide->warnings[0].message.find("ill-conditioned"), std::string::npos);
}

TEST(RbfPoseSpace, PolyharmonicFallsBackWithTooFewPoses) {
  std::vector<PoseExample> examples = MakeExamples(4);
  examples.resize(1);
  auto model = RbfPoseSpace::Fit(examples, 3, kControl, {.kernel = RbfKernel::kPolyharmonic3});
  ASSERT_TRUE(model.ok());
  EXPECT_EQ(model->kernel, RbfKernel::kGaussian);
  EXPECT_FALSE(model->warnings.empty());
  EXPECT_LT(MaxDiff(Eval(*model, examples[0].features), examples[0].displacement), kRbfExactTol);
}

TEST(RbfPoseSpace, RejectsBadInput) {
  std::vector<PoseExample> examples = MakeExamples(4);
  examples[2].features.pop_back();
  EXPECT_FALSE(RbfPoseSpace::Fit(examples, 3, kControl).ok());
  examples = MakeExamples(4);
  examples[1].displacement[0].x = std::nanf("");
  EXPECT_FALSE(RbfPoseSpace::Fit(examples, 3, kControl).ok());
  EXPECT_FALSE(RbfPoseSpace::Fit(MakeExamples(4), 3, kControl, {.kappa = 0.0}).ok());
  EXPECT_FALSE(RbfPoseSpace::Fit(MakeExamples(4), 0, kControl).ok());
}

TEST(PoseSpaceJob, Validity) {
  auto model = RbfPoseSpace::Fit(MakeExamples(4), 3, kControl);
  ASSERT_TRUE(model.ok());
  std::vector<glm::vec3> out(kControl);
  std::vector<float> x(3, 0.0f), short_x(2, 0.0f);
  EXPECT_EQ((PoseSpaceJob{.features = x, .displacement = out}.Validate().code),
            base::JobStatus::kMissingInput);
  EXPECT_EQ(
      (PoseSpaceJob{.model = &*model, .features = short_x, .displacement = out}.Validate().code),
      base::JobStatus::kSizeMismatch);
  EXPECT_EQ((PoseSpaceJob{
                .model = &*model, .features = x, .displacement = std::span(out).first(kControl - 1)}
                 .Validate()
                 .code),
            base::JobStatus::kSizeMismatch);
  EXPECT_TRUE((PoseSpaceJob{.model = &*model, .features = x, .displacement = out}.Validate().ok()));
}

// The job sums each value over the centres in centre order, from 0: the
// same float operations as the definition written out below (Gaussian
// kernel, no wrapping), so the same bits, for #C whose 3#C values fill the
// job's blocks of 8 exactly or leave a tail.
TEST(PoseSpaceJob, SumsEveryValueOverTheCentresInOrder) {
  for (int num_control : {1, 3, 5, 8, 12}) {
    std::mt19937 rng(static_cast<unsigned>(num_control));
    std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
    std::vector<PoseExample> examples = MakeExamples(7);
    for (PoseExample& e : examples) {
      e.displacement.resize(static_cast<size_t>(num_control));
      for (glm::vec3& d : e.displacement) d = glm::vec3(uni(rng), uni(rng), uni(rng));
    }
    auto model = RbfPoseSpace::Fit(examples, 3, num_control);
    ASSERT_TRUE(model.ok()) << model.error().ToString();
    const float x[3] = {0.31f, -0.42f, 0.77f};
    const std::vector<glm::vec3> out = Eval(*model, x);
    const auto k = static_cast<size_t>(model->num_centres), nv = static_cast<size_t>(model->num_values);
    std::vector<float> phi(k);
    for (size_t c = 0; c < k; ++c) {
      float r2 = 0.0f;
      for (size_t d = 0; d < 3; ++d) {
        const float delta = x[d] - model->centres[c * 3 + d];
        r2 += delta * delta;
      }
      const float q = std::sqrt(r2) / model->width;
      phi[c] = std::exp(-q * q);
    }
    for (size_t v = 0; v < nv; ++v) {
      float expected = 0.0f;
      for (size_t c = 0; c < k; ++c) expected += phi[c] * model->weights[c * nv + v];
      EXPECT_EQ(out[v / 3][static_cast<int>(v % 3)], expected) << num_control << " " << v;
    }
  }
}

// A root plus an "elbow" with ZXY channels and a non-identity rest rotation.
mocap::Skeleton ElbowSkeleton() {
  mocap::Skeleton s;
  s.names = {"root", "elbow"};
  s.parents = {mocap::kNoParent, 0};
  s.rest_translations = {glm::vec3(0.0f), glm::vec3(0.0f, 1.0f, 0.0f)};
  s.rest_rotations = {glm::quat(1, 0, 0, 0),
                      glm::angleAxis(0.3f, glm::normalize(glm::vec3(1, 2, 0)))};
  s.rest_scales = {glm::vec3(1.0f), glm::vec3(1.0f)};
  s.channels.resize(2);
  s.channels[1].first = 0;
  s.channels[1].count = 3;
  s.channels[1].types = {mocap::ChannelType::kZRotation, mocap::ChannelType::kXRotation,
                         mocap::ChannelType::kYRotation};
  s.num_channels = 3;
  return s;
}

std::vector<float> Features(const mocap::Skeleton& s, const deform::PoseFeatureSpec& spec,
                            const glm::quat& local) {
  std::vector<mocap::JointTransform> locals(2);
  mocap::RestPose(s, locals);
  locals[1].rotation = local;
  std::vector<float> out(static_cast<size_t>(deform::PoseFeatureDimension(s, spec)));
  EXPECT_TRUE(deform::ComputePoseFeatures(s, spec, locals, out).ok());
  return out;
}

TEST(PoseFeatures, RotationVectorDistanceIsGeodesicAngle) {
  const mocap::Skeleton s = ElbowSkeleton();
  const deform::PoseFeatureSpec spec{.kind = deform::PoseFeatureKind::kRotationVector,
                                     .joints = {{.joint = 1}}};
  ASSERT_TRUE(deform::CheckPoseFeatureSpec(s, spec).ok());
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> uni(-1.0f, 1.0f), ang(0.0f, 3.0f);
  const glm::quat rest = s.rest_rotations[1];
  const std::vector<float> zero(3, 0.0f);
  EXPECT_LT(deform::PoseDistance(Features(s, spec, rest), zero, false), kRbfExactTol);
  for (int t = 0; t < 50; ++t) {
    const glm::vec3 axis =
        glm::normalize(glm::vec3(uni(rng), uni(rng), uni(rng)) + glm::vec3(0, 0, 2));
    const float a = ang(rng), b = ang(rng);
    // Distance to rest: the geodesic angle between rest and pose.
    const glm::quat pose = rest * glm::angleAxis(a, axis);
    EXPECT_NEAR(deform::PoseDistance(Features(s, spec, pose), zero, false), a, kRbfExactTol);
    // Two poses about one axis (relative to rest): the angle between them.
    const glm::quat other = rest * glm::angleAxis(b, axis);
    EXPECT_NEAR(deform::PoseDistance(Features(s, spec, pose), Features(s, spec, other), false),
                std::abs(a - b), kRbfExactTol);
  }
}

TEST(PoseFeatures, EulerDistanceWraps) {
  const mocap::Skeleton s = ElbowSkeleton();
  const deform::PoseFeatureSpec spec{.kind = deform::PoseFeatureKind::kEuler,
                                     .joints = {{.joint = 1}}};
  ASSERT_EQ(deform::PoseFeatureDimension(s, spec), 3);
  const glm::quat rest = s.rest_rotations[1];
  const float deg = kPi / 180.0f;
  const std::vector<float> a =
      Features(s, spec, rest * glm::angleAxis(170.0f * deg, glm::vec3(0, 0, 1)));
  const std::vector<float> b =
      Features(s, spec, rest * glm::angleAxis(-170.0f * deg, glm::vec3(0, 0, 1)));
  EXPECT_NEAR(a[0], 170.0f * deg, kRbfExactTol);  // Z is the first channel
  EXPECT_NEAR(b[0], -170.0f * deg, kRbfExactTol);
  EXPECT_NEAR(deform::PoseDistance(a, b, true), 20.0f * deg, kRbfExactTol);
  EXPECT_NEAR(deform::PoseDistance(a, b, false), 340.0f * deg, kRbfExactTol);
}

TEST(PoseFeatures, SwingTwistSeparatesRollFromFlexion) {
  const mocap::Skeleton s = ElbowSkeleton();
  const deform::PoseFeatureSpec spec{
      .kind = deform::PoseFeatureKind::kSwingTwist,
      .joints = {
          {.joint = 1, .twist_axis = glm::vec3(0, 1, 0), .swing_gain = 1.0f, .twist_gain = 0.5f}}};
  ASSERT_TRUE(deform::CheckPoseFeatureSpec(s, spec).ok());
  const glm::quat rest = s.rest_rotations[1];
  const std::vector<float> twist =
      Features(s, spec, rest * glm::angleAxis(0.6f, glm::vec3(0, 1, 0)));
  EXPECT_NEAR(twist[2], 0.3f, kRbfExactTol);  // twist_gain x angle
  EXPECT_NEAR(std::hypot(twist[0], twist[1]), 0.0f, kRbfExactTol);
  const std::vector<float> bend =
      Features(s, spec, rest * glm::angleAxis(0.6f, glm::vec3(1, 0, 0)));
  EXPECT_NEAR(std::hypot(bend[0], bend[1]), 0.6f, kRbfExactTol);
  EXPECT_NEAR(bend[2], 0.0f, kRbfExactTol);
}

TEST(PoseFeatures, SpecChecks) {
  const mocap::Skeleton s = ElbowSkeleton();
  EXPECT_FALSE(deform::CheckPoseFeatureSpec(s, {.joints = {{.joint = 0}}}).ok());  // root
  EXPECT_FALSE(deform::CheckPoseFeatureSpec(s, {.joints = {{.joint = 5}}}).ok());
  EXPECT_FALSE(deform::CheckPoseFeatureSpec(s, {.joints = {{.joint = 1}, {.joint = 1}}}).ok());
  EXPECT_FALSE(deform::CheckPoseFeatureSpec(s, {.joints = {{.joint = 1, .weight = 0.0f}}}).ok());
  EXPECT_TRUE(deform::CheckPoseFeatureSpec(s, {.joints = {{.joint = 1, .weight = 2.0f}}}).ok());
}

TEST(PoseFeatures, InfluencingJointsSkipRootsAndLightWeights) {
  const mocap::Skeleton s = ElbowSkeleton();
  const std::vector<int> skin_joints = {1, 0};  // skin joint 0 -> elbow, 1 -> root
  const std::vector<std::uint16_t> joints = {0, 1, 1, 0};
  const std::vector<float> weights = {0.6f, 0.4f, 1.0f, 0.0f};
  const auto found = deform::InfluencingJoints(s, skin_joints, 2, joints, weights);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].joint, 1);
  const std::vector<float> light = {0.0f, 1.0f, 1.0f, 0.0f};
  EXPECT_TRUE(deform::InfluencingJoints(s, skin_joints, 2, joints, light).empty());
}

TEST(PoseFeatures, FromMotionFrame) {
  const mocap::Skeleton s = ElbowSkeleton();
  mocap::Motion motion{.num_frames = 2, .num_channels = 3, .values = {0, 0, 0, 30, 0, 0}};
  const deform::PoseFeatureSpec spec{.joints = {{.joint = 1}}};
  auto f0 = deform::PoseFeaturesAtFrame(s, motion, 0, spec);
  auto f1 = deform::PoseFeaturesAtFrame(s, motion, 1, spec);
  ASSERT_TRUE(f0.ok() && f1.ok());
  EXPECT_LT(deform::PoseDistance(*f0, std::vector<float>(3, 0.0f), false), kRbfExactTol);
  EXPECT_NEAR(deform::PoseDistance(*f1, std::vector<float>(3, 0.0f), false), 30.0f * kPi / 180.0f,
              kRbfExactTol);
  EXPECT_FALSE(deform::PoseFeaturesAtFrame(s, motion, 2, spec).ok());
}

}  // namespace
