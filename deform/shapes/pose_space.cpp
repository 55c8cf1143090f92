#include "deform/shapes/pose_space.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <opencv2/core.hpp>
#include <sstream>

#include "mocap/joint_angles.h"
#include "deform/internal/checks.h"

namespace deform {
namespace {

using base::ErrorCode;
using base::JobStatus;

constexpr double kTwoPi = 2.0 * std::numbers::pi;

bool IsRotationChannel(mocap::ChannelType t) {
  return t == mocap::ChannelType::kXRotation || t == mocap::ChannelType::kYRotation ||
         t == mocap::ChannelType::kZRotation;
}

int EulerCount(const mocap::Skeleton& skeleton, int joint) {
  const mocap::JointChannels& ch = skeleton.channels[static_cast<size_t>(joint)];
  int n = 0;
  for (int k = 0; k < ch.count; ++k)
    n += IsRotationChannel(ch.types[static_cast<size_t>(k)]) ? 1 : 0;
  return n;
}

using internal::InvalidArgument;

// The kernel phi(r) for width sig, in double (fit) or float (per frame).
template <typename T>
T Kernel(RbfKernel kernel, T r, T sig) {
  switch (kernel) {
    case RbfKernel::kGaussian: {
      const T q = r / sig;
      return std::exp(-q * q);
    }
    case RbfKernel::kInverseMultiquadric: return T(1) / std::sqrt(r * r + sig * sig);
    case RbfKernel::kMultiquadric: return std::sqrt(r * r + sig * sig);
    case RbfKernel::kPolyharmonic3: return r * r * r;
  }
  return T(0);
}

template <typename T>
T WrappedDelta(T d, bool wrap) {
  if (!wrap) return d;
  const T period = static_cast<T>(kTwoPi);
  return d - period * std::round(d / period);
}

// Polynomial columns a kernel needs: 0, 1 (constant) or 1 + #X (linear).
int PolyColumns(RbfKernel kernel, int dimension) {
  if (kernel == RbfKernel::kMultiquadric) return 1;
  if (kernel == RbfKernel::kPolyharmonic3) return 1 + dimension;
  return 0;
}

std::string ExampleLabel(const PoseExample& e, size_t index) {
  return "example '" + e.name + "' (index " + std::to_string(index) + ")";
}

}  // namespace

std::vector<PoseFeatureJoint> InfluencingJoints(const mocap::Skeleton& skeleton,
                                                std::span<const int> skin_joints, int influences,
                                                std::span<const std::uint16_t> joint_indices,
                                                std::span<const float> joint_weights,
                                                float min_weight) {
  std::vector<std::uint8_t> used(static_cast<size_t>(skeleton.num_joints()), 0);
  const size_t n = std::min(joint_indices.size(), joint_weights.size());
  for (size_t k = 0; influences > 0 && k < n; ++k) {
    if (!(joint_weights[k] >= min_weight) || joint_indices[k] >= skin_joints.size()) continue;
    const int joint = skin_joints[joint_indices[k]];
    if (joint >= 0 && joint < skeleton.num_joints()) used[static_cast<size_t>(joint)] = 1;
  }
  std::vector<PoseFeatureJoint> out;
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    if (used[static_cast<size_t>(j)] != 0 &&
        skeleton.parents[static_cast<size_t>(j)] != mocap::kNoParent) {
      out.push_back({.joint = j});
    }
  }
  return out;
}

int PoseFeatureDimension(const mocap::Skeleton& skeleton, const PoseFeatureSpec& spec) {
  int dim = 0;
  for (const PoseFeatureJoint& j : spec.joints) {
    if (j.joint < 0 || j.joint >= skeleton.num_joints()) continue;
    dim += spec.kind == PoseFeatureKind::kEuler ? EulerCount(skeleton, j.joint) : 3;
  }
  return dim;
}

