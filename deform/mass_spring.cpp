#include "deform/mass_spring.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <string>
#include <utility>

#include "deform/internal/driving_sampler.h"
#include "deform/internal/mass_spring_modal.h"
#include "deform/internal/stage_forcing.h"

namespace deform {
namespace {

using mocap::ErrorCode;
using mocap::FileLoc;
using mocap::MakeError;

constexpr double kStandardGravityMps2 = 9.81;
constexpr int kMaxGridSize = 16;
constexpr int kMaxFree = (kMaxGridSize - 2) * (kMaxGridSize - 2);
// Modal steps whose stage coefficients are computed together (one 30 fps frame
// at h = 1/240 s).
constexpr std::size_t kBatchSteps = 8;

bool Finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Everything the forces need at one stage time, per unit mass.
struct Forcing {
  glm::vec3 common{0.0f};  // -gam a + (R^T g - R_bind^T g) + u: the same for every point
  glm::vec3 w{0.0f};       // angular velocity (frame)
  glm::vec3 al{0.0f};      // angular acceleration (frame)
  float gain = 1.0f;
};

// -gam [al x k + w x (w x k)]: the rigid part of R^T K'' that depends on the
// point's position k in the frame (Euler and centrifugal terms).
inline glm::vec3 RigidTerm(const Forcing& f, const glm::vec3& k) {
  return -f.gain * (glm::cross(f.al, k) + glm::cross(f.w, glm::cross(f.w, k)));
}

// -gam [2 w x e' + al x e + w x (w x e)]: Coriolis, Euler and centrifugal on e.
inline glm::vec3 MovingFrameTerm(const Forcing& f, const glm::vec3& e, const glm::vec3& v) {
  return -f.gain * (2.0f * glm::cross(f.w, v) + glm::cross(f.al, e) +
                    glm::cross(f.w, glm::cross(f.w, e)));
}

// A batch's frames and coefficients without the default member initializers'
// zero fill (2.3 KB a run).
struct BatchStorage {
  union Frames {
    Frames() {}
    DrivingFrame at[2 * kBatchSteps];
  } frames;
  union Coefficients {
    Coefficients() {}
    internal::StageCoefficients at[2 * kBatchSteps + 1];
  } coeffs;
};

class Integrator {
 public:
  explicit Integrator(const MassSpringStepJob& job)
      : job_(job), net_(*job.network), st_(*job.state), p_(job.network->params) {
    const double g = kStandardGravityMps2 * p_.units_per_metre;
    gravity_ = glm::vec3(glm::dvec3(glm::normalize(p_.down)) * g);
    gravity_bind_ = glm::conjugate(net_.bind_rotation) * gravity_;
    max_accel_ = p_.max_acceleration_mps2 * p_.units_per_metre;
    // Below this |a|^2 the length is certainly <= max_accel_ (float rounding of
    // the square is far inside 1%), so most samples skip the square root.
    surely_below_accel2_ = 0.99f * max_accel_ * max_accel_;
    if (!job.kinematics.empty()) {
      sampler_.emplace(job.kinematics, job.num_joints, job.joint, job.frame_time_s);
    }
    forcing_ = {.gain = p_.gain, .user_acceleration = job.user_acceleration,
                .gravity = p_.gravity, .gravity_model = gravity_, .gravity_bind = gravity_bind_};
  }

  // The driving frame at t, checked: a non-finite frame becomes the bind frame,
  // |a| is clamped (both counted).
  DrivingFrame CheckedFrame(double t) {
    // Kinematics: SampleJointKinematics' values (internal/driving_sampler.h).
    DrivingFrame d = sampler_ ? sampler_->Sample(t) : (*job_.driving)(t);
    MassSpringCounters& c = st_.counters;
    const glm::vec4 q(d.rotation.x, d.rotation.y, d.rotation.z, d.rotation.w);
    if (!Finite(d.linear_acceleration) || !Finite(d.angular_velocity) ||
        !Finite(d.angular_acceleration) || !std::isfinite(glm::dot(q, q)) ||
        glm::dot(q, q) < 1e-12f) {
      ++c.non_finite_inputs;  // a glitch: the frame is taken as at rest in the bind pose
      d = DrivingFrame{net_.bind_rotation};
    }
    if (glm::dot(d.linear_acceleration, d.linear_acceleration) > surely_below_accel2_) {
      const float a_len = glm::length(d.linear_acceleration);
      if (a_len > max_accel_) {
        ++c.acceleration_clamps;
        d.linear_acceleration *= max_accel_ / a_len;
      }
    }
    return d;
  }

