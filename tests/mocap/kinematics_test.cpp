#include "mocap/kinematics.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "support/tolerances.h"

namespace {

using mocap::ChannelType;

// An analytic motion whose derivatives are known in closed form:
//   root  translates x = a t^2/2 + v0 t and turns about Y by  tp = w0 t + al t^2/2;
//   arm   (offset r along the root's X) turns about its own Z by tc = c0 t + c1 t^2/2;
//   hand  (offset r2 along the arm's X) has no channels.
struct Analytic {
  double a = 50, v0 = 20;      // cm/s^2, cm/s
  double w0 = 1.0, al = 1.5;   // rad/s, rad/s^2
  double c0 = -2.0, c1 = 3.0;  // rad/s, rad/s^2
  double r = 30, r2 = 25;      // cm
  double duration = 1.0;       // s
  // Bounds on the angular speed W and angular acceleration A of any joint over the
  // clip (sums of the parts), used for the truncation-error bounds.
  double W() const {
    return std::abs(w0) + std::abs(al) * duration + std::abs(c0) + std::abs(c1) * duration;
  }
  double A() const { return std::abs(al) + std::abs(c1) + W() * W(); }

  double tp(double t) const { return w0 * t + 0.5 * al * t * t; }
  double tc(double t) const { return c0 * t + 0.5 * c1 * t * t; }

  struct State {
    glm::dvec3 p, v, acc, w, alpha;
    glm::dquat q;
  };
  // Rigid-body kinematics: child velocity v + w x d, acceleration a + al x d + w x (w x d).
  State Root(double t) const {
    return {{a * t * t / 2 + v0 * t, 0, 0},
            {a * t + v0, 0, 0},
            {a, 0, 0},
            {0, w0 + al * t, 0},
            {0, al, 0},
            glm::angleAxis(tp(t), glm::dvec3(0, 1, 0))};
  }
  State Arm(double t) const {
    const State root = Root(t);
    const glm::dvec3 d = root.q * glm::dvec3(r, 0, 0);
    const glm::dvec3 wc = root.q * glm::dvec3(0, 0, c0 + c1 * t);  // child spin in model space
    const glm::dvec3 w = root.w + wc;
    const glm::dvec3 alpha = root.alpha + root.q * glm::dvec3(0, 0, c1) + glm::cross(root.w, wc);
    return {root.p + d,
            root.v + glm::cross(root.w, d),
            root.acc + glm::cross(root.alpha, d) + glm::cross(root.w, glm::cross(root.w, d)),
            w,
            alpha,
            root.q * glm::angleAxis(tc(t), glm::dvec3(0, 0, 1))};
  }
  State Hand(double t) const {
    const State arm = Arm(t);
    const glm::dvec3 d = arm.q * glm::dvec3(r2, 0, 0);
    return {arm.p + d,
            arm.v + glm::cross(arm.w, d),
            arm.acc + glm::cross(arm.alpha, d) + glm::cross(arm.w, glm::cross(arm.w, d)),
            arm.w,
            arm.alpha,
            arm.q};
  }
  State Joint(int j, double t) const { return j == 0 ? Root(t) : j == 1 ? Arm(t) : Hand(t); }

