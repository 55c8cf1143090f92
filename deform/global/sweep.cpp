#include "deform/global/sweep.h"
#include "deform/internal/checks.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace deform {
namespace {

using base::ErrorCode;
using base::MakeError;

template <typename T>
using Vec3T = glm::vec<3, T, glm::defaultp>;
template <typename T>
using QuatT = glm::qua<T, glm::defaultp>;

template <typename T>
T Smoothstep(T x) {
  const T y = std::clamp(x, T(0), T(1));
  return y * y * (T(3) - T(2) * y);
}

// Where u falls: in the region of interior joint `index`, or on bone `index` between regions.
struct Location {
  bool in_region = false;
  int index = 0;
};

template <typename T>
Location Locate(const SweepChain& chain, T u) {
  const int num_bones = chain.num_bones();
  int k = static_cast<int>(std::floor(u));
  k = std::clamp(k, 0, num_bones - 1);
  // u lies on bone k: it may be in the region of joint k (start) or k+1 (end).
  if (k >= 1 && u <= T(chain.region_end(k))) return {true, k};
  if (k + 1 <= num_bones - 1 && u >= T(chain.region_start(k + 1))) return {true, k + 1};
  return {false, k};
}

// Bezier control points of region k.
template <typename T>
void RegionBezier(const SweepChain& chain, const BasicSweepPose<T>& pose, int k,
                  std::array<Vec3T<T>, 4>* b) {
  const T hm = T(chain.half_width_in(k));
  const T hp = T(chain.half_width_out(k));
  const T third = (hm + hp) / T(3);
  const Vec3T<T>& a_in = pose.axes[static_cast<std::size_t>(k - 1)];
  const Vec3T<T>& a_out = pose.axes[static_cast<std::size_t>(k)];
  const Vec3T<T>& joint = pose.points[static_cast<std::size_t>(k)];
  (*b)[0] = joint - hm * a_in;
  (*b)[1] = (*b)[0] + third * a_in;
  (*b)[3] = joint + hp * a_out;
  (*b)[2] = (*b)[3] - third * a_out;
}

// Arc length of the region's Bezier by composite Simpson on |B'(x)| (16 intervals).
template <typename T>
T RegionArcLength(const SweepChain& chain, const BasicSweepPose<T>& pose, int k) {
  std::array<Vec3T<T>, 4> b;
  RegionBezier(chain, pose, k, &b);
  constexpr int kIntervals = 16;
  T sum = T(0);
  for (int i = 0; i <= kIntervals; ++i) {
    const T x = T(i) / T(kIntervals);
    const T s = T(1) - x;
    const Vec3T<T> d = T(3) * (s * s * (b[1] - b[0]) + T(2) * s * x * (b[2] - b[1]) +
                               x * x * (b[3] - b[2]));
    const T weight = (i == 0 || i == kIntervals) ? T(1) : (i % 2 == 1 ? T(4) : T(2));
    sum += weight * glm::length(d);
  }
  return sum / (T(3) * T(kIntervals));
}

using internal::Finite;

}  // namespace

double DefaultHalfWidth(double skin_radius, double bend_rad, double length_in,
                        double length_out) {
  const double l_min = std::min(length_in, length_out);
  return std::clamp(0.75 * skin_radius * bend_rad, 0.1 * l_min, 0.45 * l_min);
}

