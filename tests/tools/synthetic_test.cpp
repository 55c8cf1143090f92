#include "tools/synthetic.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "mocap/joint_angles.h"
#include "mocap/kinematics.h"
#include "support/tolerances.h"

namespace {

// Model-space joint positions of every frame (#F x #J).
std::vector<glm::vec3> Positions(const mocap::Skeleton& s, const mocap::Motion& m) {
  std::vector<mocap::JointTransform> locals(static_cast<std::size_t>(s.num_joints()));
  std::vector<glm::mat4> model(static_cast<std::size_t>(m.num_frames * s.num_joints()));
  EXPECT_TRUE((mocap::ModelMatricesJob{
                   .skeleton = &s, .motion = &m, .locals = locals, .model_from_joint = model})
                  .Run()
                  .ok());
  std::vector<glm::vec3> p(model.size());
  for (std::size_t i = 0; i < model.size(); ++i) p[i] = glm::vec3(model[i][3]);
  return p;
}

struct Probe {
  const mocap::Skeleton& s;
  std::vector<glm::vec3> p;
  glm::vec3 At(int f, const char* name) const {
    const int j = s.FindJoint(name);
    EXPECT_GE(j, 0) << name;
    return p[static_cast<std::size_t>(f * s.num_joints() + j)];
  }
};

// Angle (degrees) at joint b between the bones a->b and b->c: 0 when straight.
float BendDeg(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  const float d = glm::dot(glm::normalize(b - a), glm::normalize(c - b));
  return glm::degrees(std::acos(std::clamp(d, -1.0f, 1.0f)));
}

void ExpectWellFormed(const mocap::Skeleton& s, const mocap::Motion& m) {
  EXPECT_EQ(m.num_channels, s.num_channels);
  EXPECT_EQ(m.values.size(), static_cast<std::size_t>(m.num_frames * m.num_channels));
  for (float v : m.values) ASSERT_TRUE(std::isfinite(v));
}

// Lowest foot point (ankle or toe) of each side must touch y = 0 within this.
float LowestFootY(const Probe& pr, int f, const char* side) {
  const std::string s(side);
  return std::min(pr.At(f, (s + "Foot").c_str()).y - 7.0f,
                  pr.At(f, (s + "ToeBase").c_str()).y - 1.0f);
}

TEST(Synthetic, HumanoidSkeletonLooksLikeACapture) {
  const mocap::Skeleton s = synthetic::MakeHumanoidSkeleton();
  ASSERT_TRUE(s.Check().ok());
  EXPECT_EQ(s.num_joints(), 24);
  EXPECT_EQ(s.num_channels, 6 + 23 * 3);
  for (const char* name :
       {"Hips",        "Spine",         "Spine1",      "Neck",         "Head",      "LeftShoulder",
        "LeftArm",     "LeftForeArm",   "LeftHand",    "LeftUpLeg",    "LeftLeg",   "LeftFoot",
        "LeftToeBase", "RightShoulder", "RightArm",    "RightForeArm", "RightHand", "RightUpLeg",
        "RightLeg",    "RightFoot",     "RightToeBase"}) {
    EXPECT_GE(s.FindJoint(name), 0) << name;
  }
  EXPECT_EQ(s.channels[0].count, 6);
  EXPECT_EQ(s.channels[1].types[0], mocap::ChannelType::kZRotation);
  EXPECT_EQ(s.channels[1].types[1], mocap::ChannelType::kXRotation);
  EXPECT_EQ(s.channels[1].types[2], mocap::ChannelType::kYRotation);
  mocap::Motion rest;
  rest.num_frames = 1;
  rest.num_channels = s.num_channels;
  rest.values.assign(static_cast<std::size_t>(s.num_channels), 0.0f);
  rest.values[1] = s.rest_translations[0].y;
  const Probe pr{s, Positions(s, rest)};
  // T-pose: arms horizontal, left on +X; toes on the ground.
  EXPECT_NEAR(pr.At(0, "LeftHand").y, pr.At(0, "LeftArm").y, testsupport::kPositionTol);
  EXPECT_GT(pr.At(0, "LeftHand").x, 60.0f);
  EXPECT_LT(pr.At(0, "RightHand").x, -60.0f);
  EXPECT_NEAR(LowestFootY(pr, 0, "Left"), 0.0f, testsupport::kPositionTol);
  EXPECT_GT(pr.At(0, "Head").y, 150.0f);
}

TEST(Synthetic, WalkKeepsFeetOnTheGroundAndMovesForward) {
  const mocap::Skeleton s = synthetic::MakeHumanoidSkeleton();
  auto m = synthetic::MakeWalkMotion(s);
  ASSERT_TRUE(m.ok()) << m.error().ToString();
  ExpectWellFormed(s, *m);
  EXPECT_EQ(m->num_frames, 90);
  const Probe pr{s, Positions(s, *m)};
  float max_knee = 0.0f;
  float max_elbow = 0.0f;
  for (int f = 0; f < m->num_frames; ++f) {
    const float lowest = std::min(LowestFootY(pr, f, "Left"), LowestFootY(pr, f, "Right"));
    EXPECT_NEAR(lowest, 0.0f, testsupport::kGroundContactTolCm) << "frame " << f;
    EXPECT_GE(LowestFootY(pr, f, "Left"), -testsupport::kGroundContactTolCm);
    if (f > 0) {
      EXPECT_GT(pr.At(f, "Hips").z, pr.At(f - 1, "Hips").z);
    }
    max_knee = std::max(max_knee,
                        BendDeg(pr.At(f, "LeftUpLeg"), pr.At(f, "LeftLeg"), pr.At(f, "LeftFoot")));
    max_elbow = std::max(
        max_elbow, BendDeg(pr.At(f, "LeftArm"), pr.At(f, "LeftForeArm"), pr.At(f, "LeftHand")));
    // Hands stay outside the torso: lateral distance from the spine > 15 cm.
    for (const char* hand : {"LeftHand", "RightHand"}) {
      const glm::vec3 d = pr.At(f, hand) - pr.At(f, "Spine1");
      EXPECT_GT(std::hypot(d.x, d.z), 15.0f) << hand << " frame " << f;
    }
  }
  EXPECT_GT(max_knee, 55.0f);
  EXPECT_LE(max_knee, 120.0f);
  EXPECT_GT(max_elbow, 35.0f);
  EXPECT_LE(max_elbow, 120.0f);
}

TEST(Synthetic, WalkPlantsTheStanceFootAndMovesSmoothly) {
  const mocap::Skeleton s = synthetic::MakeHumanoidSkeleton();
  auto m = synthetic::MakeWalkMotion(s);
  ASSERT_TRUE(m.ok());
  const Probe pr{s, Positions(s, *m)};
  int planted_pairs = 0;
  for (int f = 1; f < m->num_frames; ++f) {
    for (const char* foot : {"LeftFoot", "RightFoot"}) {
      const glm::vec3 a = pr.At(f - 1, foot);
      const glm::vec3 b = pr.At(f, foot);
      const float ankle_rest_y = 8.0f;
      if (std::abs(a.y - ankle_rest_y) < testsupport::kFootSlideTolCm &&
          std::abs(b.y - ankle_rest_y) < testsupport::kFootSlideTolCm) {
        EXPECT_LT(std::hypot(b.x - a.x, b.z - a.z), testsupport::kFootSlideTolCm)
            << foot << " slides at frame " << f;
        ++planted_pairs;
      }
    }
  }
  // Stance is 60% of the cycle for each foot.
  EXPECT_GT(planted_pairs, m->num_frames);
  // Hips: no vertical acceleration spikes (a real walk stays well under 0.5 g).
  auto k = mocap::ComputeKinematics(s, *m);
  ASSERT_TRUE(k.ok());
  for (int f = 0; f < m->num_frames; ++f) {
    EXPECT_LT(std::abs((*k)[static_cast<std::size_t>(f * s.num_joints())].linear_acceleration.y),
              0.5 * synthetic::kGravityCmPerS2)
        << "frame " << f;
  }
}

TEST(Synthetic, WalkLoops) {
  const mocap::Skeleton s = synthetic::MakeHumanoidSkeleton();
  auto m = synthetic::MakeWalkMotion(s, {.num_cycles = 2});
  ASSERT_TRUE(m.ok());
  const int cycle = m->num_frames / 2;
  for (int c = 3; c < m->num_channels; ++c) {  // all but the root position
    EXPECT_NEAR(m->frame(cycle)[c], m->frame(0)[c], testsupport::kResampleChannelTol)
        << "channel " << c;
  }
  EXPECT_NEAR(m->frame(cycle)[1], m->frame(0)[1], testsupport::kResampleChannelTol);
  auto again = synthetic::MakeWalkMotion(s, {.num_cycles = 2});
  EXPECT_EQ(again->values, m->values);  // deterministic
}

TEST(Synthetic, BendRampReaches150Degrees) {
  const mocap::Skeleton s = synthetic::MakeHumanoidSkeleton();
  auto m = synthetic::MakeBendRamp(s);
  ASSERT_TRUE(m.ok());
  ExpectWellFormed(s, *m);
  const Probe pr{s, Positions(s, *m)};
  const int last = m->num_frames - 1;
  const float tol = testsupport::kBendMeasureTolDeg;
  EXPECT_NEAR(BendDeg(pr.At(0, "LeftArm"), pr.At(0, "LeftForeArm"), pr.At(0, "LeftHand")), 0.0f,
              tol);
  EXPECT_NEAR(BendDeg(pr.At(last, "LeftArm"), pr.At(last, "LeftForeArm"), pr.At(last, "LeftHand")),
              150.0f, tol);
  EXPECT_NEAR(
      BendDeg(pr.At(last, "RightArm"), pr.At(last, "RightForeArm"), pr.At(last, "RightHand")),
      150.0f, tol);
  EXPECT_NEAR(BendDeg(pr.At(last, "LeftUpLeg"), pr.At(last, "LeftLeg"), pr.At(last, "LeftFoot")),
              150.0f, tol);
  const int mid = last / 2;
  EXPECT_NEAR(BendDeg(pr.At(mid, "LeftUpLeg"), pr.At(mid, "LeftLeg"), pr.At(mid, "LeftFoot")),
              75.0f, tol);
  for (int f = 0; f <= last; ++f) {
    EXPECT_NEAR(LowestFootY(pr, f, "Right"), 0.0f, testsupport::kPositionTol);  // standing leg
    EXPECT_GT(LowestFootY(pr, f, "Left"), -testsupport::kPositionTol);          // lifted leg
    // Forearms bend forward, never into the chest.
    EXPECT_GE(pr.At(f, "LeftHand").z, -testsupport::kPositionTol);
  }
}

TEST(Synthetic, TwistRampTurnsTheForearmsAboutTheirAxis) {
  const mocap::Skeleton s = synthetic::MakeHumanoidSkeleton();
  auto m = synthetic::MakeTwistRamp(s);
  ASSERT_TRUE(m.ok());
  ExpectWellFormed(s, *m);
  const int fore = s.FindJoint("LeftForeArm");
  std::vector<mocap::JointTransform> locals(static_cast<std::size_t>(s.num_joints()));
  float previous = 0.0f;
  for (int f = 0; f < m->num_frames; ++f) {
    ASSERT_TRUE((mocap::LocalPoseJob{&s, m->frame(f), locals}).Run().ok());
    const mocap::SwingTwist st = mocap::DecomposeSwingTwist(
        locals[static_cast<std::size_t>(fore)].rotation, glm::vec3(1, 0, 0));
    const float twist = std::abs(glm::degrees(st.twist_angle_rad));
    const float expected = 180.0f * static_cast<float>(f) / static_cast<float>(m->num_frames - 1);
    EXPECT_NEAR(twist, expected, testsupport::kBendMeasureTolDeg);
    EXPECT_NEAR(glm::degrees(2.0f * std::acos(std::min(1.0f, std::abs(st.swing.w)))), 0.0f,
                testsupport::kBendMeasureTolDeg);
    // The X channel carries the twist continuously (no jump to Z=180, Y=180).
    const float x_channel = m->frame(f)[s.channels[static_cast<std::size_t>(fore)].first + 1];
    EXPECT_LT(std::abs(x_channel - previous), testsupport::kMaxAngleStepDeg);
    previous = x_channel;
  }
}

TEST(Synthetic, JumpHasAnAccelerationSpikeAndFreeFall) {
  const mocap::Skeleton s = synthetic::MakeHumanoidSkeleton();
  const synthetic::JumpOptions options{.frame_time_s = 1.0 / 120.0};
  auto m = synthetic::MakeJumpMotion(s, options);
  ASSERT_TRUE(m.ok());
  ExpectWellFormed(s, *m);
  const synthetic::JumpTimeline tl = synthetic::MakeJumpTimeline(options);
  auto k = mocap::ComputeKinematics(s, *m);
  ASSERT_TRUE(k.ok());
  const int nj = s.num_joints();
  const double h = m->frame_time_s;
  const Probe pr{s, Positions(s, *m)};
  float apex = 0.0f;
  for (int f = 1; f + 1 < m->num_frames; ++f) {
    const double t = f * h;
    const float ay = (*k)[static_cast<std::size_t>(f * nj)].linear_acceleration.y;
    // Whole flight and push intervals, away from the kinks where the central
    // difference straddles two phases.
    if (t > tl.takeoff_s + h && t < tl.touchdown_s - h) {
      EXPECT_NEAR(ay, -synthetic::kGravityCmPerS2, testsupport::kJumpAccelTolCmPerS2) << "t " << t;
      EXPECT_GT(LowestFootY(pr, f, "Left"), 0.0f);
    }
    if (t > tl.push_start_s + h && t < tl.takeoff_s - h) {
      EXPECT_NEAR(ay, tl.push_acceleration_cm_per_s2, testsupport::kJumpAccelTolCmPerS2)
          << "t " << t;
    }
    if (t < tl.takeoff_s - h || t > tl.touchdown_s + h) {
      EXPECT_NEAR(LowestFootY(pr, f, "Left"), 0.0f, testsupport::kPositionTol) << "t " << t;
    }
    apex = std::max(apex, pr.At(f, "Hips").y - s.rest_translations[0].y);
  }
  EXPECT_NEAR(apex, options.height_cm, testsupport::kJumpApexTolCm);
  EXPECT_GT(tl.push_acceleration_cm_per_s2, synthetic::kGravityCmPerS2);  // a real spike
}

TEST(Synthetic, GeneratorsRejectBadInput) {
  const mocap::Skeleton s = synthetic::MakeHumanoidSkeleton();
  EXPECT_EQ(synthetic::MakeBendRamp(s, 150.0f, 2.0, 0.0).error().code,
            base::ErrorCode::kInvalidArgument);
  EXPECT_EQ(synthetic::MakeWalkMotion(s, {.step_length_cm = 90.0}).error().code,
            base::ErrorCode::kInvalidArgument);
  EXPECT_EQ(synthetic::MakeWalkMotion(s, {.num_cycles = 0}).error().code,
            base::ErrorCode::kInvalidArgument);
  EXPECT_EQ(synthetic::MakeJumpMotion(s, {.crouch_cm = 100.0}).error().code,
            base::ErrorCode::kInvalidArgument);
  auto chain = synthetic::MakeChainSkeleton(5);
  ASSERT_TRUE(chain.ok());
  const auto missing = synthetic::MakeTwistRamp(*chain);
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().code, base::ErrorCode::kNotFound);
  EXPECT_NE(missing.error().message.find("Hips"), std::string::npos);
  EXPECT_EQ(synthetic::MakeChainSkeleton(0).error().code, base::ErrorCode::kInvalidArgument);
  EXPECT_EQ(synthetic::MakeChainSkeleton(mocap::kMaxJoints + 1).error().code,
            base::ErrorCode::kInvalidArgument);
}