  Forcing Sample(double t) {
    const DrivingFrame d = CheckedFrame(t);
    Forcing f;
    f.gain = p_.gain;
    f.w = d.angular_velocity;
    f.al = d.angular_acceleration;
    f.common = -p_.gain * d.linear_acceleration + job_.user_acceleration;
    if (p_.gravity) {
      f.common += glm::conjugate(glm::normalize(d.rotation)) * gravity_ - gravity_bind_;
    }
    return f;
  }

  // Whole RK4 steps of every mode until the step time reaches `until_s`. The
  // modes live in padded structure-of-arrays buffers for the run (two pairs:
  // the newest step and the one before, swapped after each step); the state's
  // vec3 arrays are read once before and written once after.
  void ModalSteps(double until_s) {
    const std::size_t n = static_cast<std::size_t>(net_.num_free);
    const std::size_t stride = static_cast<std::size_t>(net_.mode_stride);
    alignas(32) float buffers[4][3 * internal::kMaxModeStride];
    float* x = buffers[0];
    float* v = buffers[1];
    float* prev_x = buffers[2];
    float* prev_v = buffers[3];
    std::fill(x, x + 3 * stride, 0.0f);
    std::fill(v, v + 3 * stride, 0.0f);
    for (std::size_t k = 0; k < n; ++k) {
      for (std::size_t c = 0; c < 3; ++c) {
        x[c * stride + k] = st_.position[k][static_cast<int>(c)];
        v[c * stride + k] = st_.velocity[k][static_cast<int>(c)];
      }
    }
    const internal::ModalStepFn step = internal::SelectModalStep(job_.allow_avx, job_.allow_fma);
    const double h = net_.time_step_s;
    // Steps go in batches of up to kBatchSteps: the frames at the batch's stage
    // times first (t + h/2, t + h, t + 3h/2, ...: the times and the order of the
    // step-by-step loop), their coefficients four at a time
    // (internal/stage_forcing.h: the same bits), then the steps. coeffs[2 i],
    // [2 i + 1], [2 i + 2]: step i's start, middle and end.
    BatchStorage batch;  // left uninitialized: every entry is written before it is read
    DrivingFrame* const frames = batch.frames.at;
    internal::StageCoefficients* const coeffs = batch.coeffs.at;
    frames[0] = CheckedFrame(st_.step_time_s);
    internal::StageCoefficientsOfEach({frames, 1}, forcing_, {coeffs, 1});
    while (st_.step_time_s < until_s) {
      double starts[kBatchSteps];
      std::size_t count = 0;
      for (double t = st_.step_time_s; count < kBatchSteps && t < until_s; t = t + h) {
        starts[count++] = t;
      }
      for (std::size_t i = 0; i < count; ++i) {
        frames[2 * i] = CheckedFrame(starts[i] + 0.5 * h);
        frames[2 * i + 1] = CheckedFrame(starts[i] + h);
      }
      internal::StageCoefficientsOfEach({frames, 2 * count}, forcing_, {coeffs + 1, 2 * count});
      for (std::size_t i = 0; i < count; ++i) {
        const internal::ModalStepSums sums =
            step(net_, coeffs[2 * i], coeffs[2 * i + 1], coeffs[2 * i + 2],
                 static_cast<float>(h), x, v, prev_x, prev_v);
        std::swap(x, prev_x);
        std::swap(v, prev_v);
        ModalLimits(sums, x, v, prev_x, prev_v);
        st_.step_time_s = starts[i] + h;
        ++st_.counters.steps;
      }
      coeffs[0] = coeffs[2 * count];
    }
    for (std::size_t k = 0; k < n; ++k) {
      for (std::size_t c = 0; c < 3; ++c) {
        const int ci = static_cast<int>(c);
        st_.position[k][ci] = x[c * stride + k];
        st_.velocity[k][ci] = v[c * stride + k];
        st_.prev_position[k][ci] = prev_x[c * stride + k];
        st_.prev_velocity[k][ci] = prev_v[c * stride + k];
      }
    }
  }