double SkinRadiusNearJoint(const SweepChainSpec& spec, int k,
                           std::span<const glm::vec3> rest_positions) {
  const auto ks = static_cast<std::size_t>(k);
  const glm::dvec3 prev(spec.rest_points[ks - 1]);
  const glm::dvec3 joint(spec.rest_points[ks]);
  const glm::dvec3 next(spec.rest_points[ks + 1]);
  const double l_min = std::min(glm::length(joint - prev), glm::length(next - joint));
  std::vector<double> distances;
  for (const glm::vec3& v : rest_positions) {
    const glm::dvec3 p(v);
    if (glm::length(p - joint) > 0.5 * l_min) continue;
    // Distance from the axis: from the nearer of the two (infinite) bone lines.
    double best = std::numeric_limits<double>::max();
    for (const auto& [a, b] : {std::pair{prev, joint}, std::pair{joint, next}}) {
      const glm::dvec3 axis = glm::normalize(b - a);
      const glm::dvec3 d = p - a;
      best = std::min(best, glm::length(d - glm::dot(d, axis) * axis));
    }
    distances.push_back(best);
  }
  if (distances.empty()) return 0.0;
  const auto nth = static_cast<std::ptrdiff_t>(0.9 * static_cast<double>(distances.size() - 1));
  std::nth_element(distances.begin(), distances.begin() + nth, distances.end());
  return distances[static_cast<std::size_t>(nth)];
}

double SweepChain::joint_parameter(int k) const {
  const auto ks = static_cast<std::size_t>(k);
  if (k <= 0 || k >= num_bones_) return k;
  return region_start_[ks] + (region_end_[ks] - region_start_[ks]) * hm_[ks] / (hm_[ks] + hp_[ks]);
}

template <typename T>
QuatT<T> TwistQuat(const Vec3T<T>& axis, T angle_rad) {
  const T half = T(0.5) * angle_rad;
  const T s = std::sin(half);
  return QuatT<T>(std::cos(half), s * axis.x, s * axis.y, s * axis.z);
}

template <typename T>
T TwistAngle(const QuatT<T>& q_in, const Vec3T<T>& axis) {
  const QuatT<T> q = q_in.w < T(0) ? -q_in : q_in;  // short arc: |angle| <= pi
  const T along = q.x * axis.x + q.y * axis.y + q.z * axis.z;
  if (std::sqrt(q.w * q.w + along * along) < T(1e-9)) return T(0);  // pure 180 deg swing
  return T(2) * std::atan2(along, q.w);
}

template <typename T>
QuatT<T> SlerpShort(const QuatT<T>& q0, const QuatT<T>& q1_in, T w) {
  T cosine = glm::dot(q0, q1_in);
  const QuatT<T> q1 = cosine < T(0) ? -q1_in : q1_in;
  cosine = std::abs(cosine);
  if (cosine > T(1) - T(1e-6)) {  // nearly equal: nlerp is exact to rounding
    return glm::normalize(QuatT<T>((T(1) - w) * q0.w + w * q1.w, (T(1) - w) * q0.x + w * q1.x,
                                   (T(1) - w) * q0.y + w * q1.y, (T(1) - w) * q0.z + w * q1.z));
  }
  const T angle = std::acos(cosine);
  const T inv_sin = T(1) / std::sin(angle);
  const T c0 = std::sin((T(1) - w) * angle) * inv_sin;
  const T c1 = std::sin(w * angle) * inv_sin;
  return QuatT<T>(c0 * q0.w + c1 * q1.w, c0 * q0.x + c1 * q1.x, c0 * q0.y + c1 * q1.y,
                  c0 * q0.z + c1 * q1.z);
}

