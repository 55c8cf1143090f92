#include "mocap/kinematics.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "mocap/joint_angles.h"
#include "mocap/sampling.h"

namespace mocap {
namespace {

struct Sample {
  glm::dvec3 p;
  glm::dquat q;
};

Sample SampleOf(const glm::mat4& m) {
  glm::dmat3 r{glm::mat3(m)};  // float -> double after dropping translation
  for (int c = 0; c < 3; ++c) r[c] = glm::normalize(r[c]);  // remove scale
  return {glm::dvec3(m[3]), glm::normalize(glm::quat_cast(r))};
}

// Rotation vector (radians, shorter arc) of the rotation from a to b in model
// space: rv(b a^-1).
glm::dvec3 RelativeRotation(const glm::dquat& a, const glm::dquat& b) {
  glm::dquat d = b * glm::conjugate(a);
  if (d.w < 0.0) d = -d;
  const glm::dvec3 v(d.x, d.y, d.z);
  const double len = glm::length(v);
  if (len < 1e-15) return 2.0 * v;
  return v * (2.0 * std::atan2(len, d.w) / len);
}

glm::vec3 ToJointFrame(const glm::quat& r, const glm::vec3& v) { return glm::conjugate(r) * v; }

void FillLocal(JointKinematics* k) {
  k->local_linear_velocity = ToJointFrame(k->rotation, k->linear_velocity);
  k->local_linear_acceleration = ToJointFrame(k->rotation, k->linear_acceleration);
  k->local_angular_velocity = ToJointFrame(k->rotation, k->angular_velocity);
  k->local_angular_acceleration = ToJointFrame(k->rotation, k->angular_acceleration);
}

}  // namespace

base::JobStatus ModelMatricesJob::Validate() const {
  if (skeleton == nullptr || motion == nullptr) {
    return {base::JobStatus::kMissingInput, "skeleton and motion are required"};
  }
  const std::size_t num_joints = static_cast<std::size_t>(skeleton->num_joints());
  if (num_joints == 0) return {base::JobStatus::kMissingInput, "skeleton has no joints"};
  if (motion->num_channels != skeleton->num_channels) {
    return {base::JobStatus::kSizeMismatch, "motion and skeleton have different channel counts"};
  }
  if (locals.size() != num_joints) {
    return {base::JobStatus::kSizeMismatch, "locals must hold one transform per joint"};
  }
  if (model_from_joint.size() % num_joints != 0) {
    return {base::JobStatus::kSizeMismatch,
            "model_from_joint must hold whole frames of #J matrices"};
  }
  const std::size_t frames = model_from_joint.size() / num_joints;
  if (first_frame < 0 || static_cast<std::size_t>(first_frame) + frames >
                             static_cast<std::size_t>(std::max(motion->num_frames, 0))) {
    return {base::JobStatus::kOutOfRange, "frames outside the motion"};
  }
  if (motion->values.size() < static_cast<std::size_t>(motion->num_frames) *
                                  static_cast<std::size_t>(motion->num_channels)) {
    return {base::JobStatus::kOutOfRange, "motion values hold fewer than num_frames rows"};
  }
  return base::kJobOk;
}

base::JobStatus ModelMatricesJob::Run() const {
  const base::JobStatus status = Validate();
  if (!status) return status;
  const std::size_t num_joints = locals.size();
  const std::size_t frames = model_from_joint.size() / num_joints;
  for (std::size_t k = 0; k < frames; ++k) {
    const int f = first_frame + static_cast<int>(k);
    const base::JobStatus pose = LocalPoseJob{skeleton, motion->frame(f), locals}.Run();
    if (!pose) return pose;
    const base::JobStatus model =
        LocalToModelJob{.parents = skeleton->parents,
                        .locals = locals,
                        .model_from_root = model_from_root,
                        .model_from_joint = model_from_joint.subspan(k * num_joints, num_joints)}
            .Run();
    if (!model) return model;
  }
  return base::kJobOk;
}

base::JobStatus KinematicsJob::Validate() const {
  if (num_joints <= 0) return {base::JobStatus::kMissingInput, "num_joints must be positive"};
  const std::size_t nj = static_cast<std::size_t>(num_joints);
  if (model_from_joint.empty())
    return {base::JobStatus::kMissingInput, "model_from_joint is empty"};
  if (model_from_joint.size() % nj != 0 || output.size() % nj != 0) {
    return {base::JobStatus::kSizeMismatch, "model_from_joint and output must hold whole frames"};
  }
  if (!(frame_time_s > 0.0)) return {base::JobStatus::kOutOfRange, "frame_time_s must be positive"};
  const std::size_t total = model_from_joint.size() / nj;
  if (first_frame < 0 || static_cast<std::size_t>(first_frame) + output.size() / nj > total) {
    return {base::JobStatus::kOutOfRange, "output frames outside the motion"};
  }
  return base::kJobOk;
}

base::JobStatus KinematicsJob::Run() const {
  const base::JobStatus status = Validate();
  if (!status) return status;
  const std::size_t nj = static_cast<std::size_t>(num_joints);
  const int num_frames = static_cast<int>(model_from_joint.size() / nj);
  const int out_frames = static_cast<int>(output.size() / nj);
  const double h = frame_time_s;
  const auto at = [&](int f, std::size_t j) {
    return SampleOf(model_from_joint[static_cast<std::size_t>(f) * nj + j]);
  };
  for (int k = 0; k < out_frames; ++k) {
    const int f = first_frame + k;
    for (std::size_t j = 0; j < nj; ++j) {
      const Sample s = at(f, j);
      glm::dvec3 v(0.0), a(0.0), w(0.0), al(0.0);
      if (num_frames == 2) {
        const Sample s0 = at(0, j);
        const Sample s1 = at(1, j);
        v = (s1.p - s0.p) / h;
        w = RelativeRotation(s0.q, s1.q) / h;
      } else if (num_frames >= 3) {
        // The three frames whose second differences give a and al (frame 1 at
        // frame 0, frame #F-2 at the last: first order there).
        const int c = std::clamp(f, 1, num_frames - 2);
        const Sample m = at(c - 1, j);
        const Sample o = at(c, j);
        const Sample p = at(c + 1, j);
        a = (p.p - 2.0 * o.p + m.p) / (h * h);
        al = (RelativeRotation(o.q, p.q) - RelativeRotation(m.q, o.q)) / (h * h);
        if (f == c) {
          v = (p.p - m.p) / (2.0 * h);
          w = RelativeRotation(m.q, p.q) / (2.0 * h);
        } else {
          // One-sided second-order differences from the end frame e towards the
          // inside: x'(e) = dir (-3 x_e + 4 x_e1 - x_e2) / 2h, dir = +1 at the start.
          const double dir = f == 0 ? 1.0 : -1.0;
          const Sample s1 = at(f + static_cast<int>(dir), j);
          const Sample s2 = at(f + 2 * static_cast<int>(dir), j);
          v = dir * (-3.0 * s.p + 4.0 * s1.p - s2.p) / (2.0 * h);
          w = dir * (4.0 * RelativeRotation(s.q, s1.q) - RelativeRotation(s.q, s2.q)) / (2.0 * h);
        }
      }
      JointKinematics& out = output[static_cast<std::size_t>(k) * nj + j];
      out.position = glm::vec3(s.p);
      out.rotation = glm::quat(s.q);
      out.linear_velocity = glm::vec3(v);
      out.linear_acceleration = glm::vec3(a);
      out.angular_velocity = glm::vec3(w);
      out.angular_acceleration = glm::vec3(al);
      FillLocal(&out);
    }
  }
  return base::kJobOk;
}

base::JobStatus SmoothTrajectoriesJob::Validate() const {
  const base::JobStatus base = KinematicsJob{
      .model_from_joint = model_from_joint,
      .num_joints = num_joints,
      .frame_time_s = frame_time_s,
      .first_frame = first_frame,
      .output = {}}.Validate();
  if (!base) return base;
  if (output.size() % static_cast<std::size_t>(num_joints) != 0) {
    return {base::JobStatus::kSizeMismatch, "output must hold whole frames"};
  }
  if (static_cast<std::size_t>(first_frame) * static_cast<std::size_t>(num_joints) + output.size() >
      model_from_joint.size()) {
    return {base::JobStatus::kOutOfRange, "output frames outside the motion"};
  }
  if (!(cutoff_hz > 0.0) || !std::isfinite(cutoff_hz)) {
    return {base::JobStatus::kOutOfRange, "cutoff_hz must be positive and finite"};
  }
  return base::kJobOk;
}

base::JobStatus SmoothTrajectoriesJob::Run() const {
  const base::JobStatus status = Validate();
  if (!status) return status;
  const std::size_t nj = static_cast<std::size_t>(num_joints);
  const int num_frames = static_cast<int>(model_from_joint.size() / nj);
  const int out_frames = static_cast<int>(output.size() / nj);
  const double sigma_frames =
      std::sqrt(std::log(2.0)) / (2.0 * std::numbers::pi * cutoff_hz) / frame_time_s;
  // Radius capped so a tiny cutoff cannot make the window unbounded.
  const int radius = static_cast<int>(std::min(std::floor(3.0 * sigma_frames), 1e4));
  for (int k = 0; k < out_frames; ++k) {
    const int f = first_frame + k;
    const int lo = std::max(0, f - radius);
    const int hi = std::min(num_frames - 1, f + radius);
    for (std::size_t j = 0; j < nj; ++j) {
      const glm::mat4& centre = model_from_joint[static_cast<std::size_t>(f) * nj + j];
      glm::mat4& out = output[static_cast<std::size_t>(k) * nj + j];
      if (radius == 0) {
        out = centre;
        continue;
      }
      const Sample c = SampleOf(centre);
      glm::dvec3 p(0.0);
      glm::dquat q(0.0, 0.0, 0.0, 0.0);
      double total = 0.0;
      for (int i = lo; i <= hi; ++i) {
        const double u = (i - f) / sigma_frames;
        const double w = std::exp(-0.5 * u * u);
        const Sample s = SampleOf(model_from_joint[static_cast<std::size_t>(i) * nj + j]);
        p += w * s.p;
        q += (glm::dot(s.q, c.q) < 0.0 ? -w : w) * s.q;
        total += w;
      }
      p /= total;
      const glm::mat3 r = glm::mat3_cast(glm::quat(glm::normalize(q)));
      for (int col = 0; col < 3; ++col) {
        out[col] = glm::vec4(r[col] * glm::length(glm::vec3(centre[col])), 0.0f);
      }
      out[3] = glm::vec4(glm::vec3(p), 1.0f);
    }
  }
  return base::kJobOk;
}

base::Result<std::vector<JointKinematics>> ComputeKinematics(const Skeleton& skeleton,
                                                             const Motion& motion, double cutoff_hz,
                                                             const glm::mat4& model_from_root) {
  const base::FileLoc loc{skeleton.info.source_file, 0, 0, {}};
  const std::size_t nj = static_cast<std::size_t>(skeleton.num_joints());
  if (nj == 0 || motion.num_frames < 1 || motion.num_channels != skeleton.num_channels ||
      !(motion.frame_time_s > 0.0) ||
      motion.values.size() != static_cast<std::size_t>(motion.num_frames) *
                                  static_cast<std::size_t>(motion.num_channels)) {
    return base::InvalidArgument(loc, "expected a motion with frames, a positive frame time and " +
                                          std::to_string(skeleton.num_channels) +
                                          " channels per frame for " + std::to_string(nj) +
                                          " joints");
  }
  const auto fail = [&](const char* what) {
    return base::InvalidArgument(loc, std::string("joint kinematics: ") + what);
  };
  const std::size_t frames = static_cast<std::size_t>(motion.num_frames);
  std::vector<JointTransform> locals(nj);
  std::vector<glm::mat4> model(frames * nj);
  const base::JobStatus m = ModelMatricesJob{.skeleton = &skeleton,
                                             .motion = &motion,
                                             .model_from_root = model_from_root,
                                             .locals = locals,
                                             .model_from_joint = model}
                                .Run();
  if (!m) return fail(m.what);
  if (cutoff_hz > 0.0) {
    std::vector<glm::mat4> smooth(frames * nj);
    const base::JobStatus s = SmoothTrajectoriesJob{.model_from_joint = model,
                                                    .num_joints = static_cast<int>(nj),
                                                    .frame_time_s = motion.frame_time_s,
                                                    .cutoff_hz = cutoff_hz,
                                                    .output = smooth}
                                  .Run();
    if (!s) return fail(s.what);
    model = std::move(smooth);
  }
  std::vector<JointKinematics> out(frames * nj);
  const base::JobStatus k = KinematicsJob{.model_from_joint = model,
                                          .num_joints = static_cast<int>(nj),
                                          .frame_time_s = motion.frame_time_s,
                                          .output = out}
                                .Run();
  if (!k) return fail(k.what);
  return out;
}

base::Result<std::vector<JointKinematics>> ComputeKinematicsOf(const Skeleton& skeleton,
                                                               const Motion& motion,
                                                               std::span<const int> joints,
                                                               double cutoff_hz,
                                                               const glm::mat4& model_from_root) {
  const auto fail = [&](const std::string& what) {
    return base::InvalidArgument({skeleton.info.source_file, 0, 0, {}},
                                 "joint kinematics: " + what);
  };
  const std::size_t nj = static_cast<std::size_t>(skeleton.num_joints());
  const std::size_t nd = joints.size();
  if (nd == 0) return fail("no driving joints");
  for (std::size_t d = 0; d < nd; ++d) {
    if (joints[d] < 0 || static_cast<std::size_t>(joints[d]) >= nj) {
      return fail("driving joint " + std::to_string(joints[d]) + " out of range");
    }
    if (std::find(joints.begin(), joints.begin() + static_cast<std::ptrdiff_t>(d), joints[d]) !=
        joints.begin() + static_cast<std::ptrdiff_t>(d)) {
      return fail("driving joint " + std::to_string(joints[d]) + " listed twice");
    }
  }
  if (motion.num_frames < 1) return fail("motion has no frames");
  const std::size_t nf = static_cast<std::size_t>(motion.num_frames);
  // Model matrices of every joint, a chunk of frames at a time; keep the
  // driving columns. Each frame's matrices depend on that frame alone.
  constexpr std::size_t kChunkFrames = 256;
  std::vector<JointTransform> locals(nj);
  std::vector<glm::mat4> chunk(nj * std::min(kChunkFrames, nf));
  std::vector<glm::mat4> raw(nd * nf);
  for (std::size_t first = 0; first < nf; first += kChunkFrames) {
    const std::size_t count = std::min(kChunkFrames, nf - first);
    const std::span<glm::mat4> out = std::span(chunk).first(count * nj);
    const base::JobStatus s = ModelMatricesJob{.skeleton = &skeleton,
                                               .motion = &motion,
                                               .first_frame = static_cast<int>(first),
                                               .model_from_root = model_from_root,
                                               .locals = locals,
                                               .model_from_joint = out}
                                  .Run();
    if (!s) return fail(s.what);
    for (std::size_t k = 0; k < count; ++k) {
      for (std::size_t d = 0; d < nd; ++d) {
        raw[(first + k) * nd + d] = out[k * nj + static_cast<std::size_t>(joints[d])];
      }
    }
  }
  chunk = {};
  locals = {};
  const int num_columns = static_cast<int>(nd);
  if (cutoff_hz > 0.0) {
    std::vector<glm::mat4> smooth(nd * nf);
    const base::JobStatus s = SmoothTrajectoriesJob{.model_from_joint = raw,
                                                    .num_joints = num_columns,
                                                    .frame_time_s = motion.frame_time_s,
                                                    .cutoff_hz = cutoff_hz,
                                                    .output = smooth}
                                  .Run();
    if (!s) return fail(s.what);
    raw = std::move(smooth);  // frees the unsmoothed columns before kin is allocated
  }
  std::vector<JointKinematics> kin(nd * nf);
  const base::JobStatus s = KinematicsJob{.model_from_joint = raw,
                                          .num_joints = num_columns,
                                          .frame_time_s = motion.frame_time_s,
                                          .output = kin}
                                .Run();
  if (!s) return fail(s.what);
  return kin;
}

base::JobStatus SampleJointKinematics(std::span<const JointKinematics> kinematics, int num_joints,
                                      int joint, double frame_time_s, double time_s,
                                      JointKinematics* out) {
  if (out == nullptr || kinematics.empty())
    return {base::JobStatus::kMissingInput, "no buffer or no output"};
  if (num_joints <= 0 || joint < 0 || joint >= num_joints) {
    return {base::JobStatus::kOutOfRange, "joint outside [0, num_joints)"};
  }
  const std::size_t nj = static_cast<std::size_t>(num_joints);
  if (kinematics.size() % nj != 0)
    return {base::JobStatus::kSizeMismatch, "buffer is not whole frames"};
  if (!(frame_time_s > 0.0)) return {base::JobStatus::kOutOfRange, "frame_time_s must be positive"};
  const int num_frames = static_cast<int>(kinematics.size() / nj);
  const FrameBlend b = FindFrameBlend(num_frames, frame_time_s, time_s);
  const std::size_t js = static_cast<std::size_t>(joint);
  const JointKinematics& k0 = kinematics[static_cast<std::size_t>(b.frame0) * nj + js];
  if (b.frame1 == b.frame0) {
    *out = k0;
    return base::kJobOk;
  }
  const JointKinematics& k1 = kinematics[static_cast<std::size_t>(b.frame1) * nj + js];
  const double s = b.weight;
  const double h = frame_time_s;
  const double s2 = s * s;
  const double s3 = s2 * s;
  const double h00 = 2 * s3 - 3 * s2 + 1;  // cubic Hermite basis
  const double h10 = s3 - 2 * s2 + s;
  const double h01 = -2 * s3 + 3 * s2;
  const double h11 = s3 - s2;
  const glm::dvec3 p = h00 * glm::dvec3(k0.position) + h10 * h * glm::dvec3(k0.linear_velocity) +
                       h01 * glm::dvec3(k1.position) + h11 * h * glm::dvec3(k1.linear_velocity);
  const float w = b.weight;
  const auto lerp = [w](const glm::vec3& x, const glm::vec3& y) { return x + w * (y - x); };
  out->position = glm::vec3(p);
  out->rotation = SlerpShortest(k0.rotation, k1.rotation, w);
  out->linear_velocity = lerp(k0.linear_velocity, k1.linear_velocity);
  out->linear_acceleration = lerp(k0.linear_acceleration, k1.linear_acceleration);
  out->angular_velocity = lerp(k0.angular_velocity, k1.angular_velocity);
  out->angular_acceleration = lerp(k0.angular_acceleration, k1.angular_acceleration);
  FillLocal(out);
  return base::kJobOk;
}

}  // namespace mocap