  // ApplyLimits on the modal buffers (3 x stride each) of the newest step.
  void ModalLimits(const internal::ModalStepSums& sums, float* x, float* v, float* prev_x,
                   float* prev_v) {
    const std::size_t n = static_cast<std::size_t>(net_.num_free);
    const std::size_t stride = static_cast<std::size_t>(net_.mode_stride);
    if (!std::isfinite(sums.sum_x) || !std::isfinite(sums.sum_v)) {
      ++st_.counters.non_finite_resets;
      for (float* a : {x, v, prev_x, prev_v}) std::fill(a, a + 3 * stride, 0.0f);
      return;
    }
    // U is orthonormal, so |e_a|^2 <= sum_k |eta_k|^2; also |e_a| <= sum_k u_k |eta_k|
    // with u_k = max_a |U[a, k]|. Below e_max by either bound nothing can exceed.
    const float e_max = p_.max_displacement;
    if (sums.sum_x <= e_max * e_max) return;
    const float* u_max = net_.mode_lanes.data() + internal::kLaneMaxAbs * stride;
    float bound = 0.0f;
    for (std::size_t k = 0; k < n; ++k) {
      bound += u_max[k] * glm::length(glm::vec3(x[k], x[stride + k], x[2 * stride + k]));
    }
    if (bound <= e_max) return;
    alignas(32) float e[3 * internal::kMaxModeStride];
    internal::ModalToPoints(net_, x, e, job_.allow_avx);
    const auto point = [stride](const float* f, std::size_t a) {
      return glm::vec3(f[a], f[stride + a], f[2 * stride + a]);
    };
    bool any = false;
    for (std::size_t a = 0; a < n && !any; ++a) any = glm::length(point(e, a)) > e_max;
    if (!any) return;
    // The clamp itself (rare): point space, then back to modes.
    alignas(32) float ev[3 * internal::kMaxModeStride];
    internal::ModalToPoints(net_, v, ev, job_.allow_avx);
    for (std::size_t a = 0; a < n; ++a) {
      glm::vec3 ea = point(e, a), va = point(ev, a);
      const float len = glm::length(ea);
      if (len <= e_max) continue;
      const glm::vec3 dir = ea / len;
      ea = dir * e_max;
      const float outward = glm::dot(va, dir);
      if (outward > 0.0f) va -= outward * dir;
      ++st_.counters.displacement_clamps;
      for (std::size_t c = 0; c < 3; ++c) {
        e[c * stride + a] = ea[static_cast<int>(c)];
        ev[c * stride + a] = va[static_cast<int>(c)];
      }
    }
    internal::PointsToModal(net_, e, x, job_.allow_avx);
    internal::PointsToModal(net_, ev, v, job_.allow_avx);
  }

  // Accelerations of every free point from point-space springs.
  void PointAccelerations(const Forcing& f, std::span<const glm::vec3> e,
                          std::span<const glm::vec3> v, std::span<glm::vec3> acc) const {
    const int n = net_.num_free;
    const float inv_m = 1.0f / p_.mass;
    for (int a = 0; a < n; ++a) {
      const std::size_t as = static_cast<std::size_t>(a);
      const glm::vec3 k = net_.rest_points[static_cast<std::size_t>(net_.point_of_free[as])];
      acc[as] = inv_m * (-net_.anchor_stiffness * e[as] - net_.anchor_damping * v[as]) +
                f.common + RigidTerm(f, k) + MovingFrameTerm(f, e[as], v[as]);
    }
    const bool length_model = p_.force_model == SpringForceModel::kLength;
    for (const Spring& s : net_.springs) {
      const std::size_t fa = static_cast<std::size_t>(s.free_a);
      const std::size_t fb = static_cast<std::size_t>(s.free_b);
      const glm::vec3 ea = s.free_a >= 0 ? e[fa] : glm::vec3(0.0f);
      const glm::vec3 eb = s.free_b >= 0 ? e[fb] : glm::vec3(0.0f);
      const glm::vec3 va = s.free_a >= 0 ? v[fa] : glm::vec3(0.0f);
      const glm::vec3 vb = s.free_b >= 0 ? v[fb] : glm::vec3(0.0f);
      glm::vec3 force = -s.damping * (va - vb);  // on a
      if (length_model) {
        const glm::vec3 d = net_.rest_points[static_cast<std::size_t>(s.point_a)] + ea -
                            net_.rest_points[static_cast<std::size_t>(s.point_b)] - eb;
        const float len = glm::length(d);
        if (len > 0.0f) force -= s.stiffness * (len - s.rest_length) / len * d;
      } else {
        force -= s.stiffness * (ea - eb);
      }
      if (s.free_a >= 0) acc[fa] += inv_m * force;
      if (s.free_b >= 0) acc[fb] -= inv_m * force;
    }
  }

