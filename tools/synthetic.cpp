#include "tools/synthetic.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "mocap/joint_angles.h"
#include "mocap/pose.h"

namespace synthetic {

using mocap::ChannelType;
using mocap::EulerToQuat;
using mocap::JointChannels;
using mocap::kMaxJoints;
using mocap::kNoParent;
using mocap::Motion;
using mocap::PositionChannelMode;
using mocap::QuatToEulerNear;
using mocap::Skeleton;
using mocap::UpAxis;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr std::array<ChannelType, 3> kZxy = {ChannelType::kZRotation, ChannelType::kXRotation,
                                             ChannelType::kYRotation};
// Humanoid leg segments (cm): hip joint -> knee -> ankle.
constexpr double kThighCm = 42.0;
constexpr double kShinCm = 42.0;
constexpr float kHipsRestY = 97.0f;

// Appends joints in parent-before-child order with contiguous channels.
class Builder {
 public:
  int Add(const std::string& name, int parent, glm::vec3 offset, bool with_position = false) {
    JointChannels ch;
    ch.first = static_cast<std::uint32_t>(s_.num_channels);
    int c = 0;
    if (with_position) {
      for (ChannelType t :
           {ChannelType::kXPosition, ChannelType::kYPosition, ChannelType::kZPosition}) {
        ch.types[static_cast<std::size_t>(c++)] = t;
      }
    }
    for (ChannelType t : kZxy) ch.types[static_cast<std::size_t>(c++)] = t;
    ch.count = static_cast<std::uint8_t>(c);
    s_.num_channels += c;
    s_.names.push_back(name);
    s_.parents.push_back(static_cast<std::int16_t>(parent));
    s_.rest_translations.push_back(offset);
    s_.rest_rotations.emplace_back(1.0f, 0.0f, 0.0f, 0.0f);
    s_.rest_scales.emplace_back(1.0f);
    s_.channels.push_back(ch);
    return static_cast<int>(s_.names.size()) - 1;
  }
  void End(int parent, glm::vec3 offset) { s_.end_sites.push_back({parent, offset, "End Site"}); }
  Skeleton Finish(const char* source) {
    s_.info.source_file = source;
    s_.info.detected_units = "cm";
    s_.info.up_axis = UpAxis::kY;
    return std::move(s_);
  }

 private:
  Skeleton s_;
};

// Joint rotation from ZXY Euler angles in degrees (R = Rz * Rx * Ry).
glm::quat Zxy(double z_deg, double x_deg, double y_deg) {
  const float angles[3] = {static_cast<float>(z_deg), static_cast<float>(x_deg),
                           static_cast<float>(y_deg)};
  return EulerToQuat(kZxy.data(), angles, 3);
}

// The humanoid joints the generators drive, in a fixed order.
// clang-format off
enum H : int {
  kHips, kSpine, kSpine1, kSpine2, kNeck, kHead,
  kLShoulder, kLArm, kLForeArm, kLHand, kLIndex,
  kRShoulder, kRArm, kRForeArm, kRHand, kRIndex,
  kLUpLeg, kLLeg, kLFoot, kLToe, kRUpLeg, kRLeg, kRFoot, kRToe, kNumH
};
// clang-format on
constexpr std::array<const char*, kNumH> kHumanoidNames = {
    "Hips",        "Spine",        "Spine1",         "Spine2",
    "Neck",        "Head",         "LeftShoulder",   "LeftArm",
    "LeftForeArm", "LeftHand",     "LeftHandIndex1", "RightShoulder",
    "RightArm",    "RightForeArm", "RightHand",      "RightHandIndex1",
    "LeftUpLeg",   "LeftLeg",      "LeftFoot",       "LeftToeBase",
    "RightUpLeg",  "RightLeg",     "RightFoot",      "RightToeBase"};

// One intended pose: root position and per-humanoid-joint rotation relative to rest.
struct HumanoidPose {
  glm::vec3 root_position{0.0f, kHipsRestY, 0.0f};
  std::array<glm::quat, kNumH> rotations;
  HumanoidPose() { rotations.fill(glm::quat(1.0f, 0.0f, 0.0f, 0.0f)); }
};

// Writes motions of a humanoid skeleton frame by frame, whatever its channel order.
class MotionWriter {
 public:
  static base::Result<MotionWriter> Create(const Skeleton& s, double frame_time_s, int num_frames) {
    const base::FileLoc loc{s.info.source_file, 0, 0, {}};
    if (!(frame_time_s > 0.0) || !std::isfinite(frame_time_s) || num_frames < 1 ||
        num_frames > (1 << 20)) {
      return base::MakeError(base::ErrorCode::kInvalidArgument, loc,
                             "expected a positive frame time and duration, found frame time " +
                                 std::to_string(frame_time_s) + " s for " +
                                 std::to_string(num_frames) + " frames");
    }
    const base::Status check = s.Check();
    if (!check) return check.error();
    MotionWriter w(s);
    for (int i = 0; i < kNumH; ++i) {
      w.index_[static_cast<std::size_t>(i)] =
          s.FindJoint(kHumanoidNames[static_cast<std::size_t>(i)]);
      if (w.index_[static_cast<std::size_t>(i)] < 0) {
        return base::MakeError(base::ErrorCode::kNotFound, loc,
                               std::string("expected a humanoid joint named '") +
                                   kHumanoidNames[static_cast<std::size_t>(i)] + "'");
      }
    }
    w.motion_.frame_time_s = frame_time_s;
    w.motion_.num_channels = s.num_channels;
    w.motion_.num_frames = num_frames;
    w.motion_.values.assign(
        static_cast<std::size_t>(num_frames) * static_cast<std::size_t>(s.num_channels), 0.0f);
    return w;
  }

