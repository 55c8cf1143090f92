#pragma once
// The elastic layer dE (ALGORITHMS.md 6; Lee, Kim, Yoon 2009): a damped
// mass-spring network over the M x N control points of one patch, driven by the
// motion of a "driving" joint's frame and integrated by fourth-order Runge-Kutta
// with a fixed step.
//
// State: per free (interior) control point a, its displacement e_a and velocity
// e'_a in the driving joint's frame (model units, model units/s). Boundary points
// (i = 0, M-1 or j = 0, N-1) are fixed at e = 0. Springs join grid neighbours:
// structural (i+-1, j), (i, j+-1); shear (i+-1, j+-1); bending (i+-2, j), (i, j+-2);
// each free point also has an anchor spring to its own origin.
//
// Equation of motion (per free point, mass m, in the driving frame; w and al the
// frame's angular velocity and acceleration in the frame, a = R^T o'' its linear
// acceleration in the frame, k_a the point's position in the frame):
//   m e''_a = F_a - gam m [ a + al x k_a + w x (w x k_a)            (driving terms)
//                          + 2 w x e'_a + al x e_a + w x (w x e_a) ] (Coriolis, Euler,
//                                                                      centrifugal on e)
//             + m (R^T g - R_bind^T g) + m u                         (gravity, user push)
// Linear force model (default):
//   F_a = -k_an e_a - c_an e'_a - sum_b [ k_ab (e_a - e_b) + c_ab (e'_a - e'_b) ]
// Length model (option): k_ab (|y_a - y_b| - L_ab) along y_a - y_b with y = k + e and
// L_ab = |k_a - k_b| at e = 0; damping and anchors stay linear.
//
// Stiffness scaling: K1 = the #free x #free stiffness matrix with k_an = 1 and
// k_ab = kst, ksh, kbd by kind; every stiffness is multiplied by
// s = m (2 pi f0)^2 / lambda_min(K1) so the slowest mode rings at f0;
// c_an = 2 z0 (2 pi f0) m, c_ab = b k_ab. Sustained acceleration a then gives
// about gam |a| / (2 pi f0)^2 of displacement (exactly that for the slowest mode).
//
// Solution: the linear model's K and C share eigenvectors (C = c_an I + b (K - k_an I)),
// and the inertial terms act on the 3 axes of every point alike, so in the modal
// basis (e = U eta, U orthonormal, #free modes) each mode is an independent 3-D
// oscillator. RK4 is invariant under this linear change of variables: integrating
// the modes is the same RK4 on the same system (up to float round-off) at
// O(#free) cost per evaluation instead of O(#springs). The length model and
// Solver::kPointSpace integrate the springs directly.
//
// Time: a fixed step h (default 1/240 s) independent of the frame rate. Each run
// advances whole steps from the state's step grid until it passes the requested
// time, and the displacement returned is interpolated linearly between the last
// two steps, so 30, 60 and 120 fps outputs sample the same trajectory.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "base/error.h"
#include "mocap/kinematics.h"

