#include "deform/elastic/mass_spring.h"
#include "deform/internal/checks.h"

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

namespace deform {
namespace {

constexpr double kStandardGravityMps2 = 9.81;
// A state whose displacements' and velocities' squares each sum below this is
// at rest and set to exactly 0 (see MassSpringStepJob).
constexpr float kRestSumOfSquares = 1e-24f;

// The forcing at one stage time, per unit mass, as matrices acting on every
// point (or mode) alike:
//   e'' = common + mx (k + e) + mv e' + (springs and anchors)
// with common = -gam a + u (+ R^T g - R_bind^T g), mx = -gam ([al]x + [w]x^2)
// (Euler and centrifugal terms on the position k + e in the frame) and
// mv = -2 gam [w]x (Coriolis; skew, its diagonal 0).
struct Forcing {
  glm::vec3 common{0.0f};
  float mx[3][3] = {};
  float mv[3][3] = {};
};

glm::vec3 Times(const float m[3][3], const glm::vec3& p) {
  return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z,
          m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z,
          m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z};
}

using internal::Finite;

bool Finite(const DrivingFrame& d) {
  const glm::quat& q = d.rotation;
  return std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) && std::isfinite(q.w) &&
         Finite(d.linear_acceleration) && Finite(d.angular_velocity) &&
         Finite(d.angular_acceleration);
}

// The job's driving source at any time, with the input limits applied and
// counted, as forcing.
class Driving {
 public:
  Driving(const MassSpringStepJob& job, MassSpringCounters& counters)
      : job_(job), p_(job.network->params), counters_(counters) {
    const double g = kStandardGravityMps2 * p_.units_per_metre;
    gravity_model_ = glm::vec3(glm::dvec3(glm::normalize(p_.down)) * g);
    gravity_bind_ = glm::conjugate(job.network->bind_rotation) * gravity_model_;
    max_accel_ = p_.max_acceleration_mps2 * p_.units_per_metre;
  }

  Forcing At(double time_s) {
    DrivingFrame d = Sample(time_s);
    Check(d);
    return ForcingOf(d);
  }

 private:
  DrivingFrame Sample(double time_s) const {
    if (job_.kinematics.empty()) return (*job_.driving)(time_s);
    mocap::JointKinematics k;
    // Validate() checked the arguments, so this does not fail; if it did, the
    // bind frame at rest.
    if (!mocap::SampleJointKinematics(job_.kinematics, job_.num_joints, job_.joint,
                                      job_.frame_time_s, time_s, &k)) {
      return DrivingFrame{job_.network->bind_rotation};
    }
    return {k.rotation, k.local_linear_acceleration, k.local_angular_velocity,
            k.local_angular_acceleration};
  }

  // A glitch (NaN/Inf, a zero rotation) is taken as the bind frame at rest;
  // |a| above the clamp is scaled back to it.
  void Check(DrivingFrame& d) {
    const glm::vec4 q(d.rotation.x, d.rotation.y, d.rotation.z, d.rotation.w);
    const float q2 = glm::dot(q, q);
    if (!Finite(d) || !std::isfinite(q2) || q2 < 1e-12f) {
      ++counters_.non_finite_inputs;
      d = DrivingFrame{job_.network->bind_rotation};
    }
    const float a_len = glm::length(d.linear_acceleration);
    if (a_len > max_accel_) {
      ++counters_.acceleration_clamps;
      d.linear_acceleration *= max_accel_ / a_len;
    }
  }

  Forcing ForcingOf(const DrivingFrame& d) const {
    Forcing f;
    f.common = -p_.gain * d.linear_acceleration + job_.user_acceleration;
    if (p_.gravity) {
      f.common += glm::conjugate(glm::normalize(d.rotation)) * gravity_model_ - gravity_bind_;
    }
    const glm::vec3 w = d.angular_velocity, al = d.angular_acceleration;
    const float ww = glm::dot(w, w);
    const float skew_al[3][3] = {{0, -al.z, al.y}, {al.z, 0, -al.x}, {-al.y, al.x, 0}};
    const float skew_w[3][3] = {{0, -w.z, w.y}, {w.z, 0, -w.x}, {-w.y, w.x, 0}};
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        const float w2 = w[r] * w[c] - (r == c ? ww : 0.0f);  // [w]x^2 = w w^T - |w|^2 I
        f.mx[r][c] = -p_.gain * (skew_al[r][c] + w2);
        f.mv[r][c] = r == c ? 0.0f : -2.0f * p_.gain * skew_w[r][c];
      }
    }
    return f;
  }

  const MassSpringStepJob& job_;
  const MassSpringParams& p_;
  MassSpringCounters& counters_;
  glm::vec3 gravity_model_{0.0f}, gravity_bind_{0.0f};
  float max_accel_ = 0.0f;
};