  int num_frames() const { return motion_.num_frames; }
  double time(int f) const { return f * motion_.frame_time_s; }

  void Write(int f, const HumanoidPose& pose) {
    std::vector<glm::quat> delta(skeleton_->parents.size(), glm::quat(1.0f, 0.0f, 0.0f, 0.0f));
    for (int i = 0; i < kNumH; ++i) {
      delta[static_cast<std::size_t>(index_[static_cast<std::size_t>(i)])] =
          pose.rotations[static_cast<std::size_t>(i)];
    }
    const std::size_t root = static_cast<std::size_t>(index_[kHips]);
    std::span<float> row = motion_.frame(f);
    const std::span<const float> previous =
        f > 0 ? std::span<const float>(motion_.frame(f - 1)) : row;
    for (std::size_t j = 0; j < delta.size(); ++j) {
      const JointChannels& ch = skeleton_->channels[j];
      const glm::vec3 translation =
          j == root ? pose.root_position : skeleton_->rest_translations[j];
      ChannelType axes[3];
      std::uint32_t where[3];
      int n = 0;
      for (int c = 0; c < ch.count; ++c) {
        const ChannelType t = ch.types[static_cast<std::size_t>(c)];
        const std::uint32_t k = ch.first + static_cast<std::uint32_t>(c);
        const int type = static_cast<int>(t);
        if (type <= 2) {  // kX/Y/ZPosition
          row[k] =
              translation[type] - (skeleton_->position_mode == PositionChannelMode::kAddToOffset
                                       ? skeleton_->rest_translations[j][type]
                                       : 0.0f);
        } else if (type <= 5 && n < 3) {
          axes[n] = t;
          where[n++] = k;
        } else if (t >= ChannelType::kQuatX && t <= ChannelType::kQuatW) {
          const glm::quat q = skeleton_->rest_rotations[j] * delta[j];
          const float v[4] = {q.x, q.y, q.z, q.w};
          row[k] = v[type - static_cast<int>(ChannelType::kQuatX)];
        } else {
          row[k] = skeleton_->rest_scales[j][type - static_cast<int>(ChannelType::kXScale)];
        }
      }
      if (n > 0) {
        float ref[3] = {0.0f, 0.0f, 0.0f};
        float out[3];
        if (f > 0) {
          for (int i = 0; i < n; ++i) ref[i] = previous[where[i]];
        }
        QuatToEulerNear(delta[j], axes, n, ref, out);
        for (int i = 0; i < n; ++i) row[where[i]] = out[i];
      }
    }
  }
  Motion Take() { return std::move(motion_); }