  void PointStep(double h_d, const Forcing& f0, const Forcing& fm, const Forcing& f1) {
    const float h = static_cast<float>(h_d);
    const std::size_t n = static_cast<std::size_t>(net_.num_free);
    std::span<glm::vec3> w(st_.work);
    std::span<glm::vec3> xs = w.subspan(0, n), vs = w.subspan(n, n), acc = w.subspan(2 * n, n),
                         sx = w.subspan(3 * n, n), sv = w.subspan(4 * n, n);
    std::span<glm::vec3> x(st_.position), v(st_.velocity);
    PointAccelerations(f0, x, v, acc);  // stage 1
    for (std::size_t a = 0; a < n; ++a) {
      sx[a] = v[a];
      sv[a] = acc[a];
      xs[a] = x[a] + 0.5f * h * v[a];
      vs[a] = v[a] + 0.5f * h * acc[a];
    }
    PointAccelerations(fm, xs, vs, acc);  // stage 2
    for (std::size_t a = 0; a < n; ++a) {
      sx[a] += 2.0f * vs[a];
      sv[a] += 2.0f * acc[a];
      xs[a] = x[a] + 0.5f * h * vs[a];
      vs[a] = v[a] + 0.5f * h * acc[a];
    }
    PointAccelerations(fm, xs, vs, acc);  // stage 3
    for (std::size_t a = 0; a < n; ++a) {
      sx[a] += 2.0f * vs[a];
      sv[a] += 2.0f * acc[a];
      xs[a] = x[a] + h * vs[a];
      vs[a] = v[a] + h * acc[a];
    }
    PointAccelerations(f1, xs, vs, acc);  // stage 4
    for (std::size_t a = 0; a < n; ++a) {
      sx[a] += vs[a];
      sv[a] += acc[a];
      st_.prev_position[a] = x[a];
      st_.prev_velocity[a] = v[a];
      x[a] += (h / 6.0f) * sx[a];
      v[a] += (h / 6.0f) * sv[a];
    }
  }

  // |e_a| <= e_max with the outward velocity removed; non-finite state resets
  // (point-space state; ModalLimits does the same for the modes).
  void ApplyLimits() {
    const std::size_t n = static_cast<std::size_t>(net_.num_free);
    const float e_max = p_.max_displacement;
    float sum_x = 0.0f, sum_v = 0.0f;
    for (std::size_t a = 0; a < n; ++a) {
      sum_x += glm::dot(st_.position[a], st_.position[a]);
      sum_v += glm::dot(st_.velocity[a], st_.velocity[a]);
    }
    if (!std::isfinite(sum_x) || !std::isfinite(sum_v)) {
      ++st_.counters.non_finite_resets;
      std::fill(st_.position.begin(), st_.position.end(), glm::vec3(0.0f));
      std::fill(st_.velocity.begin(), st_.velocity.end(), glm::vec3(0.0f));
      std::fill(st_.prev_position.begin(), st_.prev_position.end(), glm::vec3(0.0f));
      std::fill(st_.prev_velocity.begin(), st_.prev_velocity.end(), glm::vec3(0.0f));
      return;
    }
    if (sum_x <= e_max * e_max) return;
    std::span<glm::vec3> e(st_.position), v(st_.velocity);
    for (std::size_t a = 0; a < n; ++a) {
      const float len = glm::length(e[a]);
      if (len <= e_max) continue;
      const glm::vec3 dir = e[a] / len;
      e[a] = dir * e_max;
      const float outward = glm::dot(v[a], dir);
      if (outward > 0.0f) v[a] -= outward * dir;
      ++st_.counters.displacement_clamps;
    }
  }

