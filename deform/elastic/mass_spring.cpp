#include "deform/elastic/mass_spring.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <utility>

#include "deform/elastic/internal/checked_driving.h"
#include "deform/elastic/internal/modal_run.h"

namespace deform {
namespace {

using mocap::ErrorCode;
using mocap::FileLoc;
using mocap::MakeError;

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

// The point-space solver (kPointSpace, and the length model).
class Integrator {
 public:
  explicit Integrator(const MassSpringStepJob& job)
      : net_(*job.network), st_(*job.state), p_(job.network->params), driving_(job) {}

  Forcing Sample(double t) {
    const DrivingFrame d = driving_.Sample(t);
    const internal::ForcingConstants& k = driving_.forcing();
    Forcing f;
    f.gain = p_.gain;
    f.w = d.angular_velocity;
    f.al = d.angular_acceleration;
    f.common = -p_.gain * d.linear_acceleration + k.user_acceleration;
    if (p_.gravity) {
      f.common += glm::conjugate(glm::normalize(d.rotation)) * k.gravity_model - k.gravity_bind;
    }
    return f;
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
      x[a] += (h / 6.0f) * sx[a];
      v[a] += (h / 6.0f) * sv[a];
    }
  }

  // |e_a| <= e_max with the outward velocity removed; non-finite state resets;
  // a state at rest is set to 0 (internal::kRestSumOfSquares). Point-space
  // state; the modal run does the same for the modes.
  void ApplyLimits() {
    const std::size_t n = static_cast<std::size_t>(net_.num_free);
    const float e_max = p_.max_displacement;
    float sum_x = 0.0f, sum_v = 0.0f;
    for (std::size_t a = 0; a < n; ++a) {
      sum_x += glm::dot(st_.position[a], st_.position[a]);
      sum_v += glm::dot(st_.velocity[a], st_.velocity[a]);
    }
    const bool finite = std::isfinite(sum_x) && std::isfinite(sum_v);
    if (!finite || (sum_x < internal::kRestSumOfSquares && sum_v < internal::kRestSumOfSquares)) {
      if (!finite) ++st_.counters.non_finite_resets;
      std::fill(st_.position.begin(), st_.position.end(), glm::vec3(0.0f));
      std::fill(st_.velocity.begin(), st_.velocity.end(), glm::vec3(0.0f));
      std::fill(st_.prev_position.begin(), st_.prev_position.end(), glm::vec3(0.0f));
      return;
    }
    if (sum_x <= e_max * e_max) return;
    std::span<glm::vec3> e(st_.position), v(st_.velocity);
    for (std::size_t a = 0; a < n; ++a) {
      if (internal::ClampDisplacement(e[a], v[a], e_max)) ++st_.counters.displacement_clamps;
    }
  }

 private:
  const MassSpringNetwork& net_;
  MassSpringState& st_;
  const MassSpringParams& p_;
  internal::CheckedDriving driving_;
};

bool UsesModes(const MassSpringNetwork& net) {
  return net.params.force_model == SpringForceModel::kLinear &&
         net.params.solver == MassSpringSolver::kModal;
}

}  // namespace

void MassSpringState::Resize(const MassSpringNetwork& network) {
  const bool modes = UsesModes(network);
  const std::size_t n = modes ? 0 : static_cast<std::size_t>(network.num_free);
  position.assign(n, glm::vec3(0.0f));
  velocity.assign(n, glm::vec3(0.0f));
  prev_position.assign(n, glm::vec3(0.0f));
  work.assign(5 * n, glm::vec3(0.0f));
  modal_stride = modes ? static_cast<std::size_t>(network.mode_stride) : 0;
  modal.assign(4 * 3 * modal_stride, 0.0f);
  Reset();
}

void MassSpringState::Reset() {
  started = false;
  last_stage.valid = false;
  step_time_s = output_time_s = 0.0;
  std::fill(position.begin(), position.end(), glm::vec3(0.0f));
  std::fill(velocity.begin(), velocity.end(), glm::vec3(0.0f));
  std::fill(prev_position.begin(), prev_position.end(), glm::vec3(0.0f));
  std::fill(modal.begin(), modal.end(), 0.0f);
  modal_newest = 0;
}

JobStatus MassSpringStepJob::Validate() const {
  if (network == nullptr || state == nullptr) return {JobStatus::kMissingInput, "no network or state"};
  if (kinematics.empty() && (driving == nullptr || !*driving)) {
    return {JobStatus::kMissingInput, "no kinematics and no driving callback"};
  }
  const bool modes = UsesModes(*network);
  const std::size_t n = modes ? 0 : static_cast<std::size_t>(network->num_free);
  const std::size_t stride = modes ? static_cast<std::size_t>(network->mode_stride) : 0;
  if (state->position.size() != n || state->velocity.size() != n ||
      state->prev_position.size() != n || state->work.size() != 5 * n ||
      state->modal_stride != stride || state->modal.size() != 4 * 3 * stride ||
      (state->modal_newest != 0 && state->modal_newest != 1)) {
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
  if (UsesModes(net)) {
    internal::RunModal(*this, time_s - eps);
    st.output_time_s = time_s;
    return mocap::kJobOk;
  }
  if (st.step_time_s < time_s - eps) {
    Integrator integrator(*this);
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
  std::fill(displacements.begin(), displacements.end(), glm::vec3(0.0f));
  for (std::size_t a = 0; a < n; ++a) {
    displacements[static_cast<std::size_t>(net.point_of_free[a])] =
        st.prev_position[a] + alpha * (st.position[a] - st.prev_position[a]);
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

// The newest step's displacement and velocity as stored: per point, or per
// mode for the modal solver.
void NewestStep(const MassSpringNetwork& net, const MassSpringState& state,
                std::vector<glm::vec3>& x, std::vector<glm::vec3>& v) {
  if (!UsesModes(net)) {
    x = state.position;
    v = state.velocity;
    return;
  }
  const std::size_t n = static_cast<std::size_t>(net.num_free);
  x.resize(n);
  v.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    x[k] = state.ModalDisplacement(k);
    v[k] = state.ModalVelocity(k);
  }
}
}  // namespace

void MassSpringPointDisplacements(const MassSpringNetwork& network, const MassSpringState& state,
                                  std::span<glm::vec3> out) {
  std::vector<glm::vec3> x, v;
  NewestStep(network, state, x, v);
  ToPointSpace(network, x, out);
}

double MassSpringEnergy(const MassSpringNetwork& network, const MassSpringState& state) {
  const std::size_t n = static_cast<std::size_t>(network.num_free);
  std::vector<glm::vec3> e(n), v(n), modes_x, modes_v;
  NewestStep(network, state, modes_x, modes_v);
  ToPointSpace(network, modes_x, e);
  ToPointSpace(network, modes_v, v);
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
