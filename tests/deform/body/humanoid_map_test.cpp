// Humanoid skeletons matched by topology (deform/body/humanoid_map.h), on synthetic
// BVH skeletons written by the test: renamed and reordered joints map back to
// their originals; left and right come from the feet, not the names, unless the
// feet give no direction; a T-pose capture on an A-pose skeleton (and the
// reverse) puts the hands where the capture's are, checked on joint positions.

#include "deform/body/humanoid_map.h"

#include <cmath>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>

#include "mocap/bvh_reader.h"
#include "mocap/pose.h"
#include "mocap/retarget.h"

namespace {

// One joint of a synthetic humanoid, in centimetres; left is +X, forward +Z, up +Y.
struct J {
  std::string name;
  glm::vec3 offset;
  std::vector<J> kids;
  glm::vec3 end{0.0f};  // end site offset of a leaf
};

struct BodyOptions {
  float arm_down_deg = 0.0f;  // 0: T-pose, 45: A-pose
  bool feet = true;           // toes pointing forward; else legs end straight down
  bool reorder = false;       // legs before the spine, right before left
  std::map<std::string, std::string> rename;  // original name -> name in the file
};

J Arm(float side, float down_deg) {
  const float a = glm::radians(down_deg);
  const glm::vec3 d(side * std::cos(a), -std::sin(a), 0.0f);
  const std::string s = side > 0 ? "Left" : "Right";
  return {s + "Shoulder", {side * 4, 15, 0},
          {{s + "Arm", {side * 12, 0, 0},
            {{s + "ForeArm", 28.0f * d, {{s + "Hand", 26.0f * d, {}, 8.0f * d}}}}}}};
}

J Leg(float side, bool feet) {
  const std::string s = side > 0 ? "Left" : "Right";
  J foot{s + "Foot", {0, -42, 0}, {}, {0, -3, 0}};
  if (feet) foot = {s + "Foot", {0, -42, 0}, {{s + "Toe", {0, -5, 12}, {}, {0, 0, 6}}}};
  return {s + "UpLeg", {side * 9, -5, 0}, {{s + "Leg", {0, -45, 0}, {foot}}}};
}

J Body(const BodyOptions& o) {
  J chest{"Chest", {0, 15, 0},
          {{"Neck", {0, 20, 0}, {{"Head", {0, 10, 0}, {}, {0, 12, 0}}}},
           Arm(1, o.arm_down_deg), Arm(-1, o.arm_down_deg)}};
  if (o.reorder) std::swap(chest.kids[1], chest.kids[2]);
  J hips{"Hips", {0, 100, 0},
         {{"Spine", {0, 10, 0}, {chest}}, Leg(1, o.feet), Leg(-1, o.feet)}};
  if (o.reorder) hips.kids = {hips.kids[2], hips.kids[1], hips.kids[0]};
  return hips;
}

void Write(const J& j, const BodyOptions& o, int depth, std::string& out, std::vector<std::string>& order) {
  const std::string pad(static_cast<std::size_t>(depth), ' ');
  const auto it = o.rename.find(j.name);
  const std::string name = it == o.rename.end() ? j.name : it->second;
  out += pad + (depth == 0 ? "ROOT " : "JOINT ") + name + "\n" + pad + "{\n";
  out += pad + " OFFSET " + std::to_string(j.offset.x) + " " + std::to_string(j.offset.y) + " " +
         std::to_string(j.offset.z) + "\n";
  out += pad + (depth == 0 ? " CHANNELS 6 Xposition Yposition Zposition " : " CHANNELS 3 ") +
         "Zrotation Xrotation Yrotation\n";
  order.push_back(j.name);
  for (const J& k : j.kids) Write(k, o, depth + 1, out, order);
  if (j.kids.empty()) {
    out += pad + " End Site\n" + pad + " {\n" + pad + "  OFFSET " + std::to_string(j.end.x) + " " +
           std::to_string(j.end.y) + " " + std::to_string(j.end.z) + "\n" + pad + " }\n";
  }
  out += pad + "}\n";
}

// Frames as Z rotations (degrees) per original joint name; the hips stay at 100 cm.
using Frame = std::map<std::string, float>;

mocap::BvhFile Parse(const BodyOptions& o, const std::vector<Frame>& frames) {
  std::string text = "HIERARCHY\n";
  std::vector<std::string> order;
  Write(Body(o), o, 0, text, order);
  std::ostringstream motion;  // (a stream: GCC 12 warns falsely on these += chains)
  motion << "MOTION\nFrames: " << frames.size() << "\nFrame Time: 0.1\n";
  for (const Frame& f : frames) {
    motion << "0 100 0";
    for (const std::string& name : order) {
      const auto it = f.find(name);
      motion << " " << (it == f.end() ? 0.0f : it->second) << " 0 0";
    }
    motion << "\n";
  }
  text += motion.str();
  auto file = mocap::ParseBvh(text, "synthetic.bvh", {});
  EXPECT_TRUE(file.ok()) << file.error().ToString();
  return file.ok() ? std::move(file).value() : mocap::BvhFile{};
}

base::Result<deform::HumanoidMatch> Match(const mocap::BvhFile& target,
                                          const mocap::BvhFile& source) {
  return deform::MatchHumanoids(target.skeleton, source.skeleton, source.motion, {}, "target.bvh",
                                "source.bvh", "");
}

const char* const kNames[] = {"Hips",         "Spine",       "Chest",        "Neck",
                              "Head",         "LeftShoulder", "LeftArm",     "LeftForeArm",
                              "LeftHand",     "RightShoulder", "RightArm",   "RightForeArm",
                              "RightHand",    "LeftUpLeg",    "LeftLeg",     "LeftFoot",
                              "LeftToe",      "RightUpLeg",   "RightLeg",    "RightFoot",
                              "RightToe"};

// (A stream: GCC 12 warns falsely on "text" + std::to_string(k) here.)
std::string Numbered(const char* prefix, int k) {
  std::ostringstream s;
  s << prefix << k;
  return s.str();
}

std::string SourceOf(const mocap::BvhFile& target, const mocap::BvhFile& source,
                     const deform::HumanoidMatch& m, const std::string& target_joint) {
  const int j = target.skeleton.FindJoint(target_joint);
  EXPECT_GE(j, 0) << target_joint;
  if (j < 0) return "?";
  const int b = m.plan.source_of_target[static_cast<std::size_t>(j)];
  return b < 0 ? "(rest)" : source.skeleton.names[static_cast<std::size_t>(b)];
}

TEST(HumanoidMap, RenamedAndReorderedJointsMapToTheirOriginals) {
  BodyOptions renamed;
  renamed.reorder = true;
  int k = 0;
  for (const char* n : kNames) renamed.rename[n] = Numbered("bone", 37 - 3 * k++);
  const mocap::BvhFile source = Parse({}, {{}});
  const mocap::BvhFile target = Parse(renamed, {{}});
  auto m = Match(target, source);
  ASSERT_TRUE(m.ok()) << m.error().ToString();
  EXPECT_EQ(m->method, "topology");
  EXPECT_EQ(m->target_sides, "geometry");
  for (const char* n : kNames) {
    EXPECT_EQ(SourceOf(target, source, *m, renamed.rename[n]), n) << "target joint " << n;
  }
  EXPECT_NEAR(m->plan.translation_scale, 1.0f, 1e-5f);
}

TEST(HumanoidMap, SidesComeFromTheFeetNotTheNames) {
  BodyOptions swapped;  // the +X limbs are named Right..., the -X ones Left...
  for (const char* n : kNames) {
    std::string s = n;
    if (s.rfind("Left", 0) == 0) swapped.rename[s] = "Right" + s.substr(4);
    if (s.rfind("Right", 0) == 0) swapped.rename[s] = "Left" + s.substr(5);
  }
  const mocap::BvhFile target = Parse({}, {{}});
  const mocap::BvhFile source = Parse(swapped, {{}});
  auto m = Match(target, source);
  ASSERT_TRUE(m.ok()) << m.error().ToString();
  EXPECT_EQ(m->source_sides, "geometry");
  EXPECT_EQ(SourceOf(target, source, *m, "LeftArm"), "RightArm");
  EXPECT_EQ(SourceOf(target, source, *m, "LeftUpLeg"), "RightUpLeg");
  EXPECT_EQ(SourceOf(target, source, *m, "RightHand"), "LeftHand");
}

TEST(HumanoidMap, WithoutFeetTheNamesDecideThenTheOrderIsAGuess) {
  BodyOptions no_feet;
  no_feet.feet = false;
  no_feet.reorder = true;  // right limbs first in the file: the order alone would be wrong
  const mocap::BvhFile target = Parse({}, {{}});
  const mocap::BvhFile named = Parse(no_feet, {{}});
  auto m = Match(target, named);
  ASSERT_TRUE(m.ok()) << m.error().ToString();
  EXPECT_EQ(m->source_sides, "names");
  EXPECT_EQ(SourceOf(target, named, *m, "LeftArm"), "LeftArm");
  EXPECT_EQ(SourceOf(target, named, *m, "LeftLeg"), "LeftLeg");
  EXPECT_TRUE(m->warnings.empty());

  BodyOptions anonymous = no_feet;
  int k = 0;
  for (const char* n : kNames) anonymous.rename[n] = Numbered("j", k++);
  const mocap::BvhFile guessed = Parse(anonymous, {{}});
  auto g = Match(target, guessed);
  ASSERT_TRUE(g.ok()) << g.error().ToString();
  EXPECT_EQ(g->source_sides, "guess");
  ASSERT_EQ(g->warnings.size(), 1u);
  EXPECT_NE(g->warnings[0].message.find("--joint-map"), std::string::npos);
}

TEST(HumanoidMap, NamesAreUsedWhenASkeletonIsNoHumanoid) {
  // A chain with one leg: no mirror pairs, so the names match.
  auto file = mocap::ParseBvh(
      "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition Zposition "
      "Zrotation Xrotation Yrotation\n JOINT LeftUpLeg\n {\n  OFFSET 10 -50 0\n  CHANNELS 3 "
      "Zrotation Xrotation Yrotation\n  End Site\n  {\n   OFFSET 0 -50 0\n  }\n }\n}\nMOTION\n"
      "Frames: 1\nFrame Time: 0.1\n0 100 0 0 0 0 0 0 0\n",
      "leg.bvh", {});
  ASSERT_TRUE(file.ok()) << file.error().ToString();
  const mocap::BvhFile body = Parse({}, {{}});
  auto m = deform::MatchHumanoids(file->skeleton, body.skeleton, body.motion, {}, "leg.bvh",
                                  "body.bvh", "");
  ASSERT_TRUE(m.ok()) << m.error().ToString();
  EXPECT_EQ(m->method, "names");
  EXPECT_EQ(m->plan.source_of_target, (std::vector<int>{0, body.skeleton.FindJoint("LeftUpLeg")}));
}

TEST(HumanoidMap, JointMapOverridesAndNamesUnknownJoints) {
  const mocap::BvhFile body = Parse({}, {{}});
  auto m = deform::MatchHumanoids(body.skeleton, body.skeleton, body.motion,
                                  {{"LeftHand", ""}, {"RightHand", "RightForeArm"}}, "a.glb",
                                  "b.bvh", "map.json");
  ASSERT_TRUE(m.ok()) << m.error().ToString();
  EXPECT_EQ(SourceOf(body, body, *m, "LeftHand"), "(rest)");
  EXPECT_EQ(SourceOf(body, body, *m, "RightHand"), "RightForeArm");
  EXPECT_EQ(SourceOf(body, body, *m, "LeftArm"), "LeftArm");

  auto bad = deform::MatchHumanoids(body.skeleton, body.skeleton, body.motion,
                                    {{"LeftHand", "NoSuchJoint"}}, "a.glb", "b.bvh", "map.json");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().loc.file, "map.json");
  EXPECT_NE(bad.error().message.find("\"NoSuchJoint\""), std::string::npos) << bad.error().ToString();
}