base::Status CheckPoseFeatureSpec(const mocap::Skeleton& skeleton, const PoseFeatureSpec& spec) {
  if (spec.joints.empty()) return InvalidArgument("expected at least one pose joint, found none");
  for (size_t k = 0; k < spec.joints.size(); ++k) {
    const PoseFeatureJoint& j = spec.joints[k];
    const std::string where = "pose joint " + std::to_string(k);
    if (j.joint < 0 || j.joint >= skeleton.num_joints()) {
      return InvalidArgument(where + ": expected a joint index below " +
                             std::to_string(skeleton.num_joints()) + ", found " +
                             std::to_string(j.joint));
    }
    const std::string& name = skeleton.names[static_cast<size_t>(j.joint)];
    if (skeleton.parents[static_cast<size_t>(j.joint)] == mocap::kNoParent) {
      return InvalidArgument(where + ": '" + name +
                             "' is a root; expected a joint that bends the patch");
    }
    for (size_t o = 0; o < k; ++o) {
      if (spec.joints[o].joint == j.joint)
        return InvalidArgument(where + ": '" + name + "' is listed twice");
    }
    if (!std::isfinite(j.weight) || j.weight <= 0.0f) {
      return InvalidArgument(where + ": expected a finite weight > 0 for '" + name + "'");
    }
    if (spec.kind == PoseFeatureKind::kEuler && j.weight != 1.0f) {
      return InvalidArgument(where +
                             ": Euler features wrap at 2 pi and take no weight; use the "
                             "rotation-vector features to weight '" +
                             name + "'");
    }
    if (spec.kind == PoseFeatureKind::kSwingTwist &&
        std::abs(glm::length(j.twist_axis) - 1.0f) > 1e-3f) {
      return InvalidArgument(where + ": expected a unit twist axis for '" + name + "'");
    }
  }
  const int dim = PoseFeatureDimension(skeleton, spec);
  if (dim < 1 || dim > kMaxPoseFeatures) {
    return InvalidArgument("expected 1.." + std::to_string(kMaxPoseFeatures) +
                           " pose features, found " + std::to_string(dim) +
                           " (Euler joints without rotation channels add none)");
  }
  return {};
}

base::Status ComputePoseFeatures(const mocap::Skeleton& skeleton, const PoseFeatureSpec& spec,
                                 std::span<const mocap::JointTransform> locals,
                                 std::span<float> out) {
  if (locals.size() != static_cast<size_t>(skeleton.num_joints())) {
    return InvalidArgument("expected " + std::to_string(skeleton.num_joints()) +
                           " local transforms");
  }
  if (out.size() != static_cast<size_t>(PoseFeatureDimension(skeleton, spec))) {
    return InvalidArgument("feature output has the wrong size");
  }
  size_t at = 0;
  constexpr float kDegToRad = std::numbers::pi_v<float> / 180.0f;
  for (const PoseFeatureJoint& j : spec.joints) {
    if (j.joint < 0 || j.joint >= skeleton.num_joints())
      return InvalidArgument("pose joint out of range");
    const glm::quat rest = skeleton.rest_rotations[static_cast<size_t>(j.joint)];
    const glm::quat local = locals[static_cast<size_t>(j.joint)].rotation;
    switch (spec.kind) {
      case PoseFeatureKind::kEuler: {
        float deg[3] = {0.0f, 0.0f, 0.0f};
        const int n = mocap::JointEulerAngles(skeleton, j.joint, local, deg);
        for (int k = 0; k < n; ++k) out[at++] = deg[k] * kDegToRad;
        break;
      }
      case PoseFeatureKind::kRotationVector: {
        const glm::vec3 r = j.weight * mocap::RotationVectorFeature(rest, local);
        for (int k = 0; k < 3; ++k) out[at++] = r[k];
        break;
      }
      case PoseFeatureKind::kSwingTwist: {
        const glm::vec3 r =
            j.weight * mocap::SwingTwistFeature(glm::inverse(rest) * local, j.twist_axis,
                                                j.swing_gain, j.twist_gain);
        for (int k = 0; k < 3; ++k) out[at++] = r[k];
        break;
      }
    }
  }
  return {};
}