 private:
  explicit MotionWriter(const Skeleton& s) : skeleton_(&s) {}
  const Skeleton* skeleton_;
  std::array<int, kNumH> index_{};
  Motion motion_;
};

int FramesFor(double duration_s, double frame_time_s) {
  if (!(frame_time_s > 0.0) || !(duration_s > 0.0) || !std::isfinite(duration_s / frame_time_s))
    return 0;
  return static_cast<int>(std::min(std::round(duration_s / frame_time_s), 1e7)) + 1;
}

// Sets thigh, knee and a foot kept parallel to the ground (their X rotations sum to 0).
void SetLeg(HumanoidPose* p, int up_leg, double thigh_x_deg, double knee_x_deg) {
  p->rotations[static_cast<std::size_t>(up_leg)] = Zxy(0, thigh_x_deg, 0);
  p->rotations[static_cast<std::size_t>(up_leg + 1)] = Zxy(0, knee_x_deg, 0);
  p->rotations[static_cast<std::size_t>(up_leg + 2)] = Zxy(0, -(thigh_x_deg + knee_x_deg), 0);
}

// Two-bone IK for a leg under unrotated hips: puts the ankle at `ankle` (cm,
// relative to the hip joint, hips frame) with the knee pointing forward and the
// foot flat and facing +Z. The leg first tilts about Z by tau so the ankle's
// sideways offset lies in its plane, then bends in that plane: the thigh flexes
// by gamma + a and the knee by 2a (equal segments), gamma the forward angle of
// the hip->ankle line, a = acos(d / 2L). Targets beyond reach are clamped.
void SolveLeg(HumanoidPose* p, int up_leg, const glm::dvec3& ankle) {
  const double r = std::hypot(ankle.x, ankle.y);  // length of the tilted plane's down axis
  const double tau = std::atan2(ankle.x, -ankle.y);
  const double d = std::min(std::hypot(r, ankle.z), 0.9995 * (kThighCm + kShinCm));
  const double a = std::acos(d / (kThighCm + kShinCm));
  const double gamma = std::atan2(ankle.z, r);
  const glm::quat thigh = Zxy(glm::degrees(tau), -glm::degrees(gamma + a), 0);
  const glm::quat knee = Zxy(0, glm::degrees(2 * a), 0);
  p->rotations[static_cast<std::size_t>(up_leg)] = thigh;
  p->rotations[static_cast<std::size_t>(up_leg + 1)] = knee;
  p->rotations[static_cast<std::size_t>(up_leg + 2)] = glm::conjugate(thigh * knee);
}

}  // namespace

Skeleton MakeHumanoidSkeleton() {
  Builder b;
  const int hips = b.Add("Hips", kNoParent, {0.0f, kHipsRestY, 0.0f}, true);
  const int spine = b.Add("Spine", hips, {0, 8, 0});
  const int spine1 = b.Add("Spine1", spine, {0, 12, 0});
  const int spine2 = b.Add("Spine2", spine1, {0, 12, 0});
  const int neck = b.Add("Neck", spine2, {0, 16, 0});
  const int head = b.Add("Head", neck, {0, 9, 0});
  b.End(head, {0, 18, 0});
  for (float side : {1.0f, -1.0f}) {
    const std::string s = side > 0 ? "Left" : "Right";
    const int shoulder = b.Add(s + "Shoulder", spine2, {4 * side, 11, 0});
    const int arm = b.Add(s + "Arm", shoulder, {13 * side, 0, 0});
    const int fore = b.Add(s + "ForeArm", arm, {28 * side, 0, 0});
    const int hand = b.Add(s + "Hand", fore, {25 * side, 0, 0});
    const int index = b.Add(s + "HandIndex1", hand, {9 * side, 0, 0});
    b.End(index, {7 * side, 0, 0});
  }
  for (float side : {1.0f, -1.0f}) {
    const std::string s = side > 0 ? "Left" : "Right";
    const int up = b.Add(s + "UpLeg", hips, {9 * side, -5, 0});
    const int leg = b.Add(s + "Leg", up, {0, -static_cast<float>(kThighCm), 0});
    const int foot = b.Add(s + "Foot", leg, {0, -static_cast<float>(kShinCm), 0});
    const int toe = b.Add(s + "ToeBase", foot, {0, -7, 12});
    b.End(toe, {0, 0, 6});
  }
  Skeleton s = b.Finish("synthetic:humanoid");
  s.info.rest_height = 172.0f;
  return s;
}