TEST(Synthetic, GeneratorsFollowAnyChannelOrder) {
  mocap::Skeleton s = synthetic::MakeHumanoidSkeleton();
  const mocap::Skeleton zxy = s;
  for (std::size_t j = 1; j < s.channels.size(); ++j) {  // XYZ everywhere but the root
    s.channels[j].types[0] = mocap::ChannelType::kXRotation;
    s.channels[j].types[1] = mocap::ChannelType::kYRotation;
    s.channels[j].types[2] = mocap::ChannelType::kZRotation;
  }
  auto a = synthetic::MakeWalkMotion(zxy);
  auto b = synthetic::MakeWalkMotion(s);
  ASSERT_TRUE(a.ok() && b.ok());
  const std::vector<glm::vec3> pa = Positions(zxy, *a);
  const std::vector<glm::vec3> pb = Positions(s, *b);
  for (std::size_t i = 0; i < pa.size(); ++i) {
    EXPECT_LT(glm::length(pa[i] - pb[i]), testsupport::kPositionTol * 10);
  }
}

TEST(Synthetic, ChainAndQuadrupedSkeletons) {
  auto chain = synthetic::MakeChainSkeleton(12, 5.0f);
  ASSERT_TRUE(chain.ok());
  ASSERT_TRUE(chain->Check().ok());
  EXPECT_EQ(chain->num_joints(), 12);
  EXPECT_EQ(chain->num_channels, 6 + 11 * 3);
  EXPECT_EQ(chain->names[11], "Chain11");
  const mocap::Skeleton q = synthetic::MakeQuadrupedSkeleton();
  ASSERT_TRUE(q.Check().ok());
  EXPECT_EQ(q.num_joints(), 23);
  mocap::Motion rest;
  rest.num_frames = 1;
  rest.num_channels = q.num_channels;
  rest.values.assign(static_cast<std::size_t>(q.num_channels), 0.0f);
  rest.values[1] = q.rest_translations[0].y;
  const Probe pr{q, Positions(q, rest)};
  for (const char* toe :
       {"LeftFrontToeBase", "RightFrontToeBase", "LeftHindToeBase", "RightHindToeBase"}) {
    EXPECT_NEAR(pr.At(0, toe).y, 1.0f, testsupport::kPositionTol) << toe;
  }
  EXPECT_GT(pr.At(0, "Head").z, pr.At(0, "Hips").z);  // faces +Z
}

}  // namespace
