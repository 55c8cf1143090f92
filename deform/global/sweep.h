#pragma once
// Sweep chains for SWD, sweep-based deformation (ALGORITHMS.md 2.3; our variant of
// Hyun, Yoon, Chang, Seong, Kim, Juttler 2005).
//
// A sweep is a chain of K bones (e.g. clavicle-upperarm-forearm-hand). Bone k runs
// from joint J_k to J_{k+1}, has rest length L_k and rest unit axis a0_k, and moves
// with the joint rotation dQ_k (relative to bind). The sweep parameter u lies in
// [0, K]; u = k + t (t in [0,1]) is on bone k.
//
// Centre curve c(u): on bone k outside joint regions c = J_k + t L_k a_k (a_k = dQ_k a0_k).
// Interior joint k owns the region [ua_k, ub_k] = [k - hm_k/L_{k-1}, k + hp_k/L_k]; in it
// c is the cubic Bezier B0 = J_k - hm a_{k-1}, B1 = B0 + (l/3) a_{k-1},
// B2 = B3 - (l/3) a_k, B3 = J_k + hp a_k (l = hm + hp) at x = (u-ua_k)/(ub_k-ua_k).
// Frame dR(u): in region k slerp(Fm_k, Fp_k, sm(x)) (the pure swing); along bone k the
// twist of the neighbouring joints is spread with a smoothstep (see SweepFrame).
// A bound point p0 = c0(u) + o is rebuilt as p = c(u) + dR(u) o.
//
// The rest data are built once and checked (BuildSweepChain); the per-frame state is a
// fixed-size SweepPose, filled without allocating (PoseSweepChain).

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "base/error.h"