base::Result<std::vector<float>> PoseFeaturesAtFrame(const mocap::Skeleton& skeleton,
                                                     const mocap::Motion& motion, int frame,
                                                     const PoseFeatureSpec& spec) {
  if (frame < 0 || frame >= motion.num_frames) {
    return InvalidArgument("expected a frame in 0.." + std::to_string(motion.num_frames - 1) +
                           ", found " + std::to_string(frame));
  }
  std::vector<mocap::JointTransform> locals(static_cast<size_t>(skeleton.num_joints()));
  const mocap::LocalPoseJob job{
      .skeleton = &skeleton, .frame_values = motion.frame(frame), .locals = locals};
  const JobStatus status = job.Run();
  if (!status.ok())
    return InvalidArgument(std::string("motion does not fit the skeleton: ") + status.what);
  std::vector<float> features(static_cast<size_t>(PoseFeatureDimension(skeleton, spec)));
  base::Status s = ComputePoseFeatures(skeleton, spec, locals, features);
  if (!s.ok()) return s.error();
  return features;
}

double PoseDistance(std::span<const float> a, std::span<const float> b, bool wrap_angles) {
  double sum = 0.0;
  const size_t n = std::min(a.size(), b.size());
  for (size_t k = 0; k < n; ++k) {
    const double d =
        WrappedDelta(static_cast<double>(a[k]) - static_cast<double>(b[k]), wrap_angles);
    sum += d * d;
  }
  return std::sqrt(sum);
}

const char* RbfKernelName(RbfKernel kernel) {
  switch (kernel) {
    case RbfKernel::kGaussian: return "gaussian";
    case RbfKernel::kInverseMultiquadric: return "inverse-multiquadric";
    case RbfKernel::kMultiquadric: return "multiquadric";
    case RbfKernel::kPolyharmonic3: return "polyharmonic3";
  }
  return "unknown";
}

int AddOrUpdateExample(std::vector<PoseExample>& examples, PoseExample example,
                       double duplicate_tol, bool wrap_angles) {
  for (size_t e = 0; e < examples.size(); ++e) {
    if (examples[e].features.size() == example.features.size() &&
        PoseDistance(examples[e].features, example.features, wrap_angles) < duplicate_tol) {
      examples[e].displacement = std::move(example.displacement);
      return static_cast<int>(e);
    }
  }
  examples.push_back(std::move(example));
  return static_cast<int>(examples.size()) - 1;
}