base::Result<Motion> MakeWalkMotion(const Skeleton& humanoid, const WalkOptions& o) {
  if (!(o.step_length_cm > 0.0 && o.step_length_cm <= 60.0) ||
      !(o.foot_lift_cm >= 0.0 && o.foot_lift_cm <= 30.0)) {
    return base::MakeError(base::ErrorCode::kInvalidArgument, {humanoid.info.source_file, 0, 0, {}},
                           "expected a step length in (0, 60] cm and a foot lift in [0, 30] cm");
  }
  const int frames = o.num_cycles >= 1 && o.cycle_s > 0.0
                         ? FramesFor(o.num_cycles * o.cycle_s, o.frame_time_s) - 1
                         : 0;
  auto writer = MotionWriter::Create(humanoid, o.frame_time_s, frames);
  if (!writer.ok()) return std::move(writer).error();
  constexpr double kDuty = 0.6;        // stance fraction of the cycle
  constexpr double kHipHeight = 80.0;  // mean hip joint height above the ankle, cm
  constexpr double kBob = 2.0;         // cm
  const double step = o.step_length_cm;
  const double speed = step / (kDuty * o.cycle_s);  // cm/s
  const double swing_s = (1.0 - kDuty) * o.cycle_s;
  // Hip joint height above the ankles at cycle phase u of the left leg: highest
  // at each leg's mid-stance (u = 0.3 and 0.8).
  const auto hip_height = [&](double u) {
    return kHipHeight + kBob * std::cos(4 * kPi * (u - 0.3));
  };
  // Ankle path relative to the hip joint (z forward, lift up) at the leg's own phase u.
  const auto ankle_path = [&](double u, double* z, double* lift) {
    if (u < kDuty) {
      *z = 0.5 * step - speed * u * o.cycle_s;  // planted: moves back at the hips' speed
      *lift = 0.0;
      return;
    }
    const double s = (u - kDuty) / (1.0 - kDuty);
    const double s2 = s * s;
    const double s3 = s2 * s;
    const double slope = -speed * swing_s;  // ground speed 0 at both ends
    *z = (2 * s3 - 3 * s2 + 1) * (-0.5 * step) + (s3 - 2 * s2 + s) * slope +
         (-2 * s3 + 3 * s2) * (0.5 * step) + (s3 - s2) * slope;
    *lift = o.foot_lift_cm * std::sin(kPi * s) * std::sin(kPi * s);
  };
  const double hip_offset_y = -humanoid
                                   .rest_translations[static_cast<std::size_t>(
                                       std::max(humanoid.FindJoint("LeftUpLeg"), 0))]
                                   .y;  // hips above the hip joints
  const double ankle_rest_y = kHipsRestY - hip_offset_y - (kThighCm + kShinCm);
  for (int f = 0; f < writer->num_frames(); ++f) {
    const double t = writer->time(f);
    const double u_left = t / o.cycle_s - std::floor(t / o.cycle_s);
    const double u_right = u_left + 0.5 - std::floor(u_left + 0.5);
    const double height = hip_height(u_left);
    const double sway = 2.0 * std::cos(2 * kPi * (u_left - 0.3));  // over the stance foot
    const double c = std::cos(2 * kPi * u_left);                   // +1 when the left foot lands
    HumanoidPose p;
    p.root_position = glm::vec3(static_cast<float>(sway),
                                static_cast<float>(ankle_rest_y + height + hip_offset_y),
                                static_cast<float>(speed * t));
    double z = 0.0;
    double lift = 0.0;
    ankle_path(u_left, &z, &lift);
    SolveLeg(&p, kLUpLeg, {-sway, -(height - lift), z});
    ankle_path(u_right, &z, &lift);
    SolveLeg(&p, kRUpLeg, {-sway, -(height - lift), z});
    // The chest turns with the forward arm (right arm forward when c = 1); neck
    // and head undo it so the gaze stays on +Z.
    p.rotations[kSpine] = Zxy(0, 3, 1.5 * c);
    p.rotations[kSpine1] = Zxy(0, 1, 1.5 * c);
    p.rotations[kSpine2] = Zxy(0, 0, 1.0 * c);
    p.rotations[kNeck] = Zxy(0, 0, -2.0 * c);
    p.rotations[kHead] = Zxy(0, -4, -2.0 * c);
    // Arms hang 75 degrees down and swing against the same-side leg.
    const double swing = o.arm_swing_deg;
    const double left_fwd = -swing * c;
    const double right_fwd = swing * c;
    const auto elbow = [&](double fwd) {
      const double w = swing > 0.0 ? 0.5 + 0.5 * fwd / swing : 0.5;
      return 15.0 + (o.elbow_peak_deg - 15.0) * w;
    };
    p.rotations[kLArm] = Zxy(-75, 0, -left_fwd);
    p.rotations[kRArm] = Zxy(75, 0, right_fwd);
    p.rotations[kLForeArm] = Zxy(0, 0, -elbow(left_fwd));
    p.rotations[kRForeArm] = Zxy(0, 0, elbow(right_fwd));
    writer->Write(f, p);
  }
  return writer->Take();
}