// ---- Modal solver: each mode an independent 3-D oscillator -----------------

// Mode k's acceleration at stage forcing f: e = rest_k + x, and per axis c
// (a < b the other two; mv's diagonal is 0 and not read)
//   ((sum_k common_c + mx_c0 e_x) + (mx_c1 e_y + mx_c2 e_z))
//     + ((mv_ca v_a + mv_cb v_b) - (omega2_k x_c + damping_k v_c)).
glm::vec3 ModeAcceleration(const MassSpringNetwork& net, std::size_t k, const Forcing& f,
                           const glm::vec3& x, const glm::vec3& v) {
  const glm::vec3 e = net.mode_rest[k] + x;
  const float sum = net.mode_sum[k], omega2 = net.mode_omega2[k], damping = net.mode_damping[k];
  glm::vec3 acc;
  for (int c = 0; c < 3; ++c) {
    const int a = c == 0 ? 1 : 0, b = c == 2 ? 1 : 2;
    acc[c] = ((sum * f.common[c] + f.mx[c][0] * e.x) + (f.mx[c][1] * e.y + f.mx[c][2] * e.z)) +
             ((f.mv[c][a] * v[a] + f.mv[c][b] * v[b]) - (omega2 * x[c] + damping * v[c]));
  }
  return acc;
}

// One RK4 step of every mode (x' = v), forcing at the step's start, middle and end.
void ModalStep(const MassSpringNetwork& net, float h, const Forcing& f0, const Forcing& fm,
               const Forcing& f1, std::span<glm::vec3> x, std::span<glm::vec3> v,
               std::span<glm::vec3> prev_x) {
  const float hh = 0.5f * h, h6 = h / 6.0f;
  for (std::size_t k = 0; k < x.size(); ++k) {
    const glm::vec3 x0 = x[k], v0 = v[k];
    const glm::vec3 k1 = ModeAcceleration(net, k, f0, x0, v0);
    const glm::vec3 v2 = v0 + hh * k1;
    const glm::vec3 k2 = ModeAcceleration(net, k, fm, x0 + hh * v0, v2);
    const glm::vec3 v3 = v0 + hh * k2;
    const glm::vec3 k3 = ModeAcceleration(net, k, fm, x0 + hh * v2, v3);
    const glm::vec3 v4 = v0 + h * k3;
    const glm::vec3 k4 = ModeAcceleration(net, k, f1, x0 + h * v3, v4);
    prev_x[k] = x0;
    x[k] = x0 + h6 * ((v0 + v4) + 2.0f * (v2 + v3));
    v[k] = v0 + h6 * ((k1 + 2.0f * (k2 + k3)) + k4);
  }
}

// The displacement limit of one point (ALGORITHMS.md 6): e longer than e_max is
// projected back onto the sphere of radius e_max and the outward part of v
// removed. Returns whether it clamped.
bool ClampDisplacement(glm::vec3& e, glm::vec3& v, float e_max) {
  const float len = glm::length(e);
  if (len <= e_max) return false;
  const glm::vec3 dir = e / len;
  e = dir * e_max;
  const float outward = glm::dot(v, dir);
  if (outward > 0.0f) v -= outward * dir;
  return true;
}

// Point a of the modal field y: sum_k U[a, k] y_k, k ascending.
glm::vec3 PointOf(const MassSpringNetwork& net, std::span<const glm::vec3> y, std::size_t a) {
  const std::size_t n = y.size();
  glm::vec3 sum(0.0f);
  for (std::size_t k = 0; k < n; ++k) sum += net.modes[a * n + k] * y[k];
  return sum;
}