  mocap::Skeleton MakeSkeleton() const {
    mocap::Skeleton s;
    s.names = {"root", "arm", "hand"};
    s.parents = {mocap::kNoParent, 0, 1};
    s.rest_translations = {glm::vec3(0), glm::vec3(static_cast<float>(r), 0, 0),
                           glm::vec3(static_cast<float>(r2), 0, 0)};
    s.rest_rotations.assign(3, glm::quat(1, 0, 0, 0));
    s.rest_scales.assign(3, glm::vec3(1));
    s.channels.resize(3);
    s.channels[0] = {0,
                     6,
                     {ChannelType::kXPosition, ChannelType::kYPosition, ChannelType::kZPosition,
                      ChannelType::kZRotation, ChannelType::kXRotation, ChannelType::kYRotation}};
    s.channels[1] = {
        6, 3, {ChannelType::kZRotation, ChannelType::kXRotation, ChannelType::kYRotation}};
    s.num_channels = 9;
    return s;
  }
  mocap::Motion MakeMotion(double fps) const {
    mocap::Motion m;
    m.frame_time_s = 1.0 / fps;
    m.num_frames = static_cast<int>(std::lround(duration * fps)) + 1;
    m.num_channels = 9;
    for (int f = 0; f < m.num_frames; ++f) {
      const double t = f * m.frame_time_s;
      const float row[9] = {static_cast<float>(Root(t).p.x),
                            0,
                            0,
                            0,
                            0,
                            static_cast<float>(glm::degrees(tp(t))),
                            static_cast<float>(glm::degrees(tc(t))),
                            0,
                            0};
      m.values.insert(m.values.end(), row, row + 9);
    }
    return m;
  }
};

// Central differences: |error| <= h^2/6 max|x'''| for a first derivative and
// h^2/12 max|x''''| for a second one, plus the float round-off of the model
// matrices (relative kMatrixRoundoff) divided by 2h or h^2/4. The derivative
// bounds for a point at distance L from rotating joints: |x'''| <= (W^3 + 3 W A) L,
// |x''''| <= (W^4 + 6 W^2 A + 3 A^2) L (fixed-axis terms; al' = 0 here).
double VelocityTol(const Analytic& an, double h, double length, double magnitude) {
  const double w = an.W(), a = an.A();
  return testsupport::kFdSafety * (h * h / 6 * (w * w * w + 3 * w * a) * length +
                                   testsupport::kMatrixRoundoff * magnitude / h);
}
double AccelerationTol(const Analytic& an, double h, double length, double magnitude) {
  const double w = an.W(), a = an.A();
  return testsupport::kFdSafety *
         (h * h / 12 * (w * w * w * w + 6 * w * w * a + 3 * a * a) * length +
          4 * testsupport::kMatrixRoundoff * magnitude / (h * h));
}

void ExpectVecNear(const glm::vec3& got, const glm::dvec3& want, double tol, const char* what,
                   int f, int j) {
  EXPECT_LE(glm::length(glm::dvec3(got) - want), tol)
      << what << " frame " << f << " joint " << j << " got " << got.x << "," << got.y << ","
      << got.z << " want " << want.x << "," << want.y << "," << want.z;
}

TEST(KinematicsJob, Validity) {
  std::vector<glm::mat4> model(6);
  std::vector<mocap::JointKinematics> out(6), odd(5);
  EXPECT_EQ((mocap::KinematicsJob{
                 .model_from_joint = model, .num_joints = 0, .frame_time_s = 0.1, .output = out})
                .Validate()
                .code,
            base::JobStatus::kMissingInput);
  EXPECT_EQ((mocap::KinematicsJob{
                 .model_from_joint = model, .num_joints = 2, .frame_time_s = 0.1, .output = odd})
                .Validate()
                .code,
            base::JobStatus::kSizeMismatch);
  EXPECT_EQ((mocap::KinematicsJob{
                 .model_from_joint = model, .num_joints = 2, .frame_time_s = 0.0, .output = out})
                .Validate()
                .code,
            base::JobStatus::kOutOfRange);
  EXPECT_EQ((mocap::KinematicsJob{.model_from_joint = model,
                                  .num_joints = 2,
                                  .frame_time_s = 0.1,
                                  .first_frame = 1,
                                  .output = out})
                .Validate()
                .code,
            base::JobStatus::kOutOfRange);
  EXPECT_TRUE((mocap::KinematicsJob{
                   .model_from_joint = model, .num_joints = 2, .frame_time_s = 0.1, .output = out})
                  .Run()
                  .ok());
  const Analytic an;
  const mocap::Skeleton s = an.MakeSkeleton();
  const mocap::Motion m = an.MakeMotion(30);
  std::vector<mocap::JointTransform> locals(3), few(2);
  std::vector<glm::mat4> mats(3 * 4);
  EXPECT_EQ((mocap::ModelMatricesJob{
                 .skeleton = &s, .motion = &m, .locals = few, .model_from_joint = mats})
                .Validate()
                .code,
            base::JobStatus::kSizeMismatch);
  EXPECT_EQ((mocap::ModelMatricesJob{.skeleton = &s,
                                     .motion = &m,
                                     .first_frame = m.num_frames - 2,
                                     .locals = locals,
                                     .model_from_joint = mats})
                .Validate()
                .code,
            base::JobStatus::kOutOfRange);
  EXPECT_EQ((mocap::ModelMatricesJob{
                 .skeleton = nullptr, .motion = &m, .locals = locals, .model_from_joint = mats})
                .Validate()
                .code,
            base::JobStatus::kMissingInput);
}

TEST(KinematicsJob, MatchesAnalyticDerivativesAtInteriorFrames) {
  const Analytic an;
  const mocap::Skeleton s = an.MakeSkeleton();
  const double lengths[3] = {0.0, an.r, an.r + an.r2};  // lever arm of each joint's position
  for (double fps : {30.0, 60.0, 120.0}) {
    const mocap::Motion m = an.MakeMotion(fps);
    auto k = mocap::ComputeKinematics(s, m);
    ASSERT_TRUE(k.ok());
    const double h = m.frame_time_s;
    const double magnitude = 100.0;  // |positions| in cm over the clip, for round-off
    for (int f = 1; f + 1 < m.num_frames; ++f) {
      for (int j = 0; j < 3; ++j) {
        const mocap::JointKinematics& got = (*k)[static_cast<std::size_t>(f * 3 + j)];
        const Analytic::State want = an.Joint(j, f * h);
        ExpectVecNear(got.position, want.p, testsupport::kPositionTol, "position", f, j);
        ExpectVecNear(got.linear_velocity, want.v, VelocityTol(an, h, lengths[j], magnitude),
                      "velocity", f, j);
        ExpectVecNear(got.linear_acceleration, want.acc,
                      AccelerationTol(an, h, lengths[j], magnitude), "acceleration", f, j);
        ExpectVecNear(got.angular_velocity, want.w, VelocityTol(an, h, 1.0, 1.0),
                      "angular velocity", f, j);
        ExpectVecNear(got.angular_acceleration, want.alpha, AccelerationTol(an, h, 1.0, 1.0),
                      "angular acceleration", f, j);
      }
    }
  }
}

// Second order: halving h divides the truncation error by ~4 (velocity of the hand).
TEST(KinematicsJob, ErrorShrinksWithTheSquareOfTheStep) {
  const Analytic an;
  const mocap::Skeleton s = an.MakeSkeleton();
  double max_error[2] = {0, 0};
  const double fps[2] = {30.0, 60.0};
  for (int i = 0; i < 2; ++i) {
    const mocap::Motion m = an.MakeMotion(fps[i]);
    auto k = mocap::ComputeKinematics(s, m);
    ASSERT_TRUE(k.ok());
    for (int f = 1; f + 1 < m.num_frames; ++f) {
      const double err =
          glm::length(glm::dvec3((*k)[static_cast<std::size_t>(f * 3 + 2)].linear_velocity) -
                      an.Hand(f * m.frame_time_s).v);
      max_error[i] = std::max(max_error[i], err);
    }
  }
  EXPECT_GT(max_error[0] / max_error[1], testsupport::kSecondOrderMinRatio);
}

TEST(KinematicsJob, CentripetalAccelerationOfAChildOnASpinningParent) {
  Analytic an;
  an.a = an.v0 = an.al = an.c0 = an.c1 = 0.0;
  an.w0 = 3.0;  // rad/s
  const mocap::Skeleton s = an.MakeSkeleton();
  const mocap::Motion m = an.MakeMotion(120);
  auto k = mocap::ComputeKinematics(s, m);
  ASSERT_TRUE(k.ok());
  const double h = m.frame_time_s;
  for (int f = 1; f + 1 < m.num_frames; ++f) {
    const mocap::JointKinematics& arm = (*k)[static_cast<std::size_t>(f * 3 + 1)];
    // |a| = w^2 r, pointing from the arm to the spin axis (-position direction).
    const double expected = an.w0 * an.w0 * an.r;
    EXPECT_NEAR(glm::length(arm.linear_acceleration), expected, AccelerationTol(an, h, an.r, an.r));
    EXPECT_NEAR(glm::dot(glm::normalize(arm.linear_acceleration), glm::normalize(-arm.position)),
                1.0, testsupport::kFloatTol * 10);
    EXPECT_NEAR(glm::length(arm.linear_velocity), an.w0 * an.r, VelocityTol(an, h, an.r, an.r));
  }
}

TEST(KinematicsJob, EndFramesAreOneSided) {
  const Analytic an;
  const mocap::Skeleton s = an.MakeSkeleton();
  const mocap::Motion m = an.MakeMotion(60);
  auto k = mocap::ComputeKinematics(s, m);
  ASSERT_TRUE(k.ok());
  const double h = m.frame_time_s;
  const int last = m.num_frames - 1;
  // Root: quadratic in t, so even the one-sided formulas are exact up to round-off.
  for (int f : {0, last}) {
    const mocap::JointKinematics& root = (*k)[static_cast<std::size_t>(f * 3)];
    ExpectVecNear(root.linear_velocity, an.Root(f * h).v, VelocityTol(an, h, 0.0, 100.0),
                  "velocity", f, 0);
    ExpectVecNear(root.linear_acceleration, an.Root(f * h).acc, AccelerationTol(an, h, 0.0, 100.0),
                  "acceleration", f, 0);
    ExpectVecNear(root.angular_velocity, an.Root(f * h).w, VelocityTol(an, h, 0.0, 1.0), "w", f, 0);
    // Hand: one-sided second-order velocity (3x the central bound), first-order
    // acceleration (error h max|x'''|).
    const mocap::JointKinematics& hand = (*k)[static_cast<std::size_t>(f * 3 + 2)];
    const double len = an.r + an.r2;
    ExpectVecNear(hand.linear_velocity, an.Hand(f * h).v, 4 * VelocityTol(an, h, len, 100.0),
                  "velocity", f, 2);
    const double w = an.W(), a = an.A();
    const double first_order = testsupport::kFdSafety * h * (w * w * w + 3 * w * a) * len;
    ExpectVecNear(hand.linear_acceleration, an.Hand(f * h).acc,
                  first_order + AccelerationTol(an, h, len, 100.0), "acceleration", f, 2);
  }
}

TEST(KinematicsJob, JointFrameValuesAreRTransposeTimesModel) {
  const Analytic an;
  const mocap::Skeleton s = an.MakeSkeleton();
  auto k = mocap::ComputeKinematics(s, an.MakeMotion(30));
  ASSERT_TRUE(k.ok());
  for (const mocap::JointKinematics& j : *k) {
    const glm::mat3 r = glm::mat3_cast(j.rotation);
    const glm::mat3 rt = glm::transpose(r);
    const float tol = testsupport::kLocalFrameRelTol;
    ExpectVecNear(j.local_linear_velocity, rt * j.linear_velocity,
                  tol * (1 + glm::length(j.linear_velocity)), "v", 0, 0);
    ExpectVecNear(j.local_linear_acceleration, rt * j.linear_acceleration,
                  tol * (1 + glm::length(j.linear_acceleration)), "a", 0, 0);
    ExpectVecNear(j.local_angular_velocity, rt * j.angular_velocity,
                  tol * (1 + glm::length(j.angular_velocity)), "w", 0, 0);
    ExpectVecNear(j.local_angular_acceleration, rt * j.angular_acceleration,
                  tol * (1 + glm::length(j.angular_acceleration)), "al", 0, 0);
  }
  // The arm spins about its own Z: in its frame w has the root's spin rotated by
  // the arm's twist plus (0, 0, tc') exactly in the z component.
  const mocap::JointKinematics& arm = (*k)[static_cast<std::size_t>(10 * 3 + 1)];
  const double t = 10.0 / 30.0;
  EXPECT_NEAR(arm.local_angular_velocity.z, an.c0 + an.c1 * t,
              VelocityTol(an, 1.0 / 30.0, 1.0, 1.0));
}

TEST(KinematicsJob, SplitRangesGiveTheSameBits) {
  const Analytic an;
  const mocap::Skeleton s = an.MakeSkeleton();
  const mocap::Motion m = an.MakeMotion(30);
  auto whole = mocap::ComputeKinematics(s, m);
  ASSERT_TRUE(whole.ok());
  std::vector<mocap::JointTransform> locals(3);
  std::vector<glm::mat4> model(static_cast<std::size_t>(m.num_frames) * 3);
  ASSERT_TRUE((mocap::ModelMatricesJob{
                   .skeleton = &s, .motion = &m, .locals = locals, .model_from_joint = model})
                  .Run()
                  .ok());
  std::vector<mocap::JointKinematics> parts(model.size());
  const int split = 13;
  ASSERT_TRUE((mocap::KinematicsJob{.model_from_joint = model,
                                    .num_joints = 3,
                                    .frame_time_s = m.frame_time_s,
                                    .first_frame = 0,
                                    .output = std::span(parts).first(split * 3)})
                  .Run()
                  .ok());
  ASSERT_TRUE((mocap::KinematicsJob{.model_from_joint = model,
                                    .num_joints = 3,
                                    .frame_time_s = m.frame_time_s,
                                    .first_frame = split,
                                    .output = std::span(parts).subspan(split * 3)})
                  .Run()
                  .ok());
  for (std::size_t i = 0; i < parts.size(); ++i) {
    EXPECT_EQ(parts[i].linear_acceleration, (*whole)[i].linear_acceleration);
    EXPECT_EQ(parts[i].angular_velocity, (*whole)[i].angular_velocity);
  }
}

TEST(KinematicsJob, ShortMotions) {
  Analytic an;
  const mocap::Skeleton s = an.MakeSkeleton();
  an.duration = 0.1;
  const mocap::Motion two = an.MakeMotion(10);  // 2 frames
  ASSERT_EQ(two.num_frames, 2);
  auto k = mocap::ComputeKinematics(s, two);
  ASSERT_TRUE(k.ok());
  const glm::dvec3 expected_v = (an.Hand(0.1).p - an.Hand(0.0).p) / 0.1;
  ExpectVecNear((*k)[2].linear_velocity, expected_v, VelocityTol(an, 0.1, 0.0, 100.0), "v", 0, 2);
  ExpectVecNear((*k)[5].linear_velocity, expected_v, VelocityTol(an, 0.1, 0.0, 100.0), "v", 1, 2);
  EXPECT_EQ((*k)[5].linear_acceleration, glm::vec3(0.0f));
  mocap::Motion one = two;
  one.num_frames = 1;
  one.values.resize(9);
  auto k1 = mocap::ComputeKinematics(s, one);
  ASSERT_TRUE(k1.ok());
  EXPECT_EQ((*k1)[2].linear_velocity, glm::vec3(0.0f));
  mocap::Motion none = one;
  none.num_frames = 0;
  none.values.clear();
  EXPECT_EQ(mocap::ComputeKinematics(s, none).error().code, base::ErrorCode::kInvalidArgument);
}

TEST(SmoothTrajectoriesJob, Validity) {
  std::vector<glm::mat4> model(6), out(6), odd(5);
  EXPECT_EQ((mocap::SmoothTrajectoriesJob{.model_from_joint = model,
                                          .num_joints = 2,
                                          .frame_time_s = 0.1,
                                          .cutoff_hz = 0.0,
                                          .output = out})
                .Validate()
                .code,
            base::JobStatus::kOutOfRange);
  EXPECT_EQ((mocap::SmoothTrajectoriesJob{
                 .model_from_joint = model, .num_joints = 2, .frame_time_s = 0.1, .output = odd})
                .Validate()
                .code,
            base::JobStatus::kSizeMismatch);
  EXPECT_EQ((mocap::SmoothTrajectoriesJob{.model_from_joint = model,
                                          .num_joints = 2,
                                          .frame_time_s = 0.1,
                                          .first_frame = 2,
                                          .output = out})
                .Validate()
                .code,
            base::JobStatus::kOutOfRange);
  EXPECT_TRUE((mocap::SmoothTrajectoriesJob{
                   .model_from_joint = model, .num_joints = 2, .frame_time_s = 0.1, .output = out})
                  .Run()
                  .ok());
}

// 40 Hz jitter on the root (as capture noise) swamps the second difference; the
// 10 Hz low-pass removes it and leaves the quadratic trajectory's acceleration.
TEST(SmoothTrajectoriesJob, RemovesHighFrequencyNoiseBeforeDifferencing) {
  const Analytic an;
  const mocap::Skeleton s = an.MakeSkeleton();
  mocap::Motion m = an.MakeMotion(120);
  const double noise_cm = 0.2;
  for (int f = 0; f < m.num_frames; ++f) {
    m.frame(f)[0] +=
        static_cast<float>(noise_cm * std::sin(2.0 * 3.14159265358979 * 40.0 * f * m.frame_time_s));
  }
  std::vector<mocap::JointTransform> locals(3);
  std::vector<glm::mat4> model(static_cast<std::size_t>(m.num_frames) * 3), smooth(model.size());
  ASSERT_TRUE((mocap::ModelMatricesJob{
                   .skeleton = &s, .motion = &m, .locals = locals, .model_from_joint = model})
                  .Run()
                  .ok());
  ASSERT_TRUE((mocap::SmoothTrajectoriesJob{.model_from_joint = model,
                                            .num_joints = 3,
                                            .frame_time_s = m.frame_time_s,
                                            .cutoff_hz = 10.0,
                                            .output = smooth})
                  .Run()
                  .ok());
  std::vector<mocap::JointKinematics> raw(model.size()), filtered(model.size());
  ASSERT_TRUE((mocap::KinematicsJob{.model_from_joint = model,
                                    .num_joints = 3,
                                    .frame_time_s = m.frame_time_s,
                                    .output = raw})
                  .Run()
                  .ok());
  ASSERT_TRUE((mocap::KinematicsJob{.model_from_joint = smooth,
                                    .num_joints = 3,
                                    .frame_time_s = m.frame_time_s,
                                    .output = filtered})
                  .Run()
                  .ok());
  double raw_error = 0.0, filtered_error = 0.0, w_error = 0.0;
  const int margin = 6;  // > 3 sigma = 2.4 frames at 120 fps: windows not cut by the ends
  for (int f = margin; f + margin < m.num_frames; ++f) {
    const Analytic::State want = an.Root(f * m.frame_time_s);
    raw_error =
        std::max(raw_error, glm::length(glm::dvec3(raw[f * 3u].linear_acceleration) - want.acc));
    filtered_error = std::max(
        filtered_error, glm::length(glm::dvec3(filtered[f * 3u].linear_acceleration) - want.acc));
    w_error =
        std::max(w_error, glm::length(glm::dvec3(filtered[f * 3u].angular_velocity) - want.w));
  }
  // Raw: the noise's second difference, ~ noise (2 pi 40)^2 = 1.2e4 cm/s^2.
  EXPECT_GT(raw_error, 0.5 * noise_cm * std::pow(2.0 * 3.14159265358979 * 40.0, 2));
  EXPECT_LT(filtered_error, testsupport::kLowPassResidual * raw_error);
  // Rotation about a fixed axis with a quadratic angle keeps its velocity.
  EXPECT_LT(w_error, testsupport::kLowPassAngularVelTol);
}

TEST(SampleJointKinematics, ExactAtFramesAndCloseBetween) {
  const Analytic an;
  const mocap::Skeleton s = an.MakeSkeleton();
  const mocap::Motion m = an.MakeMotion(60);
  auto k = mocap::ComputeKinematics(s, m);
  ASSERT_TRUE(k.ok());
  const double h = m.frame_time_s;
  mocap::JointKinematics out;
  EXPECT_EQ(mocap::SampleJointKinematics(*k, 3, 3, h, 0.0, &out).code,
            base::JobStatus::kOutOfRange);
  EXPECT_EQ(mocap::SampleJointKinematics(std::span(*k).first(5), 3, 0, h, 0.0, &out).code,
            base::JobStatus::kSizeMismatch);
  EXPECT_EQ(mocap::SampleJointKinematics(*k, 3, 0, h, 0.0, nullptr).code,
            base::JobStatus::kMissingInput);
  ASSERT_TRUE(mocap::SampleJointKinematics(*k, 3, 2, h, 7 * h, &out).ok());
  EXPECT_EQ(out.linear_acceleration, (*k)[7 * 3 + 2].linear_acceleration);
  // Between frames (RK4 stage times): linear interpolation adds h^2/8 max|x'''| to
  // the finite-difference error.
  const double len = an.r + an.r2;
  const double w = an.W(), a = an.A();
  for (double frac : {0.25, 0.5, 0.75}) {
    const double t = (20 + frac) * h;
    ASSERT_TRUE(mocap::SampleJointKinematics(*k, 3, 2, h, t, &out).ok());
    const Analytic::State want = an.Hand(t);
    const double interp_v = testsupport::kFdSafety * h * h / 8 * (w * w * w + 3 * w * a) * len;
    ExpectVecNear(out.position, want.p, testsupport::kPositionTol * 10, "position", 20, 2);
    ExpectVecNear(out.linear_velocity, want.v, interp_v + VelocityTol(an, h, len, 100.0),
                  "velocity", 20, 2);
    const glm::mat3 rt = glm::transpose(glm::mat3_cast(out.rotation));
    ExpectVecNear(out.local_linear_acceleration, rt * out.linear_acceleration,
                  testsupport::kLocalFrameRelTol * (1 + glm::length(out.linear_acceleration)),
                  "local a", 20, 2);
    const glm::dquat dq = glm::conjugate(want.q) * glm::dquat(out.rotation);
    // Slerp is a geodesic between the frames: its error is h^2/8 times the angular
    // acceleration bound.
    EXPECT_LT(2 * std::acos(std::min(1.0, std::abs(dq.w))), testsupport::kFdSafety * h * h / 8 * a);
  }
}

}  // namespace
