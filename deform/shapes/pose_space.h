#pragma once
// Pose-space interpolation of example displacements dS(theta) (ALGORITHMS.md 5;
// Lewis, Cordner, Fong 2000; the RBF layer of Lee, Kim, Yoon 2009).
//
//   features (5.1):  x(theta) per influencing joint: Euler angles relative to
//                    rest (radians, wrapped distances), rotation vector of
//                    q_rest^-1 q_local (recommended) or swing-twist; each
//                    joint's features scaled by its weight g_j
//   interpolant (5.2):
//                    dS(x) = sum_e W_e phi(|x - x_e|) [+ c0 + C x]
//                    Phi W = D, or [Phi P; P^T 0][W; c] = [D; 0], P rows (1, x_e^T)
//   kernels:         Gaussian exp(-(r/sig)^2) (default), inverse multiquadric
//                    1/sqrt(r^2+sig^2), multiquadric sqrt(r^2+sig^2) + constant,
//                    polyharmonic r^3 + linear (falls back to Gaussian when
//                    the poses do not span the feature space)
//   widths (5.3):    sig = kappa x mean nearest-neighbour distance of the centres
//
// The rest pose is always centre 0 with D = 0 (its features are 0 for every
// feature kind), so dS is exactly 0 at rest and exact at every example.
// Fit runs once in double (SVD, condition number reported); PoseSpaceJob
// evaluates per frame in float without allocating: K kernel values and
// K x 3MN multiply-adds.

#include <cstdint>
#include <glm/glm.hpp>
#include <span>
#include <string>
#include <vector>

#include "base/error.h"
#include "mocap/motion.h"
#include "mocap/pose.h"
#include "mocap/skeleton.h"