base::Result<RbfModel> RbfPoseSpace::Fit(std::span<const PoseExample> examples, int dimension,
                                         int num_control, const RbfOptions& options) {
  if (dimension < 1 || dimension > kMaxPoseFeatures) {
    return InvalidArgument("expected 1.." + std::to_string(kMaxPoseFeatures) +
                           " pose features, found " + std::to_string(dimension));
  }
  if (num_control < 1) return InvalidArgument("expected at least one control point");
  if (!(options.kappa > 0.0) || !(options.width >= 0.0) || !(options.duplicate_tol >= 0.0) ||
      !(options.smoothing >= 0.0)) {
    return InvalidArgument("expected kappa > 0 and width, duplicate_tol, smoothing >= 0");
  }
  for (size_t e = 0; e < examples.size(); ++e) {
    const PoseExample& ex = examples[e];
    if (ex.features.size() != static_cast<size_t>(dimension)) {
      return InvalidArgument(ex.loc, ExampleLabel(ex, e) + ": expected " +
                                         std::to_string(dimension) + " pose features, found " +
                                         std::to_string(ex.features.size()));
    }
    if (ex.displacement.size() != static_cast<size_t>(num_control)) {
      return InvalidArgument(ex.loc, ExampleLabel(ex, e) + ": expected " +
                                         std::to_string(num_control) +
                                         " control-point displacements, found " +
                                         std::to_string(ex.displacement.size()));
    }
    for (float f : ex.features) {
      if (!std::isfinite(f))
        return InvalidArgument(ex.loc, ExampleLabel(ex, e) + ": non-finite pose feature");
    }
    for (const glm::vec3& d : ex.displacement) {
      if (!std::isfinite(d.x) || !std::isfinite(d.y) || !std::isfinite(d.z)) {
        return InvalidArgument(ex.loc, ExampleLabel(ex, e) + ": non-finite displacement");
      }
    }
  }
  // Duplicates (5.3): an error naming both, never a silent average.
  const std::vector<float> rest(static_cast<size_t>(dimension), 0.0f);
  bool sculpted_at_rest = false;
  for (size_t a = 0; a < examples.size(); ++a) {
    if (PoseDistance(examples[a].features, rest, options.wrap_angles) < options.duplicate_tol) {
      sculpted_at_rest = true;
    }
    for (size_t b = 0; b < a; ++b) {
      const double dist =
          PoseDistance(examples[a].features, examples[b].features, options.wrap_angles);
      if (dist < options.duplicate_tol) {
        std::ostringstream msg;
        msg << ExampleLabel(examples[a], a) << " duplicates " << ExampleLabel(examples[b], b)
            << ": their poses are " << dist << " apart, below the duplicate tolerance "
            << options.duplicate_tol << "; merge them or edit one pose";
        return InvalidArgument(examples[a].loc, msg.str());
      }
    }
  }
  const int k_count = static_cast<int>(examples.size()) + (sculpted_at_rest ? 0 : 1);
  if (k_count > kMaxRbfCentres) {
    return base::MakeError(ErrorCode::kLimitExceeded, {},
                           "expected at most " + std::to_string(kMaxRbfCentres) +
                               " pose centres, found " + std::to_string(k_count));
  }

  RbfModel model;
  model.kernel = options.kernel;
  model.dimension = dimension;
  model.num_centres = k_count;
  model.num_values = 3 * num_control;
  model.wrap_angles = options.wrap_angles;
  const size_t dim = static_cast<size_t>(dimension), nv = static_cast<size_t>(model.num_values);
  const size_t kk = static_cast<size_t>(k_count);
  model.centres.assign(kk * dim, 0.0f);
  std::vector<double> values(kk * nv, 0.0);  // D, the rest row (if any) stays 0
  const size_t first = sculpted_at_rest ? 0 : 1;
  for (size_t e = 0; e < examples.size(); ++e) {
    std::copy(examples[e].features.begin(), examples[e].features.end(),
              model.centres.begin() + static_cast<std::ptrdiff_t>((first + e) * dim));
    for (size_t c = 0; c < static_cast<size_t>(num_control); ++c) {
      for (size_t x = 0; x < 3; ++x)
        values[(first + e) * nv + 3 * c + x] = examples[e].displacement[c][static_cast<int>(x)];
    }
  }
  model.lower.assign(dim, 0.0f);
  model.upper.assign(dim, 0.0f);
  for (size_t d = 0; d < dim; ++d) {
    model.lower[d] = model.upper[d] = model.centres[d];
    for (size_t k = 1; k < kk; ++k) {
      model.lower[d] = std::min(model.lower[d], model.centres[k * dim + d]);
      model.upper[d] = std::max(model.upper[d], model.centres[k * dim + d]);
    }
  }
  auto centre = [&](size_t k) {
    return std::span<const float>(model.centres.data() + k * dim, dim);
  };
  std::vector<double> dist(kk * kk, 0.0);
  for (size_t a = 0; a < kk; ++a) {
    for (size_t b = 0; b < kk; ++b)
      dist[a * kk + b] = PoseDistance(centre(a), centre(b), options.wrap_angles);
  }
  // Width (5.3): kappa x mean nearest-neighbour distance.
  double sig = options.width;
  if (sig <= 0.0) {
    double sum = 0.0;
    for (size_t a = 0; a < kk; ++a) {
      double nearest = std::numeric_limits<double>::infinity();
      for (size_t b = 0; b < kk; ++b) {
        if (b != a) nearest = std::min(nearest, dist[a * kk + b]);
      }
      sum += kk > 1 ? nearest : 1.0;
    }
    sig = options.kappa * sum / static_cast<double>(kk);
  }
  model.width = static_cast<float>(sig);

  if (k_count == 1 && !sculpted_at_rest) {  // rest only: dS = 0 everywhere
    model.weights.assign(nv, 0.0f);
    return model;
  }
  try {
    // The linear term needs P of full column rank (dim + 1 affinely independent poses).
    if (model.kernel == RbfKernel::kPolyharmonic3) {
      bool full_rank = kk >= dim + 1;
      if (full_rank) {
        cv::Mat p(k_count, dimension + 1, CV_64F);
        for (size_t k = 0; k < kk; ++k) {
          p.at<double>(static_cast<int>(k), 0) = 1.0;
          for (size_t d = 0; d < dim; ++d)
            p.at<double>(static_cast<int>(k), static_cast<int>(d + 1)) = centre(k)[d];
        }
        cv::Mat w;
        cv::SVD::compute(p, w, cv::SVD::NO_UV);
        full_rank = w.at<double>(dimension) > 1e-9 * w.at<double>(0);
      }
      if (!full_rank) {
        model.kernel = RbfKernel::kGaussian;
        model.warnings.push_back({{},
                                  "polyharmonic kernel needs " + std::to_string(dimension + 1) +
                                      " affinely independent poses; fell back to gaussian"});
      }
    }
    const int np = PolyColumns(model.kernel, dimension);
    const int n = k_count + np;
    cv::Mat sys = cv::Mat::zeros(n, n, CV_64F);
    cv::Mat rhs = cv::Mat::zeros(n, model.num_values, CV_64F);
    for (int a = 0; a < k_count; ++a) {
      for (int b = 0; b < k_count; ++b) {
        sys.at<double>(a, b) =
            Kernel(model.kernel, dist[static_cast<size_t>(a) * kk + static_cast<size_t>(b)], sig);
      }
      sys.at<double>(a, a) += options.smoothing;
      for (int c = 0; c < np; ++c) {
        const double pv = c == 0 ? 1.0 : centre(static_cast<size_t>(a))[static_cast<size_t>(c - 1)];
        sys.at<double>(a, k_count + c) = pv;
        sys.at<double>(k_count + c, a) = pv;
      }
      for (int v = 0; v < model.num_values; ++v)
        rhs.at<double>(a, v) = values[static_cast<size_t>(a) * nv + static_cast<size_t>(v)];
    }
    cv::SVD svd(sys, cv::SVD::FULL_UV);
    const double s_max = svd.w.at<double>(0), s_min = svd.w.at<double>(n - 1);
    if (!(s_min > 1e-15 * s_max)) {
      return InvalidArgument(
          "the pose-space system is singular (condition number above 1e15); "
          "spread the example poses or change the kernel width");
    }
    model.condition = s_max / s_min;
    if (model.condition > options.warn_condition) {
      std::ostringstream msg;
      msg << "pose-space system is ill-conditioned (condition number " << model.condition << " > "
          << options.warn_condition << "); lower kappa or spread the example poses";
      model.warnings.push_back({{}, msg.str()});
    }
    cv::Mat sol;
    svd.backSubst(rhs, sol);
    model.weights.resize(kk * nv);
    for (size_t k = 0; k < kk; ++k) {
      for (size_t v = 0; v < nv; ++v)
        model.weights[k * nv + v] =
            static_cast<float>(sol.at<double>(static_cast<int>(k), static_cast<int>(v)));
    }
    model.poly.resize(static_cast<size_t>(np) * nv);
    for (size_t c = 0; c < static_cast<size_t>(np); ++c) {
      for (size_t v = 0; v < nv; ++v)
        model.poly[c * nv + v] =
            static_cast<float>(sol.at<double>(static_cast<int>(kk + c), static_cast<int>(v)));
    }
  } catch (const cv::Exception& e) {
    return base::MakeError(ErrorCode::kInternal, {},
                           std::string("pose-space solve failed: ") + e.what());
  }
  return model;
}