namespace deform {

// Most bones in one sweep chain (pelvis-spine-..-head is the longest sweep used).
inline constexpr int kMaxSweepBones = 8;
// Default largest expected bend of a joint, radians (150 degrees).
inline constexpr double kDefaultMaxBendRad = 2.62;

// Which bone a joint's twist is spread along (ALGORITHMS.md 2.3).
enum class TwistSpread : std::uint8_t {
  kDownstream,  // along the child bone: L_k = S_k Tw(a0_k, tau) (shoulder, elbow, hip, knee, spine)
  kUpstream,    // along the parent bone: L_k = Tw(a0_{k-1}, tau) S_k (wrist: forearm pronation)
};

// Input of BuildSweepChain: one chain as the rig describes it.
struct SweepChainSpec {
  // #K skeleton joint indices; bone k starts at joint joints[k] and turns with its
  // rotation dQ. The chain's end J_K need not be a skeleton joint (an end site).
  std::vector<int> joints;
  // #K+1 bind-pose model-space joint positions J_0..J_K (model units).
  std::vector<glm::vec3> rest_points;
  // #K+1 region half-widths h_k (model units) of the interior joints, used as hm = hp = h;
  // entries 0 and K are ignored. Empty: DefaultHalfWidth from skin_radii.
  std::vector<float> half_widths;
  // #K+1 skin radii r_k (90th percentile distance of nearby skin from the axis, model
  // units; see SkinRadiusNearJoint). Used only when half_widths is empty; empty then
  // means 10% of the shorter neighbouring bone.
  std::vector<float> skin_radii;
  // #K+1 twist assignment per joint; entries 0 and K are ignored. Empty: all downstream.
  std::vector<TwistSpread> twist_spread;
};

// h_k = clamp(0.75 * r * bend, 0.1 Lmin, 0.45 Lmin), Lmin = min(L_{k-1}, L_k): the narrowest
// region whose cross-section planes do not meet inside the skin at a bend of `bend_rad`.
double DefaultHalfWidth(double skin_radius, double bend_rad, double length_in, double length_out);

// 90th percentile distance from the two bone lines of the rest vertices within
// 0.5 * Lmin of interior joint `k` (model units); 0 when no vertex is that close.
// `k` must be an interior joint of the spec (1..K-1); spec sizes must be consistent.
double SkinRadiusNearJoint(const SweepChainSpec& spec, int k,
                           std::span<const glm::vec3> rest_positions);

// Per-frame state of one chain, scalar type T (float per frame, double for binding).
// Index k runs over bones (0..K-1) or joints (0..K) as each field says.
template <typename T>
struct BasicSweepPose {
  using Vec3 = glm::vec<3, T, glm::defaultp>;
  using Quat = glm::qua<T, glm::defaultp>;
  int num_bones = 0;                               // K
  std::array<Vec3, kMaxSweepBones + 1> points{};   // J_k, model space, k = 0..K
  std::array<Vec3, kMaxSweepBones> axes{};         // a_k = dQ_k a0_k, unit
  std::array<Quat, kMaxSweepBones> rotations{};    // dQ_k, unit, relative to bind
  std::array<T, kMaxSweepBones + 1> down_twist{};  // dn_k radians (0 unless downstream)
  std::array<T, kMaxSweepBones + 1> up_twist{};    // up_k radians (0 unless upstream)
  std::array<Quat, kMaxSweepBones + 1> region_from{};  // Fm_k = dQ_{k-1} Tw(a0_{k-1}, up_k)
  std::array<Quat, kMaxSweepBones + 1> region_to{};    // Fp_k = dQ_k Tw(a0_k, -dn_k), dot(Fm,Fp) >= 0
  // Volume keeping: l0/l - 1 per interior joint region (l = current, l0 = rest arc
  // length of c over the region); all 0 when volume keeping is off.
  std::array<T, kMaxSweepBones + 1> volume_gain{};
};
using SweepPose = BasicSweepPose<float>;

// The checked, immutable rest data of one sweep chain.
class SweepChain {
 public:
  int num_bones() const { return num_bones_; }
  // Skeleton joint whose rotation moves bone k (0..K-1).
  int joint(int k) const { return joints_[static_cast<std::size_t>(k)]; }
  double rest_length(int k) const { return lengths_[static_cast<std::size_t>(k)]; }     // L_k
  const glm::dvec3& rest_axis(int k) const { return axes_[static_cast<std::size_t>(k)]; }  // a0_k
  // Region of joint k in u: [region_start, region_end] (ua_k, ub_k); ub_0 = 0, ua_K = K.
  double region_start(int k) const { return region_start_[static_cast<std::size_t>(k)]; }
  double region_end(int k) const { return region_end_[static_cast<std::size_t>(k)]; }
  // The u at which the rest centre passes through J_k: k at the chain ends, else
  // ua_k + (ub_k - ua_k) hm_k / (hm_k + hp_k) (equal to k only when hm/L_{k-1} = hp/L_k,
  // because the region's Bezier has uniform speed in u when the bones are collinear).
  double joint_parameter(int k) const;
  double half_width_in(int k) const { return hm_[static_cast<std::size_t>(k)]; }   // hm_k
  double half_width_out(int k) const { return hp_[static_cast<std::size_t>(k)]; }  // hp_k
  TwistSpread twist_spread(int k) const { return spread_[static_cast<std::size_t>(k)]; }
  // Rest arc length of c0 over region k (interior joints), model units.
  double rest_region_length(int k) const { return rest_region_length_[static_cast<std::size_t>(k)]; }
  // The bind pose (all dQ identity), double precision.
  const BasicSweepPose<double>& rest_pose() const { return rest_pose_; }