// Model-space joint positions of the retargeted target at frame f.
std::vector<glm::vec3> Retargeted(const mocap::BvhFile& target, const mocap::BvhFile& source, int f) {
  auto m = Match(target, source);
  EXPECT_TRUE(m.ok()) << m.error().ToString();
  if (!m.ok()) return {};
  auto r = mocap::ApplyRetargetPlan(target.skeleton, source.skeleton, source.motion, m->plan, "source.bvh");
  EXPECT_TRUE(r.ok()) << r.error().ToString();
  if (!r.ok()) return {};
  std::vector<mocap::JointTransform> locals(static_cast<std::size_t>(r->skeleton.num_joints()));
  std::vector<glm::mat4> model(locals.size());
  EXPECT_TRUE((mocap::LocalPoseJob{&r->skeleton, r->motion.frame(f), locals}.Run()));
  EXPECT_TRUE((mocap::LocalToModelJob{.parents = r->skeleton.parents, .locals = locals,
                                      .model_from_joint = model}.Run()));
  std::vector<glm::vec3> out;
  for (const glm::mat4& mm : model) out.emplace_back(mm[3]);
  return out;
}

glm::vec3 At(const mocap::BvhFile& f, const std::vector<glm::vec3>& pos, const char* name) {
  const int j = f.skeleton.FindJoint(name);
  return j >= 0 && static_cast<std::size_t>(j) < pos.size() ? pos[static_cast<std::size_t>(j)] : glm::vec3(NAN);
}