std::vector<double> RbfModel::EvaluateReference(std::span<const float> features) const {
  const size_t dim = static_cast<size_t>(dimension), nv = static_cast<size_t>(num_values);
  std::vector<double> out(nv, 0.0);
  std::vector<float> x(features.begin(), features.end());
  if (kernel == RbfKernel::kPolyharmonic3) {
    for (size_t d = 0; d < dim; ++d) x[d] = std::clamp(x[d], lower[d], upper[d]);
  }
  for (size_t k = 0; k < static_cast<size_t>(num_centres); ++k) {
    const double r =
        PoseDistance(x, std::span<const float>(centres.data() + k * dim, dim), wrap_angles);
    const double phi = Kernel<double>(kernel, r, width);
    for (size_t v = 0; v < nv; ++v) out[v] += phi * weights[k * nv + v];
  }
  if (!poly.empty()) {
    for (size_t v = 0; v < nv; ++v) {
      out[v] += poly[v];
      for (size_t d = 0; d + 1 < poly.size() / nv; ++d)
        out[v] += static_cast<double>(x[d]) * poly[(d + 1) * nv + v];
    }
  }
  return out;
}

JobStatus PoseSpaceJob::Validate() const {
  if (model == nullptr) return {JobStatus::kMissingInput, "model is null"};
  if (features.size() != static_cast<size_t>(model->dimension)) {
    return {JobStatus::kSizeMismatch, "features must have the model's dimension"};
  }
  if (displacement.size() * 3 != static_cast<size_t>(model->num_values)) {
    return {JobStatus::kSizeMismatch, "displacement must be #C of the model"};
  }
  if (model->num_centres < 1 || model->num_centres > kMaxRbfCentres ||
      model->weights.size() != static_cast<size_t>(model->num_centres) * displacement.size() * 3) {
    return {JobStatus::kOutOfRange, "model is not fitted"};
  }
  return base::kJobOk;
}

