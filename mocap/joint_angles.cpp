#include "mocap/joint_angles.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace mocap {
namespace {

constexpr double kRadToDeg = 180.0 / std::numbers::pi;
// Below this cos(middle angle) the first and last Euler axes coincide (gimbal
// lock) and only their sum is defined.
constexpr double kGimbalCos = 1e-7;

int AxisIndex(ChannelType type) {
  switch (type) {
    case ChannelType::kXRotation:
      return 0;
    case ChannelType::kYRotation:
      return 1;
    case ChannelType::kZRotation:
      return 2;
    default:
      return -1;
  }
}

// The rotation channels of a joint in channel order (at most 3); returns how many.
int RotationAxes(const JointChannels& ch, ChannelType* axes) {
  int n = 0;
  for (int c = 0; c < ch.count && n < 3; ++c) {
    if (AxisIndex(ch.types[static_cast<std::size_t>(c)]) >= 0)
      axes[n++] = ch.types[static_cast<std::size_t>(c)];
  }
  return n;
}

glm::dvec3 UnitAxis(int i) {
  glm::dvec3 e(0.0);
  e[i] = 1.0;
  return e;
}

// Signed angle (radians, [-pi, pi]) of the twist of q about unit axis e.
double TwistAngle(glm::dquat q, const glm::dvec3& e) {
  if (q.w < 0.0) q = -q;
  const double along = q.x * e.x + q.y * e.y + q.z * e.z;
  return 2.0 * std::atan2(along, q.w);
}

// Element (row, col) of a glm (column-major) matrix.
double At(const glm::dmat3& m, int row, int col) { return m[col][row]; }

// First angle of R = R(a, x) R(b, y) [R(c, 0)]: R maps e_b to R(a, x) e_b =
// cos x e_b + s sin x e_c, with s = +1 when (a, b, c) is cyclic.
double FirstAngleFromAxisB(const glm::dmat3& m, int a, int b, int c) {
  const double s = (b == (a + 1) % 3) ? 1.0 : -1.0;
  return std::atan2(s * At(m, c, b), At(m, b, b));
}

double Wrap360Near(double angle_deg, double reference_deg) {
  return angle_deg + 360.0 * std::round((reference_deg - angle_deg) / 360.0);
}

}  // namespace

void QuatToEuler(const glm::quat& q, const ChannelType* axes, int count, float* angles_deg) {
  const glm::dquat qd = glm::normalize(glm::dquat(q.w, q.x, q.y, q.z));
  int idx[3] = {-1, -1, -1};
  for (int i = 0; i < count && i < 3; ++i) idx[i] = AxisIndex(axes[i]);
  for (int i = 0; i < count; ++i) angles_deg[i] = 0.0f;
  if (count == 1) {
    if (idx[0] >= 0)
      angles_deg[0] = static_cast<float>(TwistAngle(qd, UnitAxis(idx[0])) * kRadToDeg);
    return;
  }
  if (count < 2 || idx[0] < 0 || idx[1] < 0 || idx[0] == idx[1]) return;
  const int a = idx[0];
  const int b = idx[1];
  const int c = 3 - a - b;
  const glm::dmat3 m = glm::mat3_cast(qd);
  if (count == 2) {
    const double x = FirstAngleFromAxisB(m, a, b, c);
    const glm::dquat rest = glm::angleAxis(-x, UnitAxis(a)) * qd;  // R(a, -x) q ~ R(b, y)
    angles_deg[0] = static_cast<float>(x * kRadToDeg);
    angles_deg[1] = static_cast<float>(TwistAngle(rest, UnitAxis(b)) * kRadToDeg);
    return;
  }
  if (idx[2] != c) return;  // repeated axis: not a Tait-Bryan order
  // R = R(a, x) R(b, y) R(c, z): R[a][c] = s sin y, R[b][c] = -s sin x cos y,
  // R[c][c] = cos x cos y, R[a][b] = -s cos y sin z, R[a][a] = cos y cos z.
  const double s = (b == (a + 1) % 3) ? 1.0 : -1.0;
  const double y = std::asin(std::clamp(s * At(m, a, c), -1.0, 1.0));
  double x = 0.0;
  double z = 0.0;
  if (std::cos(y) > kGimbalCos) {
    x = std::atan2(-s * At(m, b, c), At(m, c, c));
    z = std::atan2(-s * At(m, a, b), At(m, a, a));
  } else {
    x = FirstAngleFromAxisB(m, a, b, c);  // z := 0, so R e_b = R(a, x) e_b
  }
  angles_deg[0] = static_cast<float>(x * kRadToDeg);
  angles_deg[1] = static_cast<float>(y * kRadToDeg);
  angles_deg[2] = static_cast<float>(z * kRadToDeg);
}

void QuatToEulerNear(const glm::quat& q, const ChannelType* axes, int count,
                     const float* reference_deg, float* angles_deg) {
  const int n = std::clamp(count, 0, 3);
  double ref[3] = {0.0, 0.0, 0.0};
  for (int i = 0; i < n; ++i) ref[i] = reference_deg[i];
  float base[3] = {0.0f, 0.0f, 0.0f};
  QuatToEuler(q, axes, n, base);
  double best[3] = {0.0, 0.0, 0.0};
  double best_cost = -1.0;
  const int num_candidates = n == 3 ? 2 : 1;
  for (int k = 0; k < num_candidates; ++k) {
    double cand[3] = {base[0], base[1], base[2]};
    if (k == 1) {  // R(a, x+180) R(b, 180-y) R(c, z+180) == R(a, x) R(b, y) R(c, z)
      cand[0] += 180.0;
      cand[1] = 180.0 - cand[1];
      cand[2] += 180.0;
    }
    double cost = 0.0;
    for (int i = 0; i < n; ++i) {
      cand[i] = Wrap360Near(cand[i], ref[i]);
      cost += (cand[i] - ref[i]) * (cand[i] - ref[i]);
    }
    if (best_cost < 0.0 || cost < best_cost) {
      best_cost = cost;
      std::copy(cand, cand + 3, best);
    }
  }
  for (int i = 0; i < n; ++i) angles_deg[i] = static_cast<float>(best[i]);
}