namespace deform {

// Most centres (rest + examples) a model may hold; keeps the job's scratch on the stack.
inline constexpr int kMaxRbfCentres = 256;
// Most feature dimensions (3 per joint).
inline constexpr int kMaxPoseFeatures = 96;

enum class PoseFeatureKind : std::uint8_t {
  kEuler,           // the paper's: local Euler angles relative to rest, radians, wrapped
  kRotationVector,  // rotation vector of q_rest^-1 q_local, radians (recommended)
  kSwingTwist,      // (g_s swing across the axis, g_t twist angle), radians
};

// One joint contributing to theta.
struct PoseFeatureJoint {
  int joint = -1;                          // skeleton index; never the root
  float weight = 1.0f;                     // g_j, multiplies all of this joint's features
  glm::vec3 twist_axis{0.0f, 1.0f, 0.0f};  // kSwingTwist: unit child bone axis, joint frame
  float swing_gain = 1.0f;                 // kSwingTwist: g_s
  float twist_gain = 1.0f;                 // kSwingTwist: g_t
};

struct PoseFeatureSpec {
  PoseFeatureKind kind = PoseFeatureKind::kRotationVector;
  std::vector<PoseFeatureJoint> joints{};  // in the order their features are concatenated
};

// The default joints of a patch (5.1): the skeleton joints whose skin joints
// carry at least `min_weight` of some control point's weight, minus roots,
// in increasing joint order, each with weight 1. `skin_joints` maps skin
// joint -> skeleton joint (SkinnedMesh::skin_joints); joint_indices and
// joint_weights are #C x influences control-point weights (3.7). Indices out
// of range are skipped (they were checked by CheckSkinWeights).
std::vector<PoseFeatureJoint> InfluencingJoints(const mocap::Skeleton& skeleton,
                                                std::span<const int> skin_joints, int influences,
                                                std::span<const std::uint16_t> joint_indices,
                                                std::span<const float> joint_weights,
                                                float min_weight = 0.01f);

// Number of features of `spec` on `skeleton`: 3 per joint, except kEuler which
// has one per rotation channel of the joint.
int PoseFeatureDimension(const mocap::Skeleton& skeleton, const PoseFeatureSpec& spec);

// Checks joints (in range, not a root, unique), weights (finite, > 0) and the
// twist axes (unit within 1e-3) and the dimension (1..kMaxPoseFeatures).
base::Status CheckPoseFeatureSpec(const mocap::Skeleton& skeleton, const PoseFeatureSpec& spec);

// Features of a pose from the #J local transforms (LocalPoseJob output).
// Writes PoseFeatureDimension values; out must be that long (checked).
base::Status ComputePoseFeatures(const mocap::Skeleton& skeleton, const PoseFeatureSpec& spec,
                                 std::span<const mocap::JointTransform> locals,
                                 std::span<float> out);

// Features of frame `frame` of a motion (the pose of an example can be "a
// frame of a motion"). Fails on a frame out of range or a mismatched motion.
base::Result<std::vector<float>> PoseFeaturesAtFrame(const mocap::Skeleton& skeleton,
                                                     const mocap::Motion& motion, int frame,
                                                     const PoseFeatureSpec& spec);

// Distance between two feature vectors: Euclidean, or with every component
// difference wrapped into [-pi, pi] (delta = a - b - 2 pi round((a-b)/(2 pi)))
// for Euler features.
double PoseDistance(std::span<const float> a, std::span<const float> b, bool wrap_angles);

enum class RbfKernel : std::uint8_t {
  kGaussian,             // exp(-(r/sig)^2), positive definite, decays to 0
  kInverseMultiquadric,  // 1/sqrt(r^2 + sig^2)
  kMultiquadric,         // sqrt(r^2 + sig^2) plus a constant term
  kPolyharmonic3,        // r^3 plus a linear term; features clamped to the examples' range
};

// Short name ("gaussian", "inverse-multiquadric", "multiquadric", "polyharmonic3").
const char* RbfKernelName(RbfKernel kernel);

// An example: the pose (features) and its displacements in the local frames.
struct PoseExample {
  std::string name{};                     // for messages, e.g. "elbow_90"
  base::FileLoc loc{};                    // where it was defined (rig file), optional
  std::vector<float> features{};          // dimension of the model
  std::vector<glm::vec3> displacement{};  // #C D_e (local frames, model units)
};

// Interactive editing (4.3): an edit at a pose within `duplicate_tol` of an
// existing example updates that example's displacement (its pose is kept);
// otherwise the example is appended. Returns the index written. The rest pose
// is not in the list: an edit at rest is appended like any other (Fit then
// lets it replace the rest centre). Re-fit the RBF afterwards.
int AddOrUpdateExample(std::vector<PoseExample>& examples, PoseExample example,
                       double duplicate_tol = 1e-4, bool wrap_angles = false);

struct RbfOptions {
  RbfKernel kernel = RbfKernel::kGaussian;
  double kappa = 1.0;            // sig = kappa x mean nearest-neighbour distance (0.5-2)
  double width = 0.0;            // > 0 overrides the automatic sig (feature units)
  bool wrap_angles = false;      // true for Euler features (wrapped distances)
  double duplicate_tol = 1e-4;   // centres closer than this are duplicates (error)
  double smoothing = 0.0;        // lam of Phi + lam I (no longer exact when > 0)
  double warn_condition = 1e10;  // condition number above which a warning is added
};

// A fitted interpolant (immutable, shared by the per-frame job).
struct RbfModel {
  RbfKernel kernel = RbfKernel::kGaussian;  // kernel actually used (after any fallback)
  int dimension = 0;                        // #X features
  int num_centres = 0;  // K = 1 (rest) + examples (or the examples, if one is at rest)
  int num_values = 0;   // 3 x #C
  bool wrap_angles = false;
  float width = 1.0f;               // sig (feature units); unused by kPolyharmonic3
  std::vector<float> centres;       // K x #X, row-major
  std::vector<float> weights;       // K x 3#C, row-major: W_e
  std::vector<float> poly;          // (1 + #X) x 3#C: constant row then linear rows, or empty
  std::vector<float> lower, upper;  // #X feature range of the centres (clamp for kPolyharmonic3)
  double condition = 1.0;           // 2-norm condition number of the solved system
  std::vector<base::Warning> warnings;  // ill-conditioning, kernel fallback

  // Evaluation in double (for tests and tools; allocates): dS(x), 3#C values.
  std::vector<double> EvaluateReference(std::span<const float> features) const;
};

class RbfPoseSpace {
 public:
  // Fits the interpolant to the examples plus the rest centre (0, D = 0).
  // All examples must have `dimension` finite features and the same #C. Errors
  // (kInvalidArgument) on mismatched sizes, non-finite values, more than
  // kMaxRbfCentres centres, two examples closer than duplicate_tol (naming
  // both), or a singular system. An example at the rest pose replaces the
  // rest centre (the user sculpted at rest).
  static base::Result<RbfModel> Fit(std::span<const PoseExample> examples, int dimension,
                                    int num_control, const RbfOptions& options = {});
};

// Per frame: dS(theta) into a caller span. Never allocates (kernel values on
// the stack, K <= kMaxRbfCentres); deterministic.
struct PoseSpaceJob {
  const RbfModel* model = nullptr;      // required
  std::span<const float> features{};    // #X pose features (ComputePoseFeatures)
  std::span<glm::vec3> displacement{};  // #C output dS, local frames

  [[nodiscard]] base::JobStatus Validate() const;
  [[nodiscard]] base::JobStatus Run() const;
};

}  // namespace deform
