// Retargeting a BVH motion onto another skeleton (mocap/retarget.h): joint
// names matched exactly, then normalized; required joints named in the error;
// rest pose maps to rest pose; rotations and the scaled root translation follow
// the documented convention, checked against hand-computed poses.

#include "mocap/retarget.h"

#include <cmath>
#include <string>

#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>

#include "mocap/bvh_reader.h"
#include "mocap/pose.h"
#include "support/tolerances.h"

namespace {

using testsupport::kFloatTol;

mocap::BvhFile Parse(const std::string& text) {
  auto file = mocap::ParseBvh(text, "motion.bvh", {});
  EXPECT_TRUE(file.ok()) << file.error().ToString();
  return file.ok() ? std::move(file).value() : mocap::BvhFile{};
}

// A target skeleton built by hand: names, parents, rest translations and rotations.
mocap::Skeleton Target(std::vector<std::string> names, std::vector<std::int16_t> parents,
                       std::vector<glm::vec3> translations, std::vector<glm::quat> rotations) {
  mocap::Skeleton s;
  s.names = std::move(names);
  s.parents = std::move(parents);
  s.rest_translations = std::move(translations);
  s.rest_rotations = std::move(rotations);
  s.rest_scales.assign(s.names.size(), glm::vec3(1.0f));
  s.channels.assign(s.names.size(), {});
  EXPECT_TRUE(s.Check().ok());
  return s;
}

// Hips -> Spine -> Head and Hips -> Leg, in centimetres; two frames: rest
// (hips at 100 cm) and a posed one.
constexpr const char* kBvh = R"(HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT spine
  {
    OFFSET 0 50 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT HEAD
    {
      OFFSET 0 30 0
      CHANNELS 3 Zrotation Xrotation Yrotation
      End Site
      {
        OFFSET 0 10 0
      }
    }
  }
  JOINT LeftLeg
  {
    OFFSET 10 -100 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 -5 0
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.5
0 100 0 0 0 0 0 0 0 0 0 0 0 0 0
20 100 -10 0 0 30 45 0 0 0 20 0 0 -40 0
)";

TEST(Retarget, NormalizesPrefixesAndCase) {
  EXPECT_EQ(mocap::NormalizeJointName("mixamorig:LeftArm"), "leftarm");
  EXPECT_EQ(mocap::NormalizeJointName("mixamorig1_LeftArm"), "leftarm");
  EXPECT_EQ(mocap::NormalizeJointName("Armature|Hips"), "hips");
  EXPECT_EQ(mocap::NormalizeJointName("Hips"), "hips");
  EXPECT_EQ(mocap::NormalizeJointName("mixamorig"), "mixamorig");
}

TEST(Retarget, MapsExactNamesFirstThenNormalized) {
  const mocap::BvhFile bvh = Parse(kBvh);
  const mocap::Skeleton target =
      Target({"mixamorig:Hips", "Spine", "mixamorig:Head", "Tail", "spine"}, {-1, 0, 1, 0, 0},
             {{0, 1, 0}, {0, .5f, 0}, {0, .3f, 0}, {0, 0, -1}, {0, 0, 1}},
             std::vector<glm::quat>(5, glm::quat(1, 0, 0, 0)));
  const std::vector<int> map = mocap::MapJointsByName(target, bvh.skeleton);
  // "spine" (joint 4) matches exactly and wins over "Spine" (joint 1), which
  // would only match after normalizing; "Tail" has no counterpart.
  EXPECT_EQ(map, (std::vector<int>{0, -1, 2, -1, 1}));
}

TEST(Retarget, NamesUnmappedRequiredJoints) {
  const mocap::BvhFile bvh = Parse(kBvh);
  // "Chest" sits between the mapped Hips and Head: it would break the chain.
  const mocap::Skeleton target =
      Target({"Hips", "Chest", "Head"}, {-1, 0, 1}, {{0, 1, 0}, {0, .5f, 0}, {0, .3f, 0}},
             std::vector<glm::quat>(3, glm::quat(1, 0, 0, 0)));
  const auto r = mocap::RetargetMotion(target, bvh.skeleton, bvh.motion, "body.glb", "motion.bvh");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, base::ErrorCode::kInvalidArgument);
  EXPECT_NE(r.error().message.find("found none for: Chest"), std::string::npos) << r.error().ToString();
  EXPECT_EQ(r.error().loc.file, "motion.bvh");

  const mocap::Skeleton no_hips = Target({"Pelvis", "spine"}, {-1, 0}, {{0, 1, 0}, {0, .5f, 0}},
                                         std::vector<glm::quat>(2, glm::quat(1, 0, 0, 0)));
  const auto r2 = mocap::RetargetMotion(no_hips, bvh.skeleton, bvh.motion, "body.glb", "motion.bvh");
  ASSERT_FALSE(r2.ok());
  EXPECT_NE(r2.error().message.find("Hips (the root)"), std::string::npos) << r2.error().ToString();
}