base::Result<Motion> MakeBendRamp(const Skeleton& humanoid, float end_deg, double duration_s,
                                  double frame_time_s) {
  auto writer = MotionWriter::Create(humanoid, frame_time_s, FramesFor(duration_s, frame_time_s));
  if (!writer.ok()) return std::move(writer).error();
  const int last = writer->num_frames() - 1;
  for (int f = 0; f <= last; ++f) {
    const double a = last > 0 ? end_deg * static_cast<double>(f) / last : end_deg;
    HumanoidPose p;
    p.rotations[kLForeArm] = Zxy(0, 0, -a);  // forearms bend forward (+Z)
    p.rotations[kRForeArm] = Zxy(0, 0, a);
    SetLeg(&p, kLUpLeg, -0.4 * a, a);  // knee forward, shin back: clear of the body
    writer->Write(f, p);
  }
  return writer->Take();
}

namespace {

// Cosine ease of the move from key k to k + 1 at time t: (k, s), s in [0, 1],
// zero speed at both keys; t past the last key gives the last key.
std::pair<int, double> EasedSegment(double t, double segment_s, int num_keys) {
  const double x = std::clamp(t / segment_s, 0.0, static_cast<double>(num_keys - 1));
  const int k = std::min(static_cast<int>(std::floor(x)), num_keys - 2);
  const double y = x - k;
  return {k, 0.5 - 0.5 * std::cos(kPi * y)};
}

}  // namespace

base::Result<Motion> MakeShoulderSweep(const Skeleton& humanoid, double segment_s,
                                       double frame_time_s) {
  if (!(segment_s > 0.0))
    return base::MakeError(base::ErrorCode::kInvalidArgument, {}, "expected segment_s > 0");
  const glm::quat t_pose(1.0f, 0.0f, 0.0f, 0.0f);
  const glm::quat poses[5] = {Zxy(-75, 0, 0), Zxy(60, 0, 0), Zxy(0, 0, -90), Zxy(0, 0, 40),
                              Zxy(-60, 0, -50)};
  std::vector<glm::quat> keys = {t_pose};
  for (const glm::quat& q : poses) {
    keys.push_back(q);
    keys.push_back(t_pose);
  }
  const int num_keys = static_cast<int>(keys.size());
  auto writer = MotionWriter::Create(humanoid, frame_time_s,
                                     FramesFor((num_keys - 1) * segment_s, frame_time_s));
  if (!writer.ok()) return std::move(writer).error();
  for (int f = 0; f < writer->num_frames(); ++f) {
    const auto [k, w] = EasedSegment(f * frame_time_s, segment_s, num_keys);
    HumanoidPose p;
    p.rotations[kLArm] = glm::slerp(keys[static_cast<std::size_t>(k)],
                                    keys[static_cast<std::size_t>(k + 1)], static_cast<float>(w));
    writer->Write(f, p);
  }
  return writer->Take();
}