base::Result<SweepChain> BuildSweepChain(const SweepChainSpec& spec) {
  const int num_bones = static_cast<int>(spec.joints.size());
  if (num_bones < 1 || num_bones > kMaxSweepBones) {
    return MakeError(ErrorCode::kLimitExceeded, {},
                     "sweep chain needs 1.." + std::to_string(kMaxSweepBones) +
                         " bones, found " + std::to_string(num_bones));
  }
  const auto num_points = static_cast<std::size_t>(num_bones + 1);
  if (spec.rest_points.size() != num_points) {
    return base::InvalidArgument("sweep chain expected " + std::to_string(num_points) +
                                 " rest points, found " + std::to_string(spec.rest_points.size()));
  }
  for (const auto* list : {&spec.half_widths, &spec.skin_radii}) {
    if (!list->empty() && list->size() != num_points) {
      return base::InvalidArgument("sweep chain expected " + std::to_string(num_points) +
                                   " half-widths or skin radii, found " +
                                   std::to_string(list->size()));
    }
  }
  if (!spec.twist_spread.empty() && spec.twist_spread.size() != num_points) {
    return base::InvalidArgument("sweep chain expected " + std::to_string(num_points) +
                                 " twist assignments, found " +
                                 std::to_string(spec.twist_spread.size()));
  }
  SweepChain chain;
  chain.num_bones_ = num_bones;
  for (int k = 0; k < num_bones; ++k) {
    const auto ks = static_cast<std::size_t>(k);
    if (spec.joints[ks] < 0) {
      return base::InvalidArgument("sweep bone " + std::to_string(k) + " has negative joint index");
    }
    if (!Finite(spec.rest_points[ks]) || !Finite(spec.rest_points[ks + 1])) {
      return base::InvalidArgument("sweep joint " + std::to_string(k) + " position is not finite");
    }
    const glm::dvec3 d = glm::dvec3(spec.rest_points[ks + 1]) - glm::dvec3(spec.rest_points[ks]);
    const double length = glm::length(d);
    if (!(length > 1e-6)) {
      return base::InvalidArgument("sweep bone " + std::to_string(k) + " has zero length");
    }
    chain.joints_[ks] = spec.joints[ks];
    chain.lengths_[ks] = length;
    chain.axes_[ks] = d / length;
  }
  for (int k = 0; k <= num_bones; ++k) {
    const auto ks = static_cast<std::size_t>(k);
    chain.spread_[ks] = spec.twist_spread.empty() ? TwistSpread::kDownstream
                                                  : spec.twist_spread[ks];
    if (k == 0 || k == num_bones) continue;  // chain ends own no region
    const double l_in = chain.lengths_[ks - 1];
    const double l_out = chain.lengths_[ks];
    double h = 0.0;
    if (!spec.half_widths.empty()) {
      h = spec.half_widths[ks];
    } else {
      const double radius = spec.skin_radii.empty() ? 0.0 : spec.skin_radii[ks];
      h = DefaultHalfWidth(radius, kDefaultMaxBendRad, l_in, l_out);
    }
    if (!std::isfinite(h) || h <= 0.0 || h >= std::min(l_in, l_out)) {
      return base::InvalidArgument(
          "sweep joint " + std::to_string(k) +
          " region half-width must be in (0, shorter bone length), found " + std::to_string(h));
    }
    chain.hm_[ks] = h;
    chain.hp_[ks] = h;
  }
  for (int k = 0; k <= num_bones; ++k) {
    const auto ks = static_cast<std::size_t>(k);
    chain.region_start_[ks] = k == 0 ? 0.0 : k - chain.hm_[ks] / chain.lengths_[ks - 1];
    chain.region_end_[ks] = k == num_bones ? num_bones : k + chain.hp_[ks] / chain.lengths_[ks];
  }
  for (int k = 0; k < num_bones; ++k) {
    const auto ks = static_cast<std::size_t>(k);
    if (!(chain.region_end_[ks] < chain.region_start_[ks + 1])) {
      return base::InvalidArgument("sweep bone " + std::to_string(k) +
                                   " is shorter than the regions of its two joints");
    }
  }
  // The bind pose: identity rotations, J_0 at its rest position.
  BasicSweepPose<double>& rest = chain.rest_pose_;
  rest.num_bones = num_bones;
  rest.points[0] = glm::dvec3(spec.rest_points[0]);
  for (int k = 0; k < num_bones; ++k) {
    const auto ks = static_cast<std::size_t>(k);
    rest.rotations[ks] = glm::dquat(1.0, 0.0, 0.0, 0.0);
    rest.axes[ks] = chain.axes_[ks];
    rest.points[ks + 1] = rest.points[ks] + chain.lengths_[ks] * chain.axes_[ks];
  }
  for (int k = 0; k <= num_bones; ++k) {
    const auto ks = static_cast<std::size_t>(k);
    rest.region_from[ks] = glm::dquat(1.0, 0.0, 0.0, 0.0);
    rest.region_to[ks] = glm::dquat(1.0, 0.0, 0.0, 0.0);
    if (k >= 1 && k < num_bones) chain.rest_region_length_[ks] = RegionArcLength(chain, rest, k);
  }
  return chain;
}

