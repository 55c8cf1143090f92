#pragma once
// Test-only arm: a 3-joint chain (upper arm, forearm, hand) along +x with a tube mesh of
// vertex rings around the bones, smoothstep SSD weights across the elbow and the wrist,
// and tiny reference SSD and DQS skinning to compare SWD with. Poses are rigid forward
// kinematics from per-bone rotations dQ (relative to bind, model space).

#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "deform/global/artifact_metrics.h"
#include "deform/mesh.h"
#include "deform/global/swd_job.h"
#include "deform/global/sweep.h"

namespace testfixture {

inline constexpr int kArmBones = 3;

// Dimensions of a 3-bone limb along +x (model units). Lengths are whole numbers so that
// rings (every 1/per_unit units) fall exactly on the middle and end joints.
struct LimbShape {
  float upper_length;       // upper arm / thigh
  float lower_length;       // forearm / shin
  float end_length;         // hand / foot
  float radius_at_root;     // tube radius at x = 0
  float radius_taper;       // radius loss per unit of x
  float middle_blend;       // SSD weights blend over x in [J1 - this, J1 + this]
  float end_blend;          // and over [J2 - this, J2 + this]
};
inline constexpr LimbShape kArmShape{30, 25, 10, 4.0f, 0.03f, 5.0f, 2.0f};
inline constexpr LimbShape kLegShape{45, 42, 15, 7.0f, 0.045f, 7.0f, 3.0f};
inline constexpr float kArmLength = 65.0f;  // kArmShape's total length

inline float Smooth(float x) {
  const float y = glm::clamp(x, 0.0f, 1.0f);
  return y * y * (3.0f - 2.0f * y);
}

struct Arm {
  LimbShape shape;
  std::array<glm::vec3, kArmBones + 1> joint_rest;  // J_0..J_3 bind positions
  deform::Mesh mesh;                                // rings of `segments` vertices
  deform::SkinWeights weights;                      // 4 influences over joints 0..2
  std::vector<std::vector<std::uint32_t>> rings;    // vertex indices of each ring
  std::vector<float> ring_x;                        // x of each ring (on the bone axis)
  int elbow_ring = 0;                               // the ring at the middle joint J_1
  float length() const { return shape.upper_length + shape.lower_length + shape.end_length; }
};

// A limb tube with `per_unit` rings per model unit (triangles wound counter-clockwise
// seen from outside).
inline Arm MakeLimb(const LimbShape& shape, int segments, int per_unit) {
  Arm arm;
  arm.shape = shape;
  const float j1 = shape.upper_length, j2 = j1 + shape.lower_length;
  arm.joint_rest = {glm::vec3(0.0f), glm::vec3(j1, 0, 0), glm::vec3(j2, 0, 0),
                    glm::vec3(arm.length(), 0, 0)};
  const int num_rings = static_cast<int>(std::lround(arm.length())) * per_unit + 1;
  arm.weights.influences = 4;
  for (int r = 0; r < num_rings; ++r) {
    const float x = static_cast<float>(r) / static_cast<float>(per_unit);
    if (r == static_cast<int>(std::lround(j1)) * per_unit) arm.elbow_ring = r;
    arm.ring_x.push_back(x);
    std::vector<std::uint32_t> ring;
    const float s = Smooth((x - (j1 - shape.middle_blend)) / (2 * shape.middle_blend));
    const float t = Smooth((x - (j2 - shape.end_blend)) / (2 * shape.end_blend));
    const float radius = shape.radius_at_root - shape.radius_taper * x;
    for (int i = 0; i < segments; ++i) {
      const float angle = 6.2831853f * static_cast<float>(i) / static_cast<float>(segments);
      const glm::vec3 radial(0.0f, std::cos(angle), std::sin(angle));
      ring.push_back(static_cast<std::uint32_t>(arm.mesh.positions.size()));
      arm.mesh.positions.push_back(glm::vec3(x, 0, 0) + radius * radial);
      arm.mesh.normals.push_back(radial);
      const std::array<float, 4> w = {1.0f - s, s * (1.0f - t), s * t, 0.0f};
      for (int j = 0; j < 4; ++j) {
        arm.weights.joints.push_back(static_cast<std::uint16_t>(j < 3 ? j : 0));
        arm.weights.weights.push_back(w[static_cast<std::size_t>(j)]);
      }
    }
    arm.rings.push_back(ring);
  }
  for (int r = 0; r + 1 < num_rings; ++r) {
    for (int i = 0; i < segments; ++i) {
      const auto& a = arm.rings[static_cast<std::size_t>(r)];
      const auto& b = arm.rings[static_cast<std::size_t>(r + 1)];
      const auto i1 = static_cast<std::size_t>((i + 1) % segments);
      const auto i0 = static_cast<std::size_t>(i);
      arm.mesh.triangles.emplace_back(a[i0], b[i1], b[i0]);
      arm.mesh.triangles.emplace_back(a[i0], a[i1], b[i1]);
    }
  }
  return arm;
}

inline Arm MakeArm(int segments, int per_unit) { return MakeLimb(kArmShape, segments, per_unit); }

// The arm's sweep chain spec: bones 0..2 move with joints 0..2; the elbow spreads its
// twist downstream (along the forearm), the wrist upstream (forearm pronation).
inline deform::SweepChainSpec ArmChainSpec(const Arm& arm) {
  deform::SweepChainSpec spec;
  spec.joints = {0, 1, 2};
  spec.rest_points.assign(arm.joint_rest.begin(), arm.joint_rest.end());
  spec.skin_radii.assign(kArmBones + 1, 0.0f);
  for (int k = 1; k < kArmBones; ++k) {
    spec.skin_radii[static_cast<std::size_t>(k)] =
        static_cast<float>(deform::SkinRadiusNearJoint(spec, k, arm.mesh.positions));
  }
  spec.twist_spread = {deform::TwistSpread::kDownstream, deform::TwistSpread::kDownstream,
                       deform::TwistSpread::kUpstream, deform::TwistSpread::kDownstream};
  return spec;
}

// A pose of the arm: rigid FK from J_0' = root and per-bone rotations.
struct ArmPose {
  std::array<glm::quat, kArmBones> rotations;         // dQ_k, relative to bind
  std::array<glm::vec3, kArmBones + 1> joints;        // J_k' current
  std::array<glm::vec3, kArmBones> translations;      // T_k p = dQ_k p + translations[k]
};

inline ArmPose MakePose(const Arm& arm, const std::array<glm::quat, kArmBones>& rotations,
                        const glm::vec3& root) {
  ArmPose pose;
  pose.rotations = rotations;
  pose.joints[0] = root;
  for (std::size_t k = 0; k < kArmBones; ++k) {
    pose.joints[k + 1] = pose.joints[k] + rotations[k] * (arm.joint_rest[k + 1] - arm.joint_rest[k]);
    pose.translations[k] = pose.joints[k] - rotations[k] * arm.joint_rest[k];
  }
  return pose;
}

// Elbow bent by `deg` about +z (the inner elbow is on the +y side).
inline ArmPose BendPose(const Arm& arm, float deg) {
  const glm::quat q = glm::angleAxis(glm::radians(deg), glm::vec3(0, 0, 1));
  return MakePose(arm, {glm::quat(1, 0, 0, 0), q, q}, arm.joint_rest[0]);
}

// Forearm (and hand with it) twisted by `deg` about its own axis at the elbow.
inline ArmPose ElbowTwistPose(const Arm& arm, float deg) {
  const glm::quat q = glm::angleAxis(glm::radians(deg), glm::vec3(1, 0, 0));
  return MakePose(arm, {glm::quat(1, 0, 0, 0), q, q}, arm.joint_rest[0]);
}

// Hand twisted by `deg` about the forearm axis (pronation).
inline ArmPose WristTwistPose(const Arm& arm, float deg) {
  const glm::quat q = glm::angleAxis(glm::radians(deg), glm::vec3(1, 0, 0));
  return MakePose(arm, {glm::quat(1, 0, 0, 0), glm::quat(1, 0, 0, 0), q}, arm.joint_rest[0]);
}

// Reference SSD: p = sum_b w_b T_b p0.
inline std::vector<glm::vec3> SkinSsd(const Arm& arm, const ArmPose& pose) {
  std::vector<glm::vec3> out(arm.mesh.positions.size());
  for (std::size_t v = 0; v < out.size(); ++v) {
    glm::vec3 p(0.0f);
    for (std::size_t i = 0; i < 4; ++i) {
      const std::size_t b = arm.weights.joints[4 * v + i];
      p += arm.weights.weights[4 * v + i] *
           (pose.rotations[b] * arm.mesh.positions[v] + pose.translations[b]);
    }
    out[v] = p;
  }
  return out;
}

// Reference DQS: blend unit dual quaternions (real q, dual 0.5 (0,t) q) with sign
// alignment to the most-weighted one, divide by |real|, apply.
inline std::vector<glm::vec3> SkinDqs(const Arm& arm, const ArmPose& pose) {
  std::vector<glm::vec3> out(arm.mesh.positions.size());
  for (std::size_t v = 0; v < out.size(); ++v) {
    std::size_t major = 0;
    for (std::size_t i = 1; i < 4; ++i) {
      if (arm.weights.weights[4 * v + i] > arm.weights.weights[4 * v + major]) major = i;
    }
    const glm::quat pivot = pose.rotations[arm.weights.joints[4 * v + major]];
    glm::quat real(0, 0, 0, 0), dual(0, 0, 0, 0);
    for (std::size_t i = 0; i < 4; ++i) {
      const std::size_t b = arm.weights.joints[4 * v + i];
      float w = arm.weights.weights[4 * v + i];
      if (glm::dot(pose.rotations[b], pivot) < 0.0f) w = -w;
      const glm::quat q = pose.rotations[b];
      const glm::vec3 t = pose.translations[b];
      const glm::quat d = 0.5f * (glm::quat(0, t.x, t.y, t.z) * q);
      real = real + w * q;
      dual = dual + w * d;
    }
    const float norm = glm::length(real);
    real = real / norm;
    dual = dual / norm;
    const glm::quat t = 2.0f * (dual * glm::conjugate(real));
    out[v] = real * arm.mesh.positions[v] + glm::vec3(t.x, t.y, t.z);
  }
  return out;
}

// The elbow ring with its rest and posed bisector planes.
inline deform::ArtifactRing ElbowRing(const Arm& arm, const ArmPose& pose,
                                      std::vector<std::uint32_t> vertices) {
  const glm::vec3 a0 = glm::normalize(arm.joint_rest[1] - arm.joint_rest[0]);
  const glm::vec3 a1 = glm::normalize(arm.joint_rest[2] - arm.joint_rest[1]);
  deform::ArtifactRing ring;
  ring.vertices = std::move(vertices);
  ring.rest_plane = deform::BisectorPlane(arm.joint_rest[1], a0, a1);
  ring.plane = deform::BisectorPlane(pose.joints[1], pose.rotations[0] * a0,
                                     pose.rotations[1] * a1);
  return ring;
}

// The tube's triangles between rings r0 < r1 and those two rings as caps (a closed
// section for CappedVolume / VolumeFigure).
struct Section {
  std::vector<glm::uvec3> triangles;
  std::vector<std::vector<std::uint32_t>> caps;
};
inline Section SectionBetween(const Arm& arm, std::size_t r0, std::size_t r1) {
  Section section;
  const std::size_t per_gap = 2 * arm.rings[0].size();  // triangles between two rings
  section.triangles.assign(arm.mesh.triangles.begin() + static_cast<std::ptrdiff_t>(per_gap * r0),
                           arm.mesh.triangles.begin() + static_cast<std::ptrdiff_t>(per_gap * r1));
  section.caps = {arm.rings[r0], arm.rings[r1]};
  return section;
}

// The section within `half_length` units of the middle joint.
inline Section SectionAroundElbow(const Arm& arm, float half_length) {
  const auto per_unit = static_cast<std::size_t>(arm.elbow_ring) /
                        static_cast<std::size_t>(std::lround(arm.shape.upper_length));
  const auto d = static_cast<std::size_t>(std::lround(half_length)) * per_unit;
  const auto elbow = static_cast<std::size_t>(arm.elbow_ring);
  return SectionBetween(arm, elbow - d, elbow + d);
}

// Rings along the forearm (from the start of the SSD elbow blend to the wrist), each
// projected on the plane through its axis point normal to the bone it lies on.
inline std::vector<deform::ArtifactRing> ForearmRings(const Arm& arm, const ArmPose& pose) {
  std::vector<deform::ArtifactRing> rings;
  for (std::size_t r = 0; r < arm.rings.size(); ++r) {
    const float x = arm.ring_x[r];
    const float elbow = arm.joint_rest[1].x, wrist = arm.joint_rest[2].x;
    if (x < elbow - arm.shape.middle_blend || x > wrist) continue;
    const std::size_t bone = x < elbow ? 0 : 1;
    const glm::vec3 axis(1, 0, 0);
    deform::ArtifactRing ring;
    ring.vertices = arm.rings[r];
    ring.rest_plane = {glm::dvec3(x, 0, 0), glm::dvec3(axis)};
    ring.plane = {glm::dvec3(pose.rotations[bone] * glm::vec3(x, 0, 0) + pose.translations[bone]),
                  glm::dvec3(pose.rotations[bone] * axis)};
    rings.push_back(std::move(ring));
  }
  return rings;
}

// SWD of the arm: one chain (index 0) over joints 0..2; positions (and normals if asked).
inline std::vector<glm::vec3> SkinSwd(const deform::SweepChain& chain,
                                      std::span<const deform::SweepVertexBinding> bindings,
                                      const ArmPose& pose, bool keep_volume = false,
                                      std::vector<glm::vec3>* normals = nullptr,
                                      std::span<const glm::vec3> rest_normals = {}) {
  std::vector<glm::vec3> out(bindings.size());
  if (normals != nullptr) normals->assign(bindings.size(), glm::vec3(0.0f));
  const std::array<glm::vec3, kArmBones> joints = {pose.joints[0], pose.joints[1], pose.joints[2]};
  const deform::SwdJob job{
      .chains = std::span<const deform::SweepChain>(&chain, 1),
      .joint_rotations = pose.rotations,
      .joint_positions = joints,
      .bindings = bindings,
      .rest_normals = normals != nullptr ? rest_normals : std::span<const glm::vec3>(),
      .keep_volume = keep_volume,
      .section_scales = {},
      .positions = out,
      .normals = normals != nullptr ? std::span<glm::vec3>(*normals) : std::span<glm::vec3>(),
  };
  if (!job.Run()) out.clear();
  return out;
}

}  // namespace testfixture