base::Result<Motion> MakeHipSwing(const Skeleton& humanoid, double segment_s, double frame_time_s) {
  if (!(segment_s > 0.0))
    return base::MakeError(base::ErrorCode::kInvalidArgument, {}, "expected segment_s > 0");
  // (thigh X, knee X) in degrees: stand, stretched back, stand, lifted, stand.
  const double keys[5][2] = {{0, 0}, {40, 0}, {0, 0}, {-80, 90}, {0, 0}};
  auto writer =
      MotionWriter::Create(humanoid, frame_time_s, FramesFor(4 * segment_s, frame_time_s));
  if (!writer.ok()) return std::move(writer).error();
  for (int f = 0; f < writer->num_frames(); ++f) {
    const auto [k, w] = EasedSegment(f * frame_time_s, segment_s, 5);
    const auto a = static_cast<std::size_t>(k), b = a + 1;
    HumanoidPose p;  // the foot follows the shin (no ankle blend to lose volume)
    p.rotations[kLUpLeg] = Zxy(0, keys[a][0] + w * (keys[b][0] - keys[a][0]), 0);
    p.rotations[kLLeg] = Zxy(0, keys[a][1] + w * (keys[b][1] - keys[a][1]), 0);
    writer->Write(f, p);
  }
  return writer->Take();
}

base::Result<Motion> MakeTwistRamp(const Skeleton& humanoid, float end_deg, double duration_s,
                                   double frame_time_s) {
  auto writer = MotionWriter::Create(humanoid, frame_time_s, FramesFor(duration_s, frame_time_s));
  if (!writer.ok()) return std::move(writer).error();
  const int last = writer->num_frames() - 1;
  for (int f = 0; f <= last; ++f) {
    const double a = last > 0 ? end_deg * static_cast<double>(f) / last : end_deg;
    HumanoidPose p;
    p.rotations[kLForeArm] = Zxy(0, a, 0);  // about the bone axis (+X on the left)
    p.rotations[kRForeArm] = Zxy(0, -a, 0);
    writer->Write(f, p);
  }
  return writer->Take();
}

JumpTimeline MakeJumpTimeline(const JumpOptions& o) {
  JumpTimeline t{};
  const double g = kGravityCmPerS2;
  t.takeoff_speed_cm_per_s = std::sqrt(2.0 * g * std::max(o.height_cm, 0.0));
  const double v0 = t.takeoff_speed_cm_per_s;
  t.push_acceleration_cm_per_s2 = v0 * v0 / (2.0 * o.crouch_cm);
  t.landing_acceleration_cm_per_s2 = v0 * v0 / (2.0 * o.landing_crouch_cm);
  t.crouch_start_s = 0.3;
  t.push_start_s = t.crouch_start_s + 0.5;
  t.takeoff_s = t.push_start_s + 2.0 * o.crouch_cm / v0;
  t.touchdown_s = t.takeoff_s + 2.0 * v0 / g;
  t.landed_s = t.touchdown_s + 2.0 * o.landing_crouch_cm / v0;
  t.recovered_s = t.landed_s + 0.5;
  t.end_s = t.recovered_s + 0.3;
  return t;
}

base::Result<Motion> MakeJumpMotion(const Skeleton& humanoid, const JumpOptions& o) {
  const double leg = kThighCm + kShinCm;
  if (!(o.height_cm > 0.0) || !(o.crouch_cm > 0.0 && o.crouch_cm < leg) ||
      !(o.landing_crouch_cm > 0.0 && o.landing_crouch_cm < leg)) {
    return base::MakeError(
        base::ErrorCode::kInvalidArgument, {humanoid.info.source_file, 0, 0, {}},
        "expected a positive jump height and crouch depths below the leg length (84 cm)");
  }
  const JumpTimeline tl = MakeJumpTimeline(o);
  auto writer = MotionWriter::Create(humanoid, o.frame_time_s, FramesFor(tl.end_s, o.frame_time_s));
  if (!writer.ok()) return std::move(writer).error();
  const double g = kGravityCmPerS2;
  const double v0 = tl.takeoff_speed_cm_per_s;
  const auto hip_offset = [&](double t) {  // hips height relative to standing, cm
    if (t < tl.crouch_start_s) return 0.0;
    if (t < tl.push_start_s) {
      return -o.crouch_cm * 0.5 * (1.0 - std::cos(kPi * (t - tl.crouch_start_s) / 0.5));
    }
    if (t < tl.takeoff_s) {
      const double u = t - tl.push_start_s;
      return -o.crouch_cm + 0.5 * tl.push_acceleration_cm_per_s2 * u * u;
    }
    if (t < tl.touchdown_s) {
      const double u = t - tl.takeoff_s;
      return v0 * u - 0.5 * g * u * u;
    }
    if (t < tl.landed_s) {
      const double u = t - tl.touchdown_s;
      return -v0 * u + 0.5 * tl.landing_acceleration_cm_per_s2 * u * u;
    }
    if (t < tl.recovered_s) {
      return -o.landing_crouch_cm * 0.5 * (1.0 + std::cos(kPi * (t - tl.landed_s) / 0.5));
    }
    return 0.0;
  };
  for (int f = 0; f < writer->num_frames(); ++f) {
    const double t = writer->time(f);
    const double y = hip_offset(t);
    HumanoidPose p;
    p.root_position.y = static_cast<float>(kHipsRestY + y);
    // Two-bone IK with equal segments: the hip joint is (leg + y) above the ankle.
    const double reach = std::clamp((leg + std::min(y, 0.0)) / leg, -1.0, 1.0);
    const double bend = glm::degrees(std::acos(reach));  // thigh flexion; the knee bends twice that
    SetLeg(&p, kLUpLeg, -bend, 2.0 * bend);
    SetLeg(&p, kRUpLeg, -bend, 2.0 * bend);
    p.rotations[kSpine] = Zxy(0, 0.5 * bend, 0);  // lean over the knees
    p.rotations[kHead] = Zxy(0, -0.3 * bend, 0);
    const double depth = t < tl.takeoff_s ? std::clamp(-y / o.crouch_cm, 0.0, 1.0)
                                          : std::clamp(-y / o.landing_crouch_cm, 0.0, 1.0);
    p.rotations[kLArm] = Zxy(-75, 0, -40.0 * depth);
    p.rotations[kRArm] = Zxy(75, 0, 40.0 * depth);
    p.rotations[kLForeArm] = Zxy(0, 0, -15.0);
    p.rotations[kRForeArm] = Zxy(0, 0, 15.0);
    writer->Write(f, p);
  }
  return writer->Take();
}