template <typename T>
void PoseSweepChain(const SweepChain& chain, std::span<const glm::quat> joint_rotations,
                    std::span<const glm::vec3> joint_positions, bool keep_volume,
                    BasicSweepPose<T>* pose) {
  const int num_bones = chain.num_bones();
  pose->num_bones = num_bones;
  const auto root = static_cast<std::size_t>(chain.joint(0));
  pose->points[0] = Vec3T<T>(joint_positions[root]);
  for (int k = 0; k < num_bones; ++k) {
    const auto ks = static_cast<std::size_t>(k);
    const glm::quat& q = joint_rotations[static_cast<std::size_t>(chain.joint(k))];
    pose->rotations[ks] = glm::normalize(QuatT<T>(T(q.w), T(q.x), T(q.y), T(q.z)));
    pose->axes[ks] = glm::normalize(pose->rotations[ks] * Vec3T<T>(chain.rest_axis(k)));
    pose->points[ks + 1] = pose->points[ks] + T(chain.rest_length(k)) * pose->axes[ks];
  }
  const QuatT<T> identity(T(1), T(0), T(0), T(0));
  for (int k = 0; k <= num_bones; ++k) {
    const auto ks = static_cast<std::size_t>(k);
    pose->down_twist[ks] = T(0);
    pose->up_twist[ks] = T(0);
    pose->region_from[ks] = identity;
    pose->region_to[ks] = identity;
    pose->volume_gain[ks] = T(0);
    if (k == 0 || k == num_bones) continue;  // chain ends carry no twist
    const QuatT<T>& q_in = pose->rotations[ks - 1];
    const QuatT<T>& q_out = pose->rotations[ks];
    const QuatT<T> local = glm::conjugate(q_in) * q_out;  // L_k = dQ_{k-1}^-1 dQ_k
    const Vec3T<T> axis_in(chain.rest_axis(k - 1));
    const Vec3T<T> axis_out(chain.rest_axis(k));
    if (chain.twist_spread(k) == TwistSpread::kDownstream) {
      pose->down_twist[ks] = TwistAngle(local, axis_out);
    } else {
      pose->up_twist[ks] = TwistAngle(local, axis_in);
    }
    pose->region_from[ks] = q_in * TwistQuat(axis_in, pose->up_twist[ks]);
    QuatT<T> to = q_out * TwistQuat(axis_out, -pose->down_twist[ks]);
    if (glm::dot(pose->region_from[ks], to) < T(0)) to = -to;
    pose->region_to[ks] = to;
  }
  if (keep_volume) {
    for (int k = 1; k < num_bones; ++k) {
      const T length = RegionArcLength(chain, *pose, k);
      pose->volume_gain[static_cast<std::size_t>(k)] =
          length > T(0) ? T(chain.rest_region_length(k)) / length - T(1) : T(0);
    }
  }
}

