#pragma once
// Hand-built skeletons in the conventions of the real captures, for tests that
// need a skeleton without parsing a file: CMU-like (zero-length helper joints),
// Bandai-like (every bone along its joint's local X, rest rotations), Mixamo-like
// (prefixed names, five fingers, eyes), a tail chain and a quadruped.
// Positions are given in model space (y up, a humanoid ~170 units tall times
// `scale`); SkeletonFrom turns them into local offsets.

#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "mocap/pose.h"
#include "mocap/skeleton.h"

namespace testsupport {

struct JointSpec {
  std::string name;
  int parent;           // index into the spec list, -1 for the root
  glm::vec3 model_pos;  // rest position in model space
};

struct BuiltSkeleton {
  mocap::Skeleton skeleton;
  std::vector<glm::mat4> model_from_joint;  // rest pose, #J
};

// local_x: give every joint a rest rotation whose X axis points at its first
// child (Bandai's convention); otherwise rotations are identity (CMU, Mixamo).
// end_site_length > 0 adds an end site of that length to every leaf, along the
// leaf's incoming bone.
inline BuiltSkeleton SkeletonFrom(const std::vector<JointSpec>& specs, bool local_x,
                                  float end_site_length) {
  BuiltSkeleton out;
  mocap::Skeleton& s = out.skeleton;
  const std::size_t n = specs.size();
  std::vector<glm::quat> model_rot(n, glm::quat(1, 0, 0, 0));
  for (std::size_t j = 0; j < n; ++j) {
    if (!local_x) continue;
    for (std::size_t c = j + 1; c < n; ++c) {
      const glm::vec3 d = specs[c].model_pos - specs[j].model_pos;
      if (specs[c].parent == static_cast<int>(j) && glm::length(d) > 0.0f) {
        model_rot[j] = glm::quat(glm::vec3(1, 0, 0), glm::normalize(d));
        break;
      }
    }
  }
  for (std::size_t j = 0; j < n; ++j) {
    const int p = specs[j].parent;
    s.names.push_back(specs[j].name);
    s.parents.push_back(static_cast<std::int16_t>(p));
    const glm::quat parent_rot = p >= 0 ? model_rot[static_cast<std::size_t>(p)] : glm::quat(1, 0, 0, 0);
    const glm::vec3 parent_pos = p >= 0 ? specs[static_cast<std::size_t>(p)].model_pos : glm::vec3(0);
    s.rest_translations.push_back(glm::inverse(parent_rot) * (specs[j].model_pos - parent_pos));
    s.rest_rotations.push_back(glm::inverse(parent_rot) * model_rot[j]);
    s.rest_scales.emplace_back(1.0f);
    s.channels.emplace_back();
  }
  if (end_site_length > 0.0f) {
    for (std::size_t j = 0; j < n; ++j) {
      bool leaf = true;
      for (std::size_t c = j + 1; c < n; ++c) leaf = leaf && specs[c].parent != static_cast<int>(j);
      const int p = specs[j].parent;
      if (!leaf || p < 0) continue;
      glm::vec3 d = specs[j].model_pos - specs[static_cast<std::size_t>(p)].model_pos;
      if (glm::length(d) == 0.0f) continue;
      d = end_site_length * glm::normalize(d);
      s.end_sites.push_back({static_cast<int>(j), glm::inverse(model_rot[j]) * d, "End Site"});
    }
  }
  std::vector<mocap::JointTransform> locals(n);
  mocap::RestPose(s, locals);
  out.model_from_joint.resize(n);
  (void)mocap::LocalToModelJob{.parents = s.parents, .locals = locals,
                               .model_from_joint = out.model_from_joint}
      .Run();
  return out;
}

// A humanoid in T-pose, y up, feet at y = 0, ~170 units tall. `helpers` adds
// CMU's zero-length joints (LHipJoint, LowerBack, Neck, shoulders, finger base);
// `fingers` adds five three-joint fingers per hand; `prefix` goes before names.
inline std::vector<JointSpec> Humanoid(float scale, bool helpers, bool fingers,
                                       const std::string& prefix) {
  std::vector<JointSpec> j;
  const auto add = [&](const std::string& name, int parent, glm::vec3 pos) {
    j.push_back({prefix + name, parent, pos * scale});
    return static_cast<int>(j.size()) - 1;
  };
  const int hips = add("Hips", -1, {0, 95, 0});
  for (int side = 0; side < 2; ++side) {
    const float x = side == 0 ? 1.0f : -1.0f;
    const std::string s = side == 0 ? "Left" : "Right";
    int p = hips;
    if (helpers) p = add(s + "HipJoint", p, {0, 95, 0});
    p = add(s + "UpLeg", p, {9 * x, 90, 0});
    p = add(s + "Leg", p, {9 * x, 50, 1});
    p = add(s + "Foot", p, {9 * x, 9, -2});
    add(s + "ToeBase", p, {9 * x, 2, 12});
  }
  int p = hips;
  if (helpers) p = add("LowerBack", p, {0, 95, 0});
  p = add("Spine", p, {0, 107, 0});
  const int chest = add("Spine1", p, {0, 125, 0});
  p = chest;
  if (helpers) p = add("Neck", p, {0, 125, 0});
  p = add("Neck1", p, {0, 143, 0});
  add("Head", p, {0, 152, 1});
  for (int side = 0; side < 2; ++side) {
    const float x = side == 0 ? 1.0f : -1.0f;
    const std::string s = side == 0 ? "Left" : "Right";
    p = chest;
    if (helpers) p = add(s + "Shoulder", p, {0, 125, 0});
    p = add(s + "Clavicle", p, {4 * x, 138, 0});
    p = add(s + "Arm", p, {17 * x, 140, 0});
    p = add(s + "ForeArm", p, {45 * x, 140, 0});
    const int hand = add(s + "Hand", p, {70 * x, 140, 0});
    if (fingers) {
      for (int f = 0; f < 5; ++f) {
        const float z = 3.0f - 1.5f * static_cast<float>(f);
        int q = add(s + "Finger" + std::to_string(f) + "_1", hand, {(f == 0 ? 73 : 79) * x, 139, z + (f == 0 ? 3 : 0)});
        q = add(s + "Finger" + std::to_string(f) + "_2", q, {(f == 0 ? 76 : 83) * x, 139, z + (f == 0 ? 4 : 0)});
        add(s + "Finger" + std::to_string(f) + "_3", q, {(f == 0 ? 78 : 86) * x, 139, z + (f == 0 ? 5 : 0)});
      }
    } else {
      if (helpers) p = add(s + "FingerBase", hand, {70 * x, 140, 0});
      else p = hand;
      add(s + "Fingers", p, {78 * x, 140, 0});
    }
  }
  return j;
}

// A chain of `n` joints along +x with a gentle curl, `length` long in total.
inline std::vector<JointSpec> Tail(int n, float length) {
  std::vector<JointSpec> j;
  for (int i = 0; i < n; ++i) {
    const float t = static_cast<float>(i) / static_cast<float>(std::max(n - 1, 1));
    j.push_back({"tail" + std::to_string(i), i - 1,
                 glm::vec3(length * t, 0.2f * length * t * t, 0.0f)});
  }
  return j;
}

// A dog-like quadruped, nose toward +z, y up, ~100 units long.
inline std::vector<JointSpec> Quadruped() {
  std::vector<JointSpec> j;
  const auto add = [&](const std::string& name, int parent, glm::vec3 pos) {
    j.push_back({name, parent, pos});
    return static_cast<int>(j.size()) - 1;
  };
  const int pelvis = add("pelvis", -1, {0, 60, 0});
  int p = add("spine0", pelvis, {0, 62, 15});
  p = add("spine1", p, {0, 63, 30});
  const int chest = add("chest", p, {0, 62, 42});
  p = add("neck", chest, {0, 72, 52});
  add("head", p, {0, 78, 62});
  for (int leg = 0; leg < 4; ++leg) {
    const float x = leg % 2 == 0 ? 8.0f : -8.0f;
    const float z = leg < 2 ? 0.0f : 42.0f;
    const int root = leg < 2 ? pelvis : chest;
    const std::string s = "leg" + std::to_string(leg);
    int q = add(s + "_hip", root, {x, 55, z});
    q = add(s + "_knee", q, {x, 35, z + 3});
    q = add(s + "_ankle", q, {x, 12, z - 2});
    add(s + "_paw", q, {x, 1, z + 4});
  }
  p = pelvis;
  for (int i = 1; i <= 5; ++i) p = add("tail" + std::to_string(i), p, {0, 60 + 1.5f * static_cast<float>(i), -7.0f * static_cast<float>(i)});
  return j;
}

}  // namespace testsupport