constexpr float kArm = 28.0f + 26.0f;  // shoulder to wrist

TEST(HumanoidMap, TPoseCaptureOnAnAPoseBodyPutsTheHandsWhereTheCapturesAre) {
  BodyOptions a_pose;
  a_pose.arm_down_deg = 45.0f;
  const mocap::BvhFile target = Parse(a_pose, {{}});
  // Frame 0: the capture's T-pose; frame 1: both arms hang down.
  const mocap::BvhFile source = Parse({}, {{}, {{"LeftArm", -90.0f}, {"RightArm", 90.0f}}});
  const std::vector<glm::vec3> t = Retargeted(target, source, 0);
  const std::vector<glm::vec3> down = Retargeted(target, source, 1);
  for (const char* side : {"Left", "Right"}) {
    const std::string arm = std::string(side) + "Arm", hand = std::string(side) + "Hand";
    const glm::vec3 shoulder0 = At(target, t, arm.c_str()), hand0 = At(target, t, hand.c_str());
    EXPECT_NEAR(hand0.y, shoulder0.y, 1e-3f * kArm) << side << ": T-pose arm horizontal";
    EXPECT_NEAR(std::abs(hand0.x - shoulder0.x), kArm, 1e-3f * kArm) << side;
    const glm::vec3 shoulder1 = At(target, down, arm.c_str()), hand1 = At(target, down, hand.c_str());
    EXPECT_NEAR(hand1.x, shoulder1.x, 1e-3f * kArm) << side << ": hand straight below the shoulder";
    EXPECT_NEAR(hand1.z, shoulder1.z, 1e-3f * kArm) << side;
    EXPECT_NEAR(shoulder1.y - hand1.y, kArm, 1e-3f * kArm) << side;
  }
}