namespace deform {

using base::JobStatus;
using base::Result;

// Spring force law.
enum class SpringForceModel {
  kLinear,  // forces linear in displacements (default, rotation invariant)
  kLength,  // Hooke springs on the points' positions in the driving frame
};

// How the linear model is integrated (both give the same trajectory).
enum class MassSpringSolver {
  kModal,       // independent modes (default; fast)
  kPointSpace,  // springs summed per point (reference; used by kLength)
};

// Per-patch parameters; every field has the documented default of ALGORITHMS.md 6.
// Rig files write them under patches[].elastic with the same names.
struct MassSpringParams {
  float mass = 1.0f;               // m per control point (unit-free), > 0
  float frequency_hz = 3.0f;       // f0: the slowest mode's frequency, > 0 (belly 3, face 5)
  float damping_ratio = 0.15f;     // z0: the anchors' damping ratio, >= 0 (belly 0.15, face 0.25)
  float structural_ratio = 1.0f;   // kst: structural spring stiffness / anchor stiffness, >= 0
  float shear_ratio = 0.5f;        // ksh, >= 0
  float bending_ratio = 0.25f;     // kbd, >= 0
  float spring_damping_s = 0.001f; // b: c_ab = b k_ab (seconds), >= 0; damps high modes
  double time_step_s = 1.0 / 240;  // h requested; may be halved by the step rule, > 0
  float gain = 1.0f;               // gam: multiplies the inertial terms, >= 0
  float units_per_metre = 100.0f;  // model units per metre (cm files: 100), > 0
  bool gravity = true;             // add m (R^T g - R_bind^T g)
  glm::vec3 down{0.0f, -1.0f, 0.0f};  // model-space direction of gravity (unit length)
  float max_displacement = 0.0f;   // e_max, model units; <= 0: 0.5 x mean structural spacing
  float max_acceleration_mps2 = 200.0f;  // input clamp on |a| (m/s^2, scaled by units_per_metre)
  float max_time_gap_s = 0.5f;     // a run more than this after the previous one resets, > 0
  double preroll_s = 0.0;          // simulated before the first output time after a reset, >= 0
  SpringForceModel force_model = SpringForceModel::kLinear;
  MassSpringSolver solver = MassSpringSolver::kModal;  // ignored (point space) for kLength
};

// Spring kinds, indexing MassSpringNetwork::num_springs.
enum SpringKind : int { kStructural = 0, kShear = 1, kBending = 2, kNumSpringKinds = 3 };

// One spring between grid points a and b; at least one of them is free.
struct Spring {
  int point_a = 0, point_b = 0;  // grid indices i * N + j
  int free_a = -1, free_b = -1;  // free indices, -1 for a fixed (boundary) point
  float stiffness = 0.0f;        // k_ab (per unit displacement, model-unit free)
  float damping = 0.0f;          // c_ab = b k_ab
  float rest_length = 0.0f;      // L_ab = |k_a - k_b| (model units; length model only)
  SpringKind kind = kStructural;
};

// The network of one patch: topology, scaled parameters and the modal basis.
// Built once by BuildMassSpringNetwork; read-only afterwards.
struct MassSpringNetwork {
  int rows = 0, cols = 0;                  // M, N >= 3
  int num_free = 0;                        // #free = (M-2)(N-2)
  std::vector<int> free_of_point;          // M*N: free index or -1 (boundary)
  std::vector<int> point_of_free;          // #free grid indices, row-major interior order
  std::vector<Spring> springs;             // springs touching a free point
  int num_springs[kNumSpringKinds] = {};   // counts by kind
  std::vector<glm::vec3> rest_points;      // M*N control points k_a in the driving frame
  glm::quat bind_rotation{1, 0, 0, 0};     // R_bind: the driving joint's model rotation at bind
  MassSpringParams params;                 // as given, with e_max resolved (> 0)
  double time_step_s = 0.0;                // h after the step rule
  float anchor_stiffness = 0.0f;           // k_an = s
  float anchor_damping = 0.0f;             // c_an = 2 z0 (2 pi f0) m
  double lambda_min = 0.0;                 // smallest eigenvalue of K1
  double stiffness_scale = 0.0;            // s
  double gershgorin_rate = 0.0;            // max(w_max, c_max / m), rad/s
  // Modal basis (linear model): mode k has e = U[., k] eta_k.
  std::vector<float> modes;                // #free x #free, U[a * #free + k], orthonormal
  std::vector<float> mode_omega2;          // #free: (2 pi f_k)^2 = s lambda_k / m, ascending
  std::vector<float> mode_damping;         // #free: c_k / m = (c_an + b s (lambda_k - 1)) / m
  std::vector<float> mode_sum;             // #free: sum_a U[a, k]
  std::vector<glm::vec3> mode_rest;        // #free: sum_a U[a, k] k_a
  std::vector<float> mode_max_abs;         // #free: max_a |U[a, k]| (cheap limit check)
  std::vector<std::string> messages;       // step-rule notes ("time step halved to ...")
};

// Setup inputs besides the parameters.
struct MassSpringSetup {
  int rows = 0, cols = 0;                        // M, N in [3, 16]
  std::span<const glm::vec3> rest_points = {};   // M*N rest control points in the driving
                                                 // joint's frame (model units), row-major
  glm::quat bind_rotation{1, 0, 0, 0};           // driving joint's model rotation at bind
  float max_angular_speed_rad_s = 0.0f;          // |w| the motion reaches (step rule), >= 0
};

// Builds the network. Step rule (Gershgorin): while
// h (max(w_max, c_max/m) + 2|w|) > 0.5 the step is halved with a message, at most
// 6 times; an error if it is still above 2.5 (RK4's stability reach).
// Errors: kInvalidArgument for sizes, non-finite points or parameters out of range.
Result<MassSpringNetwork> BuildMassSpringNetwork(const MassSpringSetup& setup,
                                                 const MassSpringParams& params = {});

// The driving frame at one time (all in the driving joint's own frame but R).
struct DrivingFrame {
  glm::quat rotation{1, 0, 0, 0};         // R: model_from_joint rotation
  glm::vec3 linear_acceleration{0.0f};    // R^T o'', model units/s^2
  glm::vec3 angular_velocity{0.0f};       // w, rad/s
  glm::vec3 angular_acceleration{0.0f};   // al, rad/s^2
};

// Counters of everything the limits changed; they only grow (Reset keeps them).
struct MassSpringCounters {
  std::int64_t steps = 0;                 // RK4 steps taken
  std::int64_t displacement_clamps = 0;   // points projected back to |e| = e_max
  std::int64_t acceleration_clamps = 0;   // driving samples with |a| above the clamp
  std::int64_t non_finite_inputs = 0;     // driving samples with NaN/Inf (taken as at rest)
  std::int64_t non_finite_resets = 0;     // state reset because it became non-finite
  std::int64_t time_resets = 0;           // resets for a first run, jump back or gap
  std::int64_t any_limit() const {
    return displacement_clamps + acceleration_clamps + non_finite_inputs + non_finite_resets;
  }
};

// Caller-owned state carried between frames (compare ozz's SamplingJob::Context):
// the newest step's displacement and velocity (per mode with the modal solver,
// per free point otherwise), the step before's displacement, and scratch.
// Sized by Resize(network); a run with a state of another size or solver
// fails validation.
class MassSpringState {
 public:
  void Resize(const MassSpringNetwork& network);
  void Reset();  // zero state, started() false; keeps the counters