// The displacement limit on the modes: every point a with |e_a| > e_max, e = U x,
// is clamped with its velocity (U v)_a (each from the state before any clamp:
// U is orthonormal, so a clamp at a moves no other point), and the changes are
// taken back to the modes, x_k += U[a, k] dx_a, a ascending. Returns the clamps.
int LimitModes(const MassSpringNetwork& net, std::span<glm::vec3> x, std::span<glm::vec3> v,
               std::span<glm::vec3> work, std::span<unsigned char> clamped) {
  const float e_max = net.params.max_displacement;
  // |e_a| <= sum_k max_a |U[a, k]| |x_k|: below e_max nothing can exceed.
  float bound = 0.0f;
  for (std::size_t k = 0; k < x.size(); ++k) bound += net.mode_max_abs[k] * glm::length(x[k]);
  if (bound <= e_max) return 0;
  const std::size_t n = x.size();
  std::span<glm::vec3> dx = work.subspan(0, n), dv = work.subspan(n, n);
  int clamps = 0;
  for (std::size_t a = 0; a < n; ++a) {
    clamped[a] = 0;
    const glm::vec3 e0 = PointOf(net, x, a);
    if (glm::dot(e0, e0) <= 0.9999f * e_max * e_max) continue;  // certainly inside
    const glm::vec3 v0 = PointOf(net, v, a);
    glm::vec3 e1 = e0, v1 = v0;
    if (!ClampDisplacement(e1, v1, e_max)) continue;
    dx[a] = e1 - e0;
    dv[a] = v1 - v0;
    clamped[a] = 1;
    ++clamps;
  }
  for (std::size_t a = 0; a < n && clamps > 0; ++a) {
    if (!clamped[a]) continue;
    for (std::size_t k = 0; k < n; ++k) {
      x[k] += net.modes[a * n + k] * dx[a];
      v[k] += net.modes[a * n + k] * dv[a];
    }
  }
  return clamps;
}

// ---- Point-space solver: springs summed per point ---------------------------

void PointAccelerations(const MassSpringNetwork& net, const Forcing& f,
                        std::span<const glm::vec3> e, std::span<const glm::vec3> v,
                        std::span<glm::vec3> acc) {
  const float inv_m = 1.0f / net.params.mass;
  for (std::size_t a = 0; a < e.size(); ++a) {
    const glm::vec3 k = net.rest_points[static_cast<std::size_t>(net.point_of_free[a])];
    acc[a] = inv_m * (-net.anchor_stiffness * e[a] - net.anchor_damping * v[a]) + f.common +
             Times(f.mx, k + e[a]) + Times(f.mv, v[a]);
  }
  const bool length_model = net.params.force_model == SpringForceModel::kLength;
  for (const Spring& s : net.springs) {
    const std::size_t fa = static_cast<std::size_t>(s.free_a);
    const std::size_t fb = static_cast<std::size_t>(s.free_b);
    const glm::vec3 ea = s.free_a >= 0 ? e[fa] : glm::vec3(0.0f);
    const glm::vec3 eb = s.free_b >= 0 ? e[fb] : glm::vec3(0.0f);
    const glm::vec3 va = s.free_a >= 0 ? v[fa] : glm::vec3(0.0f);
    const glm::vec3 vb = s.free_b >= 0 ? v[fb] : glm::vec3(0.0f);
    glm::vec3 force = -s.damping * (va - vb);  // on a
    if (length_model) {
      const glm::vec3 d = net.rest_points[static_cast<std::size_t>(s.point_a)] + ea -
                          net.rest_points[static_cast<std::size_t>(s.point_b)] - eb;
      const float len = glm::length(d);
      if (len > 0.0f) force -= s.stiffness * (len - s.rest_length) / len * d;
    } else {
      force -= s.stiffness * (ea - eb);
    }
    if (s.free_a >= 0) acc[fa] += inv_m * force;
    if (s.free_b >= 0) acc[fb] -= inv_m * force;
  }
}