TEST(HumanoidMap, APoseCaptureOnATPoseBodyKeepsItsArmAngles) {
  BodyOptions a_pose;
  a_pose.arm_down_deg = 45.0f;
  const mocap::BvhFile target = Parse({}, {{}});
  // Frame 0: the capture's A-pose; frame 1: arms raised level (45 deg up).
  const mocap::BvhFile source = Parse(a_pose, {{}, {{"LeftArm", 45.0f}, {"RightArm", -45.0f}}});
  const std::vector<glm::vec3> a = Retargeted(target, source, 0);
  const std::vector<glm::vec3> level = Retargeted(target, source, 1);
  const float leg = kArm / std::sqrt(2.0f);
  for (const char* side : {"Left", "Right"}) {
    const std::string arm = std::string(side) + "Arm", hand = std::string(side) + "Hand";
    const glm::vec3 s0 = At(target, a, arm.c_str()), h0 = At(target, a, hand.c_str());
    EXPECT_NEAR(s0.y - h0.y, leg, 1e-3f * kArm) << side << ": 45 deg down at the capture's rest";
    EXPECT_NEAR(std::abs(h0.x - s0.x), leg, 1e-3f * kArm) << side;
    const glm::vec3 s1 = At(target, level, arm.c_str()), h1 = At(target, level, hand.c_str());
    EXPECT_NEAR(h1.y, s1.y, 1e-3f * kArm) << side << ": level";
  }
}

}  // namespace