int JointEulerAngles(const Skeleton& skeleton, int joint, const glm::quat& local_rotation,
                     float* angles_deg, const float* reference_deg) {
  const std::size_t j = static_cast<std::size_t>(joint);
  ChannelType axes[3];
  const int n = RotationAxes(skeleton.channels[j], axes);
  if (n == 0) return 0;
  const glm::quat euler = glm::conjugate(skeleton.rest_rotations[j]) * local_rotation;
  if (reference_deg != nullptr) {
    QuatToEulerNear(euler, axes, n, reference_deg, angles_deg);
  } else {
    QuatToEuler(euler, axes, n, angles_deg);
  }
  return n;
}

glm::quat JointRotationFromAngles(const Skeleton& skeleton, int joint, const glm::vec3& xyz_deg) {
  const std::size_t j = static_cast<std::size_t>(joint);
  ChannelType axes[3];
  int n = RotationAxes(skeleton.channels[j], axes);
  for (ChannelType t :
       {ChannelType::kZRotation, ChannelType::kXRotation, ChannelType::kYRotation}) {
    if (std::find(axes, axes + n, t) == axes + n) axes[n++] = t;
  }
  float angles[3];
  for (int k = 0; k < 3; ++k) angles[k] = xyz_deg[AxisIndex(axes[k])];
  return skeleton.rest_rotations[j] * EulerToQuat(axes, angles, 3);
}

glm::vec3 QuatToRotationVector(const glm::quat& q) {
  glm::dquat qd(q.w, q.x, q.y, q.z);
  if (qd.w < 0.0) qd = -qd;
  const glm::dvec3 v(qd.x, qd.y, qd.z);
  const double len = glm::length(v);
  if (len < 1e-12) return glm::vec3(2.0 * v);
  return glm::vec3(v * (2.0 * std::atan2(len, qd.w) / len));
}

glm::quat RotationVectorToQuat(const glm::vec3& r) {
  const glm::dvec3 rd(r);
  const double angle = glm::length(rd);
  if (angle < 1e-12) return glm::normalize(glm::quat(1.0f, 0.5f * r.x, 0.5f * r.y, 0.5f * r.z));
  const glm::dvec3 v = rd * (std::sin(0.5 * angle) / angle);
  return glm::quat(static_cast<float>(std::cos(0.5 * angle)), static_cast<float>(v.x),
                   static_cast<float>(v.y), static_cast<float>(v.z));
}

glm::vec3 RotationVectorFeature(const glm::quat& rest_rotation, const glm::quat& local_rotation) {
  return QuatToRotationVector(glm::conjugate(rest_rotation) * local_rotation);
}

namespace {

// Shared by both orders: the twist of q about `axis` (q made w >= 0 first).
glm::dquat TwistOf(glm::dquat q, const glm::dvec3& a, double* angle) {
  const double along = q.x * a.x + q.y * a.y + q.z * a.z;
  const glm::dquat t(q.w, along * a.x, along * a.y, along * a.z);
  const double norm = glm::length(t);
  if (norm < 1e-9) {
    *angle = 0.0;
    return glm::dquat(1.0, 0.0, 0.0, 0.0);
  }
  *angle = 2.0 * std::atan2(along, q.w);
  return t / norm;
}

}  // namespace

SwingTwist DecomposeSwingTwist(const glm::quat& q, const glm::vec3& axis) {
  glm::dquat qd(q.w, q.x, q.y, q.z);
  if (qd.w < 0.0) qd = -qd;
  double angle = 0.0;
  const glm::dquat t = TwistOf(qd, glm::dvec3(axis), &angle);
  const glm::dquat swing = qd * glm::conjugate(t);
  return {glm::quat(swing), glm::quat(t), static_cast<float>(angle)};
}

SwingTwist DecomposeTwistSwing(const glm::quat& q, const glm::vec3& axis) {
  glm::dquat qd(q.w, q.x, q.y, q.z);
  if (qd.w < 0.0) qd = -qd;
  double angle = 0.0;
  const glm::dquat t = TwistOf(qd, glm::dvec3(axis), &angle);
  const glm::dquat swing = glm::conjugate(t) * qd;
  return {glm::quat(swing), glm::quat(t), static_cast<float>(angle)};
}

void PerpendicularBasis(const glm::vec3& axis, glm::vec3* u, glm::vec3* w) {
  const glm::vec3 ref = std::abs(axis.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
  *u = glm::normalize(ref - glm::dot(ref, axis) * axis);
  *w = glm::cross(axis, *u);  // u x w = axis
}

glm::vec3 SwingTwistFeature(const glm::quat& q, const glm::vec3& axis, float swing_gain,
                            float twist_gain) {
  const SwingTwist st = DecomposeSwingTwist(q, axis);
  const glm::vec3 s = QuatToRotationVector(st.swing);
  glm::vec3 u;
  glm::vec3 w;
  PerpendicularBasis(axis, &u, &w);
  return {swing_gain * glm::dot(s, u), swing_gain * glm::dot(s, w),
          twist_gain * st.twist_angle_rad};
}

}  // namespace mocap
