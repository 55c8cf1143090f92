#pragma once
// Small BVH captures written for the tests of issue 27, as text: a humanoid
// whose rest pose and animated poses disagree on the up axis, and the body
// shapes the follow camera must keep in view (a quadruped walking with a
// horizontal spine, a person crawling). Lengths are in centimetres, the
// skeleton stands Y-up unless a case says otherwise.

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace testsupport {

struct BvhBone {
  std::string name;
  int parent = -1;        // index into the list, parents first; -1 = the root
  glm::vec3 offset{0.0f};
  glm::vec3 end{0.0f};    // end site offset for a leaf (zero: none)
};

// A HIERARCHY of `bones` (root with 6 channels Xposition Yposition Zposition
// Zrotation Xrotation Yrotation, others Zrotation Xrotation Yrotation) and the
// given frames (#F rows of 6 + 3 (#bones - 1) numbers) at 30 fps.
inline std::string WriteBvh(const std::vector<BvhBone>& bones,
                            const std::vector<std::vector<float>>& frames) {
  std::ostringstream out;
  out << "HIERARCHY\n";
  std::vector<std::vector<int>> children(bones.size());
  for (std::size_t i = 1; i < bones.size(); ++i) children[static_cast<std::size_t>(bones[i].parent)].push_back(static_cast<int>(i));
  const auto write = [&](const auto& self, int b, int depth) -> void {
    const std::string pad(static_cast<std::size_t>(2 * depth), ' ');
    const BvhBone& bone = bones[static_cast<std::size_t>(b)];
    out << pad << (b == 0 ? "ROOT " : "JOINT ") << bone.name << "\n" << pad << "{\n";
    out << pad << "  OFFSET " << bone.offset.x << " " << bone.offset.y << " " << bone.offset.z << "\n";
    out << pad << "  CHANNELS "
        << (b == 0 ? "6 Xposition Yposition Zposition Zrotation Xrotation Yrotation"
                   : "3 Zrotation Xrotation Yrotation")
        << "\n";
    for (int c : children[static_cast<std::size_t>(b)]) self(self, c, depth + 1);
    if (children[static_cast<std::size_t>(b)].empty()) {
      out << pad << "  End Site\n" << pad << "  {\n" << pad << "    OFFSET " << bone.end.x << " "
          << bone.end.y << " " << bone.end.z << "\n" << pad << "  }\n";
    }
    out << pad << "}\n";
  };
  write(write, 0, 0);
  out << "MOTION\nFrames: " << frames.size() << "\nFrame Time: 0.0333333\n";
  for (const std::vector<float>& row : frames) {
    for (std::size_t i = 0; i < row.size(); ++i) out << (i ? " " : "") << row[i];
    out << "\n";
  }
  return out.str();
}

// A person standing Y-up, facing +Z: hips, spine, neck, head, arms in a
// T-pose along X, legs down, feet forward (+Z). Joint indices are stable:
// 0 Hips, 1 Spine, 2 Chest, 3 Neck, 4 Head, 5/9 L/R shoulder, 6/10 arm,
// 7/11 forearm, 8/12 hand, 13/16 L/R up leg, 14/17 leg, 15/18 foot.
inline std::vector<BvhBone> HumanoidBones() {
  return {
      {"Hips", -1, {0, 95, 0}, {}},
      {"Spine", 0, {0, 10, 0}, {}},
      {"Chest", 1, {0, 20, 0}, {}},
      {"Neck", 2, {0, 25, 0}, {}},
      {"Head", 3, {0, 10, 0}, {0, 18, 0}},
      {"LeftShoulder", 2, {5, 20, 0}, {}},
      {"LeftArm", 5, {12, 0, 0}, {}},
      {"LeftForeArm", 6, {28, 0, 0}, {}},
      {"LeftHand", 7, {25, 0, 0}, {8, 0, 0}},
      {"RightShoulder", 2, {-5, 20, 0}, {}},
      {"RightArm", 9, {-12, 0, 0}, {}},
      {"RightForeArm", 10, {-28, 0, 0}, {}},
      {"RightHand", 11, {-25, 0, 0}, {-8, 0, 0}},
      {"LeftUpLeg", 0, {9, -5, 0}, {}},
      {"LeftLeg", 13, {0, -43, 0}, {}},
      {"LeftFoot", 14, {0, -42, 0}, {0, -4, 14}},
      {"RightUpLeg", 0, {-9, -5, 0}, {}},
      {"RightLeg", 16, {0, -43, 0}, {}},
      {"RightFoot", 17, {0, -42, 0}, {0, -4, 14}},
  };
}

// (x, y, z) of a Y-up vector written Z-up (forward -Y): (x, -z, y).
inline glm::vec3 YUpToZUp(const glm::vec3& v) { return {v.x, -v.z, v.y}; }

// The humanoid walking in place: legs and arms swing about X. `z_up_offsets`
// writes every OFFSET Z-up; `root_x_deg` is added to the root's Xrotation in
// every frame (-90 stands Z-up offsets Y-up; +90 lays Y-up offsets Z-up).
inline std::string HumanoidWalkBvh(bool z_up_offsets, float root_x_deg, int num_frames = 40) {
  std::vector<BvhBone> bones = HumanoidBones();
  if (z_up_offsets) {
    for (BvhBone& b : bones) {
      b.offset = YUpToZUp(b.offset);
      b.end = YUpToZUp(b.end);
    }
  }
  const bool poses_z_up = z_up_offsets ? root_x_deg == 0.0f : root_x_deg > 0.0f;
  std::vector<std::vector<float>> frames;
  for (int f = 0; f < num_frames; ++f) {
    const float phase = 2.0f * 3.14159265f * static_cast<float>(f) / 30.0f;
    std::vector<float> row(6 + 3 * (bones.size() - 1), 0.0f);
    // The root's position channels are in the axes the poses stand in.
    const glm::vec3 root_y_up(0.0f, 95.0f, 3.0f * static_cast<float>(f));
    const glm::vec3 root = poses_z_up ? YUpToZUp(root_y_up) : root_y_up;
    row[0] = root.x;
    row[1] = root.y;
    row[2] = root.z;
    row[4] = root_x_deg;
    const float swing = 25.0f * std::sin(phase);
    // Xrotation is the second of each joint's three channels.
    const auto set_x = [&row](int joint, float deg) { row[static_cast<std::size_t>(6 + 3 * (joint - 1) + 1)] = deg; };
    set_x(13, swing);
    set_x(16, -swing);
    set_x(14, 20.0f + 20.0f * std::sin(phase + 1.0f));
    set_x(17, 20.0f - 20.0f * std::sin(phase + 1.0f));
    frames.push_back(row);
  }
  return WriteBvh(bones, frames);
}

// A dog-sized quadruped, Y-up, spine horizontal along +Z, trotting forward at
// `speed_cm_s` (400: a fast run) with its legs swinging +-30 degrees.
inline std::string QuadrupedRunBvh(float speed_cm_s = 400.0f, int num_frames = 90) {
  const std::vector<BvhBone> bones = {
      {"Pelvis", -1, {0, 55, 0}, {}},
      {"Spine1", 0, {0, 2, 15}, {}},
      {"Spine2", 1, {0, 0, 15}, {}},
      {"Chest", 2, {0, 0, 15}, {}},
      {"Neck", 3, {0, 8, 10}, {}},
      {"Head", 4, {0, 10, 8}, {0, 0, 15}},
      {"Tail1", 0, {0, 3, -8}, {}},
      {"Tail2", 6, {0, 0, -12}, {0, -5, -15}},
      {"LHip", 0, {8, -5, 0}, {}},
      {"LKnee", 8, {0, -20, 5}, {}},
      {"LHock", 9, {0, -15, -5}, {}},
      {"LHindPaw", 10, {0, -12, 0}, {0, -2, 6}},
      {"RHip", 0, {-8, -5, 0}, {}},
      {"RKnee", 12, {0, -20, 5}, {}},
      {"RHock", 13, {0, -15, -5}, {}},
      {"RHindPaw", 14, {0, -12, 0}, {0, -2, 6}},
      {"LShoulder", 3, {8, -5, 5}, {}},
      {"LElbow", 16, {0, -20, -3}, {}},
      {"LWrist", 17, {0, -20, 3}, {}},
      {"LForePaw", 18, {0, -8, 0}, {0, -2, 6}},
      {"RShoulder", 3, {-8, -5, 5}, {}},
      {"RElbow", 20, {0, -20, -3}, {}},
      {"RWrist", 21, {0, -20, 3}, {}},
      {"RForePaw", 22, {0, -8, 0}, {0, -2, 6}},
  };
  std::vector<std::vector<float>> frames;
  for (int f = 0; f < num_frames; ++f) {
    const float t = static_cast<float>(f) / 30.0f;
    const float phase = 2.0f * 3.14159265f * 2.5f * t;  // 2.5 strides a second
    std::vector<float> row(6 + 3 * (bones.size() - 1), 0.0f);
    row[1] = 55.0f + 3.0f * std::sin(2.0f * phase);
    row[2] = speed_cm_s * t;
    const auto set_x = [&row](int joint, float deg) { row[static_cast<std::size_t>(6 + 3 * (joint - 1) + 1)] = deg; };
    const float swing = 30.0f * std::sin(phase);
    set_x(8, swing);
    set_x(12, -swing);
    set_x(16, -swing);
    set_x(20, swing);
    set_x(6, 15.0f * std::sin(phase));  // the tail wags up and down
    frames.push_back(row);
  }
  return WriteBvh(bones, frames);
}

// The humanoid crawling on hands and knees along +Z at `speed_cm_s`: the root
// tips the torso forward (+90 degrees about X), thighs hang down, shins lie
// back along the floor, arms reach down; limbs swing +-15 degrees.
inline std::string HumanoidCrawlBvh(float speed_cm_s = 60.0f, int num_frames = 90) {
  const std::vector<BvhBone> bones = HumanoidBones();
  std::vector<std::vector<float>> frames;
  for (int f = 0; f < num_frames; ++f) {
    const float t = static_cast<float>(f) / 30.0f;
    const float phase = 2.0f * 3.14159265f * t;
    std::vector<float> row(6 + 3 * (bones.size() - 1), 0.0f);
    row[1] = 60.0f;
    row[2] = speed_cm_s * t;
    row[4] = 90.0f;  // root Xrotation: the spine points forward, the chest faces down
    const auto set = [&row](int joint, int channel, float deg) {
      row[static_cast<std::size_t>(6 + 3 * (joint - 1) + channel)] = deg;  // 0 Z, 1 X, 2 Y
    };
    const float swing = 15.0f * std::sin(phase);
    set(13, 1, -90.0f + swing);  // thighs down
    set(16, 1, -90.0f - swing);
    set(14, 1, 90.0f);           // shins back along the floor
    set(17, 1, 90.0f);
    set(6, 2, -90.0f);           // arms from the T-pose to down
    set(10, 2, 90.0f);
    set(6, 1, swing);
    set(10, 1, -swing);
    frames.push_back(row);
  }
  return WriteBvh(bones, frames);
}

}  // namespace testsupport