// One RK4 step of every free point; work holds 5 x #free.
void PointStep(const MassSpringNetwork& net, float h, const Forcing& f0, const Forcing& fm,
               const Forcing& f1, std::span<glm::vec3> x, std::span<glm::vec3> v,
               std::span<glm::vec3> prev_x, std::span<glm::vec3> work) {
  const std::size_t n = x.size();
  std::span<glm::vec3> xs = work.subspan(0, n), vs = work.subspan(n, n),
                       acc = work.subspan(2 * n, n), sx = work.subspan(3 * n, n),
                       sv = work.subspan(4 * n, n);
  // Stage i: derivative at (xs, vs); the next stage's point at x + c h (derivative).
  const Forcing* forcing[4] = {&f0, &fm, &fm, &f1};
  const float next[3] = {0.5f * h, 0.5f * h, h};
  const float weight[4] = {1.0f, 2.0f, 2.0f, 1.0f};
  std::copy(x.begin(), x.end(), xs.begin());
  std::copy(v.begin(), v.end(), vs.begin());
  for (int stage = 0; stage < 4; ++stage) {
    PointAccelerations(net, *forcing[stage], xs, vs, acc);
    for (std::size_t a = 0; a < n; ++a) {
      const glm::vec3 dx = vs[a], dv = acc[a];
      sx[a] = stage == 0 ? dx : sx[a] + weight[stage] * dx;
      sv[a] = stage == 0 ? dv : sv[a] + weight[stage] * dv;
      if (stage < 3) {
        xs[a] = x[a] + next[stage] * dx;
        vs[a] = v[a] + next[stage] * dv;
      }
    }
  }
  for (std::size_t a = 0; a < n; ++a) {
    prev_x[a] = x[a];
    x[a] += (h / 6.0f) * sx[a];
    v[a] += (h / 6.0f) * sv[a];
  }
}

bool UsesModes(const MassSpringNetwork& net) {
  return net.params.force_model == SpringForceModel::kLinear &&
         net.params.solver == MassSpringSolver::kModal;
}

}  // namespace

void MassSpringState::Resize(const MassSpringNetwork& network) {
  const std::size_t n = static_cast<std::size_t>(network.num_free);
  modal_ = UsesModes(network);
  x_.assign(n, glm::vec3(0.0f));
  v_.assign(n, glm::vec3(0.0f));
  prev_x_.assign(n, glm::vec3(0.0f));
  work_.assign(5 * n, glm::vec3(0.0f));
  clamped_.assign(n, 0);
  Reset();
}

void MassSpringState::Reset() {
  started_ = false;
  step_time_s_ = output_time_s_ = 0.0;
  std::fill(x_.begin(), x_.end(), glm::vec3(0.0f));
  std::fill(v_.begin(), v_.end(), glm::vec3(0.0f));
  std::fill(prev_x_.begin(), prev_x_.end(), glm::vec3(0.0f));
}

bool MassSpringState::SetDisplacement(const MassSpringNetwork& network,
                                      std::span<const glm::vec3> e) {
  const std::size_t n = static_cast<std::size_t>(network.num_free);
  if (e.size() != n || x_.size() != n || modal_ != UsesModes(network)) return false;
  for (std::size_t i = 0; i < n; ++i) {
    if (!modal_) {
      x_[i] = e[i];
      continue;
    }
    glm::vec3 eta(0.0f);  // eta_k = sum_a U[a, k] e_a (U orthonormal)
    for (std::size_t a = 0; a < n; ++a) eta += network.modes[a * n + i] * e[a];
    x_[i] = eta;
  }
  std::fill(v_.begin(), v_.end(), glm::vec3(0.0f));
  prev_x_ = x_;
  return true;
}