  // Places the newest step at the free points' displacement `e` (#free, point
  // space, model units) with zero velocity, e.g. to let a patch ring from a
  // pose. The clock is kept; a run that resets (first run, time jump) zeroes it.
  // Returns false (and changes nothing) when e.size() is not #free or the state
  // is not sized for `network`.
  bool SetDisplacement(const MassSpringNetwork& network, std::span<const glm::vec3> e);

  bool started() const { return started_; }             // false: the next run resets
  double step_time_s() const { return step_time_s_; }   // time of the newest step
  double output_time_s() const { return output_time_s_; }
  const MassSpringCounters& counters() const { return counters_; }

 private:
  friend struct MassSpringStepJob;
  friend void MassSpringPointDisplacements(const MassSpringNetwork&, const MassSpringState&,
                                           std::span<glm::vec3>);
  friend double MassSpringEnergy(const MassSpringNetwork&, const MassSpringState&);

  bool started_ = false;
  bool modal_ = false;          // sized for the modal solver
  double step_time_s_ = 0.0;
  double output_time_s_ = 0.0;
  std::vector<glm::vec3> x_, v_;   // newest step, #free
  std::vector<glm::vec3> prev_x_;  // the step before's displacement, #free
  std::vector<glm::vec3> work_;    // 5 x #free: RK4 stages, limit scratch
  std::vector<unsigned char> clamped_;  // #free: points the modal limit clamped
  MassSpringCounters counters_;
};

// Advances a state to `time_s` and writes the displacement there.
// Driving kinematics, one of:
//  - `kinematics` (per-frame buffer of ComputeKinematics / KinematicsJob, all #F x #J,
//    or a compact #F x #D table of some joints only, num_joints = #D and `joint`
//    the column) with `num_joints`, `joint` and `frame_time_s`: sampled by
//    mocap::SampleJointKinematics at every RK4 stage time;
//  - `driving`: a callback giving the frame at any time (tests, procedural input).
// Resets (zero state, then preroll_s of simulation) on the first run, when time
// goes back, or when it jumps ahead by more than max_time_gap_s. Every driving
// sample is checked (ALGORITHMS.md 6): a sample with a NaN/Inf field or a zero
// rotation is taken as the bind frame at rest, |a| above the clamp is scaled
// back to it; both are counted. A state that has decayed to nothing (the
// squares of its displacements and of its velocities each summing below 1e-24)
// is set to exactly 0 after the step, rather than left to decay on into the
// subnormal floats (where every operation is slow).
// Cost per RK4 step: O(#free) with the modal solver (plus O(#free^2) in a step
// whose displacement may exceed e_max), O(#springs) in point space; the output
// O(#free^2) (modal) or O(#free). Deterministic: the same inputs give the same
// bits on any x86-64 CPU (no contraction, no run-time instruction choice).
struct MassSpringStepJob {
  const MassSpringNetwork* network = nullptr;     // required
  MassSpringState* state = nullptr;               // required, Resize()d for network
  double time_s = 0.0;                            // output time (seconds, motion clock)
  std::span<const mocap::JointKinematics> kinematics = {};  // #F x #J, or empty with `driving`
  int num_joints = 0;
  int joint = 0;
  double frame_time_s = 0.0;
  const std::function<DrivingFrame(double)>* driving = nullptr;  // used when kinematics is empty
  glm::vec3 user_acceleration{0.0f};  // a push (model units/s^2, driving frame) during this run
  std::span<glm::vec3> displacements = {};  // output, M*N: e at time_s in the driving frame
                                      // (boundary entries 0); may be empty

  // kMissingInput: no network, state or driving source; kSizeMismatch: state not
  // sized for the network, displacements not M*N; kOutOfRange: kinematics
  // arguments (num_joints, joint, frame_time_s) or a non-finite time.
  [[nodiscard]] JobStatus Validate() const;
  // Validate(), then integrate. No allocation.
  [[nodiscard]] JobStatus Run() const;
};

// Kinetic + potential energy of the linear model at the newest step (per the
// springs and anchors; unit mass-consistent), for tests and plots.
double MassSpringEnergy(const MassSpringNetwork& network, const MassSpringState& state);

// Displacements of the newest step in point space (#free), whatever the solver.
void MassSpringPointDisplacements(const MassSpringNetwork& network, const MassSpringState& state,
                                  std::span<glm::vec3> out);

}  // namespace deform