 private:
  const MassSpringStepJob& job_;
  const MassSpringNetwork& net_;
  MassSpringState& st_;
  const MassSpringParams& p_;
  glm::vec3 gravity_{0.0f}, gravity_bind_{0.0f};
  float max_accel_ = 0.0f, surely_below_accel2_ = 0.0f;
  std::optional<internal::KinematicsDrivingSampler> sampler_;
  internal::ForcingConstants forcing_;
};

bool UsesModes(const MassSpringNetwork& net) {
  return net.params.force_model == SpringForceModel::kLinear &&
         net.params.solver == MassSpringSolver::kModal;
}

}  // namespace

void MassSpringState::Resize(const MassSpringNetwork& network) {
  const std::size_t n = static_cast<std::size_t>(network.num_free);
  position.assign(n, glm::vec3(0.0f));
  velocity.assign(n, glm::vec3(0.0f));
  prev_position.assign(n, glm::vec3(0.0f));
  prev_velocity.assign(n, glm::vec3(0.0f));
  work.assign(5 * n, glm::vec3(0.0f));
  Reset();
}

void MassSpringState::Reset() {
  started = false;
  step_time_s = output_time_s = 0.0;
  std::fill(position.begin(), position.end(), glm::vec3(0.0f));
  std::fill(velocity.begin(), velocity.end(), glm::vec3(0.0f));
  std::fill(prev_position.begin(), prev_position.end(), glm::vec3(0.0f));
  std::fill(prev_velocity.begin(), prev_velocity.end(), glm::vec3(0.0f));
}

JobStatus MassSpringStepJob::Validate() const {
  if (network == nullptr || state == nullptr) return {JobStatus::kMissingInput, "no network or state"};
  if (kinematics.empty() && (driving == nullptr || !*driving)) {
    return {JobStatus::kMissingInput, "no kinematics and no driving callback"};
  }
  const std::size_t n = static_cast<std::size_t>(network->num_free);
  if (state->position.size() != n || state->velocity.size() != n ||
      state->prev_position.size() != n || state->prev_velocity.size() != n ||
      state->work.size() != 5 * n) {
    return {JobStatus::kSizeMismatch, "state not sized for the network (call Resize)"};
  }
  const std::size_t num_points = static_cast<std::size_t>(network->rows * network->cols);
  if (!displacements.empty() && displacements.size() != num_points) {
    return {JobStatus::kSizeMismatch, "displacements must hold M*N entries"};
  }
  if (!kinematics.empty()) {
    if (num_joints <= 0 || joint < 0 || joint >= num_joints || !(frame_time_s > 0.0)) {
      return {JobStatus::kOutOfRange, "kinematics: joint, num_joints or frame_time_s"};
    }
    if (kinematics.size() % static_cast<std::size_t>(num_joints) != 0) {
      return {JobStatus::kSizeMismatch, "kinematics is not a whole number of frames"};
    }
  }
  if (!std::isfinite(time_s)) return {JobStatus::kOutOfRange, "time_s is not finite"};
  return mocap::kJobOk;
}

JobStatus MassSpringStepJob::Run() const {
  const JobStatus status = Validate();
  if (!status) return status;
  const MassSpringNetwork& net = *network;
  MassSpringState& st = *state;
  const MassSpringParams& p = net.params;
  const double h = net.time_step_s;
  const double eps = 1e-9;
  if (!st.started || time_s < st.output_time_s - eps ||
      time_s > st.output_time_s + p.max_time_gap_s) {
    st.Reset();
    st.started = true;
    ++st.counters.time_resets;
    st.step_time_s = time_s - p.preroll_s;
  }
  const bool modal = UsesModes(net);
  Integrator integrator(*this);
  if (modal && st.step_time_s < time_s - eps) {
    integrator.ModalSteps(time_s - eps);
  } else if (st.step_time_s < time_s - eps) {
    Forcing f0 = integrator.Sample(st.step_time_s);
    while (st.step_time_s < time_s - eps) {
      const double t = st.step_time_s;
      const Forcing fm = integrator.Sample(t + 0.5 * h);
      const Forcing f1 = integrator.Sample(t + h);
      integrator.PointStep(h, f0, fm, f1);
      integrator.ApplyLimits();
      st.step_time_s = t + h;
      ++st.counters.steps;
      f0 = f1;
    }
  }
  st.output_time_s = time_s;
  if (displacements.empty()) return mocap::kJobOk;

  // Linear interpolation between the last two steps (exact when no step was taken
  // since a reset: both are the same zero state).
  const std::size_t n = static_cast<std::size_t>(net.num_free);
  const float alpha = static_cast<float>(std::clamp((time_s - (st.step_time_s - h)) / h, 0.0, 1.0));
  std::span<glm::vec3> blended = std::span<glm::vec3>(st.work).subspan(2 * n, n);
  for (std::size_t a = 0; a < n; ++a) {
    blended[a] = st.prev_position[a] + alpha * (st.position[a] - st.prev_position[a]);
  }
  std::fill(displacements.begin(), displacements.end(), glm::vec3(0.0f));
  if (modal) {  // e = U eta with the modes in lanes (internal/mass_spring_modal.h)
    const std::size_t stride = static_cast<std::size_t>(net.mode_stride);
    alignas(32) float eta[3 * internal::kMaxModeStride];
    alignas(32) float e[3 * internal::kMaxModeStride];
    std::fill(eta, eta + 3 * stride, 0.0f);  // the padding lanes
    for (std::size_t k = 0; k < n; ++k) {
      for (std::size_t c = 0; c < 3; ++c) eta[c * stride + k] = blended[k][static_cast<int>(c)];
    }
    internal::ModalToPoints(net, eta, e, allow_avx);
    for (std::size_t a = 0; a < n; ++a) {
      displacements[static_cast<std::size_t>(net.point_of_free[a])] =
          glm::vec3(e[a], e[stride + a], e[2 * stride + a]);
    }
    return mocap::kJobOk;
  }
  for (std::size_t a = 0; a < n; ++a) {
    displacements[static_cast<std::size_t>(net.point_of_free[a])] = blended[a];
  }
  return mocap::kJobOk;
}

namespace {
void ToPointSpace(const MassSpringNetwork& net, std::span<const glm::vec3> in,
                  std::span<glm::vec3> out) {
  const std::size_t n = static_cast<std::size_t>(net.num_free);
  if (!UsesModes(net)) {
    std::copy(in.begin(), in.end(), out.begin());
    return;
  }
  for (std::size_t a = 0; a < n; ++a) {
    glm::vec3 sum(0.0f);
    for (std::size_t k = 0; k < n; ++k) sum += net.modes[a * n + k] * in[k];
    out[a] = sum;
  }
}
}  // namespace

void MassSpringPointDisplacements(const MassSpringNetwork& network, const MassSpringState& state,
                                  std::span<glm::vec3> out) {
  ToPointSpace(network, state.position, out);
}

double MassSpringEnergy(const MassSpringNetwork& network, const MassSpringState& state) {
  const std::size_t n = static_cast<std::size_t>(network.num_free);
  std::vector<glm::vec3> e(n), v(n);
  ToPointSpace(network, state.position, e);
  ToPointSpace(network, state.velocity, v);
  double energy = 0.0;
  for (std::size_t a = 0; a < n; ++a) {
    energy += 0.5 * network.params.mass * glm::dot(glm::dvec3(v[a]), glm::dvec3(v[a]));
    energy += 0.5 * network.anchor_stiffness * glm::dot(glm::dvec3(e[a]), glm::dvec3(e[a]));
  }
  for (const Spring& s : network.springs) {
    const glm::dvec3 ea = s.free_a >= 0 ? glm::dvec3(e[static_cast<std::size_t>(s.free_a)]) : glm::dvec3(0.0);
    const glm::dvec3 eb = s.free_b >= 0 ? glm::dvec3(e[static_cast<std::size_t>(s.free_b)]) : glm::dvec3(0.0);
    energy += 0.5 * s.stiffness * glm::dot(ea - eb, ea - eb);
  }
  return energy;
}

}  // namespace deform