JobStatus MassSpringStepJob::Validate() const {
  if (network == nullptr || state == nullptr) return {JobStatus::kMissingInput, "no network or state"};
  if (kinematics.empty() && (driving == nullptr || !*driving)) {
    return {JobStatus::kMissingInput, "no kinematics and no driving callback"};
  }
  const std::size_t n = static_cast<std::size_t>(network->num_free);
  const MassSpringState& s = *state;
  if (s.x_.size() != n || s.v_.size() != n || s.prev_x_.size() != n || s.work_.size() != 5 * n ||
      s.clamped_.size() != n || s.modal_ != UsesModes(*network)) {
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
  return base::kJobOk;
}

JobStatus MassSpringStepJob::Run() const {
  const JobStatus status = Validate();
  if (!status) return status;
  const MassSpringNetwork& net = *network;
  MassSpringState& st = *state;
  const MassSpringParams& p = net.params;
  const double h = net.time_step_s;
  const double eps = 1e-9;
  if (!st.started_ || time_s < st.output_time_s_ - eps ||
      time_s > st.output_time_s_ + p.max_time_gap_s) {
    st.Reset();
    st.started_ = true;
    ++st.counters_.time_resets;
    st.step_time_s_ = time_s - p.preroll_s;
  }
  std::span<glm::vec3> x(st.x_), v(st.v_), prev_x(st.prev_x_), work(st.work_);
  if (st.step_time_s_ < time_s - eps) {
    Driving source(*this, st.counters_);
    Forcing f0 = source.At(st.step_time_s_);
    while (st.step_time_s_ < time_s - eps) {
      const double t = st.step_time_s_;
      const Forcing fm = source.At(t + 0.5 * h);
      const Forcing f1 = source.At(t + h);
      if (st.modal_) {
        ModalStep(net, static_cast<float>(h), f0, fm, f1, x, v, prev_x);
      } else {
        PointStep(net, static_cast<float>(h), f0, fm, f1, x, v, prev_x, work);
      }
      float sum_x = 0.0f, sum_v = 0.0f;
      for (std::size_t a = 0; a < x.size(); ++a) {
        sum_x += glm::dot(x[a], x[a]);
        sum_v += glm::dot(v[a], v[a]);
      }
      const bool finite = std::isfinite(sum_x) && std::isfinite(sum_v);
      if (!finite || (sum_x < kRestSumOfSquares && sum_v < kRestSumOfSquares)) {
        if (!finite) ++st.counters_.non_finite_resets;
        std::fill(x.begin(), x.end(), glm::vec3(0.0f));
        std::fill(v.begin(), v.end(), glm::vec3(0.0f));
        std::fill(prev_x.begin(), prev_x.end(), glm::vec3(0.0f));
      } else if (sum_x > p.max_displacement * p.max_displacement) {  // |e_a|^2 <= sum_x
        if (st.modal_) {
          st.counters_.displacement_clamps += LimitModes(net, x, v, work, st.clamped_);
        } else {
          for (std::size_t a = 0; a < x.size(); ++a) {
            if (ClampDisplacement(x[a], v[a], p.max_displacement)) ++st.counters_.displacement_clamps;
          }
        }
      }
      st.step_time_s_ = t + h;
      ++st.counters_.steps;
      f0 = f1;
    }
  }
  st.output_time_s_ = time_s;
  if (displacements.empty()) return base::kJobOk;

  // Linear interpolation between the last two steps (exact when no step was taken
  // since a reset: both are the same zero state), then to point space.
  const float alpha =
      static_cast<float>(std::clamp((time_s - (st.step_time_s_ - h)) / h, 0.0, 1.0));
  std::span<glm::vec3> blend = work.subspan(0, x.size());
  for (std::size_t a = 0; a < x.size(); ++a) blend[a] = prev_x[a] + alpha * (x[a] - prev_x[a]);
  std::fill(displacements.begin(), displacements.end(), glm::vec3(0.0f));
  for (std::size_t a = 0; a < x.size(); ++a) {
    displacements[static_cast<std::size_t>(net.point_of_free[a])] =
        st.modal_ ? PointOf(net, blend, a) : blend[a];
  }
  return base::kJobOk;
}

void MassSpringPointDisplacements(const MassSpringNetwork& network, const MassSpringState& state,
                                  std::span<glm::vec3> out) {
  for (std::size_t a = 0; a < state.x_.size(); ++a) {
    out[a] = state.modal_ ? PointOf(network, state.x_, a) : state.x_[a];
  }
}

double MassSpringEnergy(const MassSpringNetwork& network, const MassSpringState& state) {
  const std::size_t n = state.x_.size();
  std::vector<glm::vec3> e(n), v(n);
  for (std::size_t a = 0; a < n; ++a) {
    e[a] = state.modal_ ? PointOf(network, state.x_, a) : state.x_[a];
    v[a] = state.modal_ ? PointOf(network, state.v_, a) : state.v_[a];
  }
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