 private:
  friend base::Result<SweepChain> BuildSweepChain(const SweepChainSpec& spec);
  int num_bones_ = 0;
  std::array<int, kMaxSweepBones> joints_{};
  std::array<double, kMaxSweepBones> lengths_{};
  std::array<glm::dvec3, kMaxSweepBones> axes_{};
  std::array<double, kMaxSweepBones + 1> hm_{};
  std::array<double, kMaxSweepBones + 1> hp_{};
  std::array<double, kMaxSweepBones + 1> region_start_{};
  std::array<double, kMaxSweepBones + 1> region_end_{};
  std::array<double, kMaxSweepBones + 1> rest_region_length_{};
  std::array<TwistSpread, kMaxSweepBones + 1> spread_{};
  BasicSweepPose<double> rest_pose_;
};

// Checks the spec and builds the chain: 1..kMaxSweepBones bones, sizes consistent,
// finite values, bones longer than 1e-6, joint indices >= 0, regions of neighbouring
// joints not overlapping (hp_k + hm_{k+1} < L_k). Errors are kInvalidArgument or
// kLimitExceeded, naming the joint or bone.
base::Result<SweepChain> BuildSweepChain(const SweepChainSpec& spec);

// Fills `pose` from the skeleton's current joint rotations dQ (#J, relative to bind,
// unit) and positions (#J, model space). J_0 is the position of joints(0); the other
// points follow the bones rigidly, J_{k+1} = J_k + L_k a_k (so c(u) stays continuous
// even if a skeleton stretches; stretching is not modelled). keep_volume fills
// volume_gain. Never allocates. Joint indices must be < #J (SwdJob::Validate checks).
template <typename T>
void PoseSweepChain(const SweepChain& chain, std::span<const glm::quat> joint_rotations,
                    std::span<const glm::vec3> joint_positions, bool keep_volume,
                    BasicSweepPose<T>* pose);

// Centre curve c(u) (model space); if `derivative` is set, dc/du there. u outside
// [0, K] extends the end bones linearly.
template <typename T>
glm::vec<3, T, glm::defaultp> SweepCentre(const SweepChain& chain, const BasicSweepPose<T>& pose,
                                          T u, glm::vec<3, T, glm::defaultp>* derivative);

// Frame dR(u) applied to rest offsets (unit quaternion):
//   bone k between regions: dQ_k Tw(a0_k, -dn_k (1-lam) + up_{k+1} lam),
//     lam = sm((u-ub_k)/(ua_{k+1}-ub_k));
//   region k: slerp(Fm_k, Fp_k, sm(x)).
template <typename T>
glm::qua<T, glm::defaultp> SweepFrame(const SweepChain& chain, const BasicSweepPose<T>& pose,
                                      T u);

// Cross-section scale at u for volume keeping: sqrt(1 + gain_k 6x(1-x)) in region k
// (so its mean square over the region is l0/l and it is 1 at the region ends), else 1.
template <typename T>
T SweepScale(const SweepChain& chain, const BasicSweepPose<T>& pose, T u);

// If u lies in the region of an interior joint, sets *joint to it and *x to the region
// parameter (u - ua)/(ub - ua) in [0,1] and returns true; else returns false.
template <typename T>
bool SweepRegionAt(const SweepChain& chain, T u, int* joint, T* x);

// Twist quaternion Tw(axis, angle) = (cos(angle/2), sin(angle/2) axis); axis unit.
template <typename T>
glm::qua<T, glm::defaultp> TwistQuat(const glm::vec<3, T, glm::defaultp>& axis, T angle_rad);

// Twist angle of q about unit `axis` (ALGORITHMS.md 5.4) on the short arc:
// 2 atan2(dot(v,axis), w) after making w >= 0, in [-pi, pi]; 0 for a pure 180 deg swing.
template <typename T>
T TwistAngle(const glm::qua<T, glm::defaultp>& q, const glm::vec<3, T, glm::defaultp>& axis);

// slerp(q0, q1, w) = q0 (q0^-1 q1)^w on the shorter arc (q1 negated if dot < 0).
template <typename T>
glm::qua<T, glm::defaultp> SlerpShort(const glm::qua<T, glm::defaultp>& q0,
                                      const glm::qua<T, glm::defaultp>& q1, T w);

// Where one point is bound on one sweep: p0 = c0(u) + offset.
struct SweepBinding {
  float u = 0.0f;             // sweep parameter in [0, K]
  glm::vec3 offset{0.0f};     // o = p0 - c0(u), bind model space (model units)
  // First axis e_a of the rest cross-section's ellipse at u (unit, orthogonal to
  // hat(c0'(u)), bind model space): principal direction, in the section plane, of the
  // offsets bound in the same joint region (the columns of E0 are e_a,
  // e_b = hat(c0') x e_a, hat(c0')). Zero between regions, where no elliptic scaling
  // applies, and when BindToSweep alone made the binding (then the section counts as round).
  glm::vec3 section_axis{0.0f};
  std::uint16_t chain = 0;    // index of the chain in the chain list given to the binder/job
};

// A vertex's binding: one sweep, or two inside a junction zone.
struct SweepVertexBinding {
  SweepBinding primary;    // the branch sweep in a junction zone, else the only sweep
  SweepBinding secondary;  // the trunk sweep; unused when weight == 1
  float weight = 1.0f;     // om in [0,1]: p = om p_primary + (1-om) p_secondary
};

// A junction (shoulder, hip, neck): the branch sweep starts one bone early (at the
// trunk) and its interval [u_start, u_end] is blended with the trunk sweep,
// om = sm((u_branch - u_start)/(u_end - u_start)).
struct SweepJunction {
  int branch = 0;         // index of the branch chain
  int trunk = 0;          // index of the trunk chain
  float u_start = 0.0f;   // junction zone start on the branch (u units)
  float u_end = 1.0f;     // junction zone end, > u_start
  // Width (model units) of a seam fade at the boundary where the trunk becomes the
  // nearest chain [ours]: om is multiplied by sm((d_trunk - d_branch) / seam_band), so
  // it is 0 on both sides of that boundary. d_trunk counts only the two trunk bones at
  // the branch point, so a branch lying against a far part of the trunk in the bind
  // pose (a forearm raised beside the head) is not blended with it. 0 (the default)
  // keeps the plain rule, which leaves a jump there when the branch starts part-way
  // along the trunk (a clavicle on the chest); a band of about the branch's first bone
  // length removes it.
  float seam_band = 0.0f;
};

// Binds one rest point to one chain: roots of g(u) = dot(p0 - c0(u), hat(c0'(u))),
// sampled 64 times per bone, bracketed and bisected to 1e-9 in u (double); of those roots
// and the chain's ends u = 0 and u = K, the one whose c0(u) is nearest p0 wins (so a
// point beyond an end binds to that end even when the normal plane of a distant part of
// the chain passes through it).
// [u_min, u_max] (clamped to [0, K]; u_max < 0 means K) limits the search to part of the
// chain, whose ends then play the chain's ends' part.
SweepBinding BindToSweep(const SweepChain& chain, int chain_index, const glm::dvec3& rest_point,
                         double u_min = 0.0, double u_max = -1.0);

// A chain and parameter chosen for a vertex by whatever made it (the mannequin's tube and
// ring), instead of the nearest chain and the root of g(u).
struct SweepPlacement {
  int chain = -1;    // index into the chain list; -1: bind by distance as usual
  float u = 0.0f;    // sweep parameter, clamped to [0, K]
};

// Binds every rest vertex (#V, bind model space) to the chain whose rest bone segment is
// nearest; a vertex on a junction's branch with u in [u_start, u_end) is also bound to
// the trunk (on the trunk's two bones at the branch point only). Then sets the
// section_axis of every binding inside a joint region: the offsets bound in that region
// give a second-moment matrix sum(o o^T), whose principal direction in the vertex's
// section plane is e_a. (The spec's E0(u) is the PCA of the ring at u; pooling over the
// region keeps e_a continuous in u and defined for nearly round rings, and equals it when
// the region's rings are alike.)
// `primary_ok` (#C, or empty: all) marks the chains a vertex may take as its nearest
// (primary) chain; a branch's body part passes its trunk as not ok, so the trunk moves
// its vertices only through the junction weight (a forearm raised beside the head in
// the bind pose must not follow the head). Errors (kInvalidArgument) for empty or
// oversized chain lists, bad junction indices or intervals, non-finite positions, a
// primary_ok list of another size or with no chain ok.
// `placements` (#V, or empty: none) gives a vertex its primary chain and u outright
// (offset o = p0 - c0(u)); junction weight and trunk binding follow as above. Errors
// also for a placement list of another size, a placement chain out of range or a
// non-finite placement u.
base::Result<std::vector<SweepVertexBinding>> BindToSweeps(
    std::span<const SweepChain> chains, std::span<const SweepJunction> junctions,
    std::span<const glm::vec3> rest_positions, std::span<const std::uint8_t> primary_ok = {},
    std::span<const SweepPlacement> placements = {});

}  // namespace deform