base::Result<Skeleton> MakeChainSkeleton(int num_joints, float segment_length_cm) {
  if (num_joints < 1 || num_joints > kMaxJoints || !(segment_length_cm > 0.0f) ||
      !std::isfinite(segment_length_cm)) {
    return base::MakeError(base::ErrorCode::kInvalidArgument, {"synthetic:chain", 0, 0, {}},
                           "expected 1.." + std::to_string(kMaxJoints) +
                               " joints and a positive segment length, found " +
                               std::to_string(num_joints) + " joints of " +
                               std::to_string(segment_length_cm) + " cm");
  }
  Builder b;
  int parent = b.Add("Chain0", kNoParent, {0, 50, 0}, true);
  for (int j = 1; j < num_joints; ++j) {
    parent = b.Add("Chain" + std::to_string(j), parent, {0, 0, -segment_length_cm});
  }
  b.End(parent, {0, 0, -segment_length_cm});
  return b.Finish("synthetic:chain");
}

Skeleton MakeQuadrupedSkeleton() {
  Builder b;
  const int hips = b.Add("Hips", kNoParent, {0, 60, 0}, true);
  const int spine = b.Add("Spine", hips, {0, 2, 20});
  const int chest = b.Add("Chest", spine, {0, 0, 20});
  const int neck = b.Add("Neck", chest, {0, 8, 12});
  const int head = b.Add("Head", neck, {0, 10, 10});
  b.End(head, {0, 0, 18});
  for (const char* end : {"Front", "Hind"}) {
    const bool front = std::string(end) == "Front";
    for (float side : {1.0f, -1.0f}) {
      const std::string s = std::string(side > 0 ? "Left" : "Right") + end;
      // Front legs hang from the chest (y 62), hind legs from the hips (y 60).
      const int up =
          b.Add(s + "UpLeg", front ? chest : hips, {10 * side, front ? -6.0f : -4.0f, 0});
      const int leg = b.Add(s + "Leg", up, {0, -24, 0});
      const int foot = b.Add(s + "Foot", leg, {0, -24, 0});
      const int toe = b.Add(s + "ToeBase", foot, {0, -7, 5});
      b.End(toe, {0, 0, 5});
    }
  }
  const int tail = b.Add("Tail", hips, {0, 4, -10});
  const int tail1 = b.Add("Tail1", tail, {0, -3, -15});
  b.End(tail1, {0, -3, -15});
  Skeleton s = b.Finish("synthetic:quadruped");
  s.info.rest_height = 98.0f;
  return s;
}

}  // namespace synthetic