// Model-space matrices of the retargeted skeleton at frame f.
std::vector<glm::mat4> Posed(const mocap::RetargetedMotion& r, int f) {
  std::vector<mocap::JointTransform> locals(static_cast<std::size_t>(r.skeleton.num_joints()));
  std::vector<glm::mat4> model(locals.size());
  EXPECT_TRUE((mocap::LocalPoseJob{&r.skeleton, r.motion.frame(f), locals}.Run()));
  EXPECT_TRUE((mocap::LocalToModelJob{.parents = r.skeleton.parents, .locals = locals,
                                      .model_from_joint = model}
                   .Run()));
  return model;
}

void ExpectMat(const glm::mat4& got, const glm::mat4& want, const std::string& what) {
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) EXPECT_NEAR(got[c][r], want[c][r], kFloatTol) << what << " [" << c << "][" << r << "]";
  }
}

glm::quat Axis(float deg, glm::vec3 axis) { return glm::angleAxis(glm::radians(deg), axis); }

TEST(Retarget, WorldRotationDeltasAndScaledRoot) {
  const mocap::BvhFile bvh = Parse(kBvh);
  // Metres, and a spine whose rest frame is turned 90 degrees about Y: the
  // world-space delta convention must still bend it the way the BVH spine bends.
  const glm::quat spine_rest = Axis(90, {0, 1, 0});
  const mocap::Skeleton target = Target(
      {"mixamorig:Hips", "mixamorig:Spine", "mixamorig:Head", "mixamorig:LeftLeg"}, {-1, 0, 1, 0},
      {{0, 1, 0}, {0, .5f, 0}, {0, .3f, 0}, {.1f, -1, 0}},
      {glm::quat(1, 0, 0, 0), spine_rest, glm::quat(1, 0, 0, 0), glm::quat(1, 0, 0, 0)});
  const auto r = mocap::RetargetMotion(target, bvh.skeleton, bvh.motion, "body.glb", "motion.bvh");
  ASSERT_TRUE(r.ok()) << r.error().ToString();
  EXPECT_EQ(r->root, 0);
  EXPECT_NEAR(r->translation_scale, 0.01f, kFloatTol);  // 1 m hips / 100 cm hips
  EXPECT_EQ(r->motion.num_frames, 2);
  EXPECT_DOUBLE_EQ(r->motion.frame_time_s, 0.5);

  // Frame 0 is the BVH rest pose standing at 100 cm: the target's rest pose.
  std::vector<mocap::JointTransform> rest(4);
  std::vector<glm::mat4> rest_model(4);
  mocap::RestPose(target, rest);
  ASSERT_TRUE((mocap::LocalToModelJob{.parents = target.parents, .locals = rest,
                                      .model_from_joint = rest_model}
                   .Run()));
  const std::vector<glm::mat4> at0 = Posed(*r, 0);
  for (int j = 0; j < 4; ++j) ExpectMat(at0[static_cast<std::size_t>(j)], rest_model[static_cast<std::size_t>(j)], "rest joint " + std::to_string(j));

  // Frame 1 by hand. BVH world rotations (ZXY channels, one axis each here):
  const glm::quat hips = Axis(30, {0, 1, 0});
  const glm::quat spine = hips * Axis(45, {0, 0, 1});
  const glm::quat head = spine * Axis(20, {1, 0, 0});
  const glm::quat leg = hips * Axis(-40, {1, 0, 0});
  // Target world rotation = BVH world delta * target rest world rotation;
  // positions chain the target's own bone vectors.
  const glm::vec3 p_hips = 0.01f * glm::vec3(20, 100, -10);
  const glm::quat w_spine = spine * spine_rest;
  const glm::vec3 p_spine = p_hips + hips * glm::vec3(0, .5f, 0);
  const glm::vec3 p_head = p_spine + w_spine * glm::vec3(0, .3f, 0);
  const glm::vec3 p_leg = p_hips + hips * glm::vec3(.1f, -1, 0);
  auto model = [](const glm::quat& q, const glm::vec3& p) {
    glm::mat4 m = glm::mat4_cast(q);
    m[3] = glm::vec4(p, 1.0f);
    return m;
  };
  const std::vector<glm::mat4> at1 = Posed(*r, 1);
  ExpectMat(at1[0], model(hips, p_hips), "hips");
  ExpectMat(at1[1], model(w_spine, p_spine), "spine");
  ExpectMat(at1[2], model(head * spine_rest, p_head), "head");
  ExpectMat(at1[3], model(leg, p_leg), "leg");
}

}  // namespace