template <typename T>
Vec3T<T> SweepCentre(const SweepChain& chain, const BasicSweepPose<T>& pose, T u,
                     Vec3T<T>* derivative) {
  const Location at = Locate(chain, u);
  const auto ks = static_cast<std::size_t>(at.index);
  if (!at.in_region) {
    const T length = T(chain.rest_length(at.index));
    const T t = u - T(at.index);
    if (derivative != nullptr) *derivative = length * pose.axes[ks];
    return pose.points[ks] + (t * length) * pose.axes[ks];
  }
  std::array<Vec3T<T>, 4> b;
  RegionBezier(chain, pose, at.index, &b);
  const T start = T(chain.region_start(at.index));
  const T width = T(chain.region_end(at.index)) - start;
  const T x = (u - start) / width;
  const T s = T(1) - x;
  if (derivative != nullptr) {
    *derivative = (T(3) / width) * (s * s * (b[1] - b[0]) + T(2) * s * x * (b[2] - b[1]) +
                                    x * x * (b[3] - b[2]));
  }
  return (s * s * s) * b[0] + (T(3) * s * s * x) * b[1] + (T(3) * s * x * x) * b[2] +
         (x * x * x) * b[3];
}

template <typename T>
QuatT<T> SweepFrame(const SweepChain& chain, const BasicSweepPose<T>& pose, T u) {
  const Location at = Locate(chain, u);
  const auto ks = static_cast<std::size_t>(at.index);
  if (at.in_region) {
    const T start = T(chain.region_start(at.index));
    const T x = (u - start) / (T(chain.region_end(at.index)) - start);
    return SlerpShort(pose.region_from[ks], pose.region_to[ks], Smoothstep(x));
  }
  const T down = pose.down_twist[ks];
  const T up = pose.up_twist[ks + 1];
  if (down == T(0) && up == T(0)) return pose.rotations[ks];
  const T start = T(chain.region_end(at.index));
  const T lam = Smoothstep((u - start) / (T(chain.region_start(at.index + 1)) - start));
  const T angle = -down * (T(1) - lam) + up * lam;
  return pose.rotations[ks] * TwistQuat(Vec3T<T>(chain.rest_axis(at.index)), angle);
}

template <typename T>
T SweepScale(const SweepChain& chain, const BasicSweepPose<T>& pose, T u) {
  const Location at = Locate(chain, u);
  if (!at.in_region) return T(1);
  const T gain = pose.volume_gain[static_cast<std::size_t>(at.index)];
  if (gain == T(0)) return T(1);
  const T start = T(chain.region_start(at.index));
  const T x = (u - start) / (T(chain.region_end(at.index)) - start);
  return std::sqrt(std::max(T(0), T(1) + gain * T(6) * x * (T(1) - x)));
}

template <typename T>
bool SweepRegionAt(const SweepChain& chain, T u, int* joint, T* x) {
  const Location at = Locate(chain, u);
  if (!at.in_region) return false;
  const T start = T(chain.region_start(at.index));
  *joint = at.index;
  *x = (u - start) / (T(chain.region_end(at.index)) - start);
  return true;
}

#define PATCHSKIN_INSTANTIATE_SWEEP(T)                                                        \
  template void PoseSweepChain<T>(const SweepChain&, std::span<const glm::quat>,              \
                                  std::span<const glm::vec3>, bool, BasicSweepPose<T>*);      \
  template Vec3T<T> SweepCentre<T>(const SweepChain&, const BasicSweepPose<T>&, T, Vec3T<T>*); \
  template QuatT<T> SweepFrame<T>(const SweepChain&, const BasicSweepPose<T>&, T);            \
  template T SweepScale<T>(const SweepChain&, const BasicSweepPose<T>&, T);                   \
  template bool SweepRegionAt<T>(const SweepChain&, T, int*, T*);                             \
  template QuatT<T> TwistQuat<T>(const Vec3T<T>&, T);                                         \
  template T TwistAngle<T>(const QuatT<T>&, const Vec3T<T>&);                                 \
  template QuatT<T> SlerpShort<T>(const QuatT<T>&, const QuatT<T>&, T);

PATCHSKIN_INSTANTIATE_SWEEP(float)
PATCHSKIN_INSTANTIATE_SWEEP(double)
#undef PATCHSKIN_INSTANTIATE_SWEEP

}  // namespace deform