JobStatus PoseSpaceJob::Run() const {
  const JobStatus status = Validate();
  if (!status.ok()) return status;
  static_assert(sizeof(glm::vec3) == 3 * sizeof(float));
  const RbfModel& m = *model;
  const size_t dim = static_cast<size_t>(m.dimension), nv = static_cast<size_t>(m.num_values);
  float x[kMaxPoseFeatures];
  for (size_t d = 0; d < dim; ++d) {
    x[d] = m.kernel == RbfKernel::kPolyharmonic3 ? std::clamp(features[d], m.lower[d], m.upper[d])
                                                 : features[d];
  }
  float phi[kMaxRbfCentres];
  for (size_t k = 0; k < static_cast<size_t>(m.num_centres); ++k) {
    const float* c = m.centres.data() + k * dim;
    float r2 = 0.0f;
    for (size_t d = 0; d < dim; ++d) {
      const float delta = WrappedDelta(x[d] - c[d], m.wrap_angles);
      r2 += delta * delta;
    }
    phi[k] = Kernel<float>(m.kernel, std::sqrt(r2), m.width);
  }
  float* __restrict out = &displacement[0].x;
  const float* __restrict w = m.weights.data();
  const size_t num_centres = static_cast<size_t>(m.num_centres);
  // Four values at a time with the K centres inside, in registers: each
  // value is still ((0 + phi_0 W_0) + phi_1 W_1) + ..., in centre order (the
  // same bits as one pass over the output per centre), without loading and
  // storing the output K times.
  typedef float F4 __attribute__((vector_size(16)));
  size_t at = 0;
  for (; at + 8 <= nv; at += 8) {
    F4 acc0 = {0.0f, 0.0f, 0.0f, 0.0f}, acc1 = acc0;
    const float* __restrict row = w + at;
    for (size_t k = 0; k < num_centres; ++k, row += nv) {
      F4 r0, r1;
      __builtin_memcpy(&r0, row, sizeof(r0));  // unaligned loads
      __builtin_memcpy(&r1, row + 4, sizeof(r1));
      const F4 pk = phi[k] - F4{};  // phi_k in every lane (x - 0 is x)
      acc0 += pk * r0;
      acc1 += pk * r1;
    }
    __builtin_memcpy(out + at, &acc0, sizeof(acc0));
    __builtin_memcpy(out + at + 4, &acc1, sizeof(acc1));
  }
  for (; at < nv; ++at) {
    float acc = 0.0f;
    for (size_t k = 0; k < num_centres; ++k) acc += phi[k] * w[k * nv + at];
    out[at] = acc;
  }
  if (!m.poly.empty()) {
    const size_t rows = m.poly.size() / nv;
    for (size_t v = 0; v < nv; ++v) out[v] += m.poly[v];
    for (size_t d = 0; d + 1 < rows; ++d) {
      const float xd = x[d];
      const float* row = m.poly.data() + (d + 1) * nv;
      for (size_t v = 0; v < nv; ++v) out[v] += xd * row[v];
    }
  }
  return base::kJobOk;
}

}  // namespace deform
