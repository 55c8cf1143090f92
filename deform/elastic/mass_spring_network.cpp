// Setup of the elastic layer's network (ALGORITHMS.md 6): topology, stiffness
// scaling from the slowest eigenvalue, the modal basis and the step rule.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include <opencv2/core.hpp>

#include "deform/elastic/mass_spring.h"
#include "deform/internal/checks.h"

namespace deform {
namespace {

using base::ErrorCode;
using base::FileLoc;
using base::MakeError;

constexpr double kStepRuleAccurate = 0.5;  // h x rate for ~1e-4 amplitude error per step
constexpr double kStepRuleHardLimit = 2.5; // RK4 reaches 2.78 (real) / 2.83 (imaginary)
constexpr int kMaxHalvings = 6;
constexpr int kMaxGridSize = 16;

using internal::Finite;

Result<MassSpringNetwork> NetworkError(const std::string& what) {
  return base::InvalidArgument(FileLoc{}, "mass-spring network: " + what);
}

}  // namespace

Result<MassSpringNetwork> BuildMassSpringNetwork(const MassSpringSetup& setup,
                                                 const MassSpringParams& params) {
  const int M = setup.rows, N = setup.cols;
  if (M < 3 || N < 3 || M > kMaxGridSize || N > kMaxGridSize) {
    return NetworkError("grid " + std::to_string(M) + " x " + std::to_string(N) +
                        " outside 3..16 x 3..16 (a free interior needs 3 x 3)");
  }
  const std::size_t num_points = static_cast<std::size_t>(M) * static_cast<std::size_t>(N);
  if (setup.rest_points.size() != num_points) {
    return NetworkError("expected " + std::to_string(num_points) + " rest points, found " +
                        std::to_string(setup.rest_points.size()));
  }
  for (const glm::vec3& p : setup.rest_points)
    if (!Finite(p)) return NetworkError("non-finite rest control point");
  const MassSpringParams& p = params;
  const bool ok = p.mass > 0 && p.frequency_hz > 0 && p.damping_ratio >= 0 &&
                  p.structural_ratio >= 0 && p.shear_ratio >= 0 && p.bending_ratio >= 0 &&
                  p.spring_damping_s >= 0 && p.time_step_s > 0 && p.gain >= 0 &&
                  p.units_per_metre > 0 && p.max_acceleration_mps2 > 0 && p.max_time_gap_s > 0 &&
                  p.preroll_s >= 0 && std::isfinite(p.max_displacement) &&
                  std::isfinite(p.preroll_s) && std::isfinite(p.time_step_s) &&
                  std::isfinite(p.max_acceleration_mps2) && std::isfinite(p.frequency_hz) &&
                  std::isfinite(p.mass) && std::isfinite(p.gain) && Finite(p.down) &&
                  glm::length(p.down) > 0.5f && setup.max_angular_speed_rad_s >= 0 &&
                  std::isfinite(setup.max_angular_speed_rad_s);
  if (!ok) return NetworkError("a parameter is out of range (see MassSpringParams)");

  MassSpringNetwork net;
  net.rows = M;
  net.cols = N;
  net.params = p;
  net.bind_rotation = glm::normalize(setup.bind_rotation);
  net.rest_points.assign(setup.rest_points.begin(), setup.rest_points.end());
  net.free_of_point.assign(num_points, -1);
  for (int i = 1; i + 1 < M; ++i) {
    for (int j = 1; j + 1 < N; ++j) {
      net.free_of_point[static_cast<std::size_t>(i * N + j)] = net.num_free++;
      net.point_of_free.push_back(i * N + j);
    }
  }
  const int n = net.num_free;
  const std::size_t ns = static_cast<std::size_t>(n);

  // Each pair once: offsets pointing "forward" in row-major order.
  struct Offset { int di, dj; SpringKind kind; float ratio; };
  const Offset offsets[] = {{0, 1, kStructural, p.structural_ratio},
                            {1, 0, kStructural, p.structural_ratio},
                            {1, 1, kShear, p.shear_ratio},
                            {1, -1, kShear, p.shear_ratio},
                            {0, 2, kBending, p.bending_ratio},
                            {2, 0, kBending, p.bending_ratio}};
  double spacing_sum = 0.0;
  int spacing_count = 0;
  cv::Mat k1 = cv::Mat::eye(n, n, CV_64F);  // anchors: k_an = 1
  for (int i = 0; i < M; ++i) {
    for (int j = 0; j < N; ++j) {
      for (const Offset& o : offsets) {
        const int i2 = i + o.di, j2 = j + o.dj;
        if (i2 < 0 || i2 >= M || j2 < 0 || j2 >= N) continue;
        const int a = i * N + j, b = i2 * N + j2;
        const glm::vec3 pa = net.rest_points[static_cast<std::size_t>(a)];
        const glm::vec3 pb = net.rest_points[static_cast<std::size_t>(b)];
        if (o.kind == kStructural) {
          spacing_sum += glm::length(pa - pb);
          ++spacing_count;
        }
        const int fa = net.free_of_point[static_cast<std::size_t>(a)];
        const int fb = net.free_of_point[static_cast<std::size_t>(b)];
        if (fa < 0 && fb < 0) continue;
        net.springs.push_back({a, b, fa, fb, o.ratio, 0.0f, glm::length(pa - pb), o.kind});
        ++net.num_springs[o.kind];
        if (fa >= 0) k1.at<double>(fa, fa) += o.ratio;
        if (fb >= 0) k1.at<double>(fb, fb) += o.ratio;
        if (fa >= 0 && fb >= 0) {
          k1.at<double>(fa, fb) -= o.ratio;
          k1.at<double>(fb, fa) -= o.ratio;
        }
      }
    }
  }
  const double mean_spacing = spacing_sum / spacing_count;
  if (net.params.max_displacement <= 0.0f) {
    if (!(mean_spacing > 0.0)) return NetworkError("rest control points coincide (zero spacing)");
    net.params.max_displacement = static_cast<float>(0.5 * mean_spacing);
  }

  cv::Mat eigenvalues, eigenvectors;  // descending; eigenvectors in rows
  try {
    if (!cv::eigen(k1, eigenvalues, eigenvectors)) return NetworkError("eigen solve failed");
  } catch (const cv::Exception& e) {
    return MakeError(ErrorCode::kInternal, FileLoc{}, std::string("cv::eigen: ") + e.what());
  }
  net.lambda_min = eigenvalues.at<double>(n - 1);
  const double two_pi_f0 = 2.0 * std::numbers::pi * p.frequency_hz;
  const double s = p.mass * two_pi_f0 * two_pi_f0 / net.lambda_min;
  net.stiffness_scale = s;
  net.anchor_stiffness = static_cast<float>(s);
  net.anchor_damping = static_cast<float>(2.0 * p.damping_ratio * two_pi_f0 * p.mass);
  for (Spring& sp : net.springs) {
    sp.stiffness = static_cast<float>(sp.stiffness * s);
    sp.damping = p.spring_damping_s * sp.stiffness;
  }
  net.modes.resize(ns * ns);
  net.mode_omega2.resize(ns);
  net.mode_damping.resize(ns);
  net.mode_sum.assign(ns, 0.0f);
  net.mode_rest.assign(ns, glm::vec3(0.0f));
  for (int k = 0; k < n; ++k) {
    const int row = n - 1 - k;  // ascending order
    const double lambda = eigenvalues.at<double>(row);
    const std::size_t ks = static_cast<std::size_t>(k);
    net.mode_omega2[ks] = static_cast<float>(s * lambda / p.mass);
    net.mode_damping[ks] = static_cast<float>(
        (net.anchor_damping + p.spring_damping_s * s * (lambda - 1.0)) / p.mass);
    for (int a = 0; a < n; ++a) {
      const float u = static_cast<float>(eigenvectors.at<double>(row, a));
      net.modes[static_cast<std::size_t>(a) * ns + ks] = u;
      net.mode_sum[ks] += u;
      net.mode_rest[ks] += u * net.rest_points[static_cast<std::size_t>(net.point_of_free[
                                   static_cast<std::size_t>(a)])];
    }
  }
  net.mode_max_abs.assign(ns, 0.0f);
  for (std::size_t a = 0; a < ns; ++a)
    for (std::size_t k = 0; k < ns; ++k)
      net.mode_max_abs[k] = std::max(net.mode_max_abs[k], std::abs(net.modes[a * ns + k]));

  // Gershgorin bound on the eigenvalues of the linear system (ALGORITHMS.md 6).
  std::vector<double> row_k(ns, s), row_c(ns, net.anchor_damping);
  for (const Spring& sp : net.springs) {
    for (int f : {sp.free_a, sp.free_b}) {
      if (f < 0) continue;
      row_k[static_cast<std::size_t>(f)] += 2.0 * sp.stiffness;
      row_c[static_cast<std::size_t>(f)] += 2.0 * sp.damping;
    }
  }
  const double w_max = std::sqrt(*std::max_element(row_k.begin(), row_k.end()) / p.mass);
  const double c_max = *std::max_element(row_c.begin(), row_c.end());
  net.gershgorin_rate = std::max(w_max, c_max / p.mass);
  const double rate = net.gershgorin_rate + 2.0 * setup.max_angular_speed_rad_s;
  double h = p.time_step_s;
  int halvings = 0;
  while (h * rate > kStepRuleAccurate && halvings < kMaxHalvings) {
    h *= 0.5;
    ++halvings;
  }
  char buf[200];
  if (halvings > 0) {
    std::snprintf(buf, sizeof buf,
                  "time step halved %d time(s) to %.6g s: h (max(w_max, c_max/m) + 2|w|) was "
                  "%.3f > %.1f",
                  halvings, h, p.time_step_s * rate, kStepRuleAccurate);
    net.messages.emplace_back(buf);
  }
  if (h * rate > kStepRuleHardLimit) {
    std::snprintf(buf, sizeof buf,
                  "step rule: h (max(w_max, c_max/m) + 2|w|) = %.3f > %.1f even at h = %.6g s "
                  "(stiffness or damping too high)",
                  h * rate, kStepRuleHardLimit, h);
    return NetworkError(buf);
  }
  net.time_step_s = h;
  return net;
}

}  // namespace deform
