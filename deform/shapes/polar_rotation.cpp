#include "deform/shapes/polar_rotation.h"

#include <cmath>

namespace deform {
namespace {

double Norm2(const glm::dmat3& m) {
  return glm::dot(m[0], m[0]) + glm::dot(m[1], m[1]) + glm::dot(m[2], m[2]);
}

}  // namespace

bool PolarRotationNewton(const glm::dmat3& m, glm::dmat3& rotation, int* iterations) {
  glm::dmat3 x = m;
  for (int it = 1; it <= kPolarNewtonMaxIterations; ++it) {
    glm::dmat3 cof;
    cof[0] = glm::cross(x[1], x[2]);                         // cof(X) = det(X) X^-T
    cof[1] = glm::cross(x[2], x[0]);
    cof[2] = glm::cross(x[0], x[1]);
    const double det = glm::dot(x[0], cof[0]);
    // The first test also rejects NaN; later iterates of a matrix that passed
    // have det >= 1 up to round-off (the iteration raises singular values).
    if (!(det > kPolarNewtonMinDet)) return false;
    const double inv_det = 1.0 / det;
    double g = 1.0;
    // Scaling pays only while the iterate is far from orthogonal (it costs two
    // square roots and a division on the critical path of an iteration): a
    // blend of rotations with det in [1/8, 8] converges as fast without it.
    if (det < kPolarNewtonScaleBelowDet || det > kPolarNewtonScaleAboveDet) {
      // |X^-1|_F = |cof|_F / det; g = sqrt(|X^-1|_F / |X|_F).
      g = std::sqrt(std::sqrt(Norm2(cof) / Norm2(x)) * inv_det);
    }
    const double a = 0.5 * g, b = 0.5 * inv_det / g;
    glm::dmat3 next;
    double step2 = 0.0;
    for (int c = 0; c < 3; ++c) {
      next[c] = a * x[c] + b * cof[c];                       // (g X + X^-T / g) / 2
      const glm::dvec3 d = next[c] - x[c];
      step2 += glm::dot(d, d);
    }
    x = next;
    if (step2 < kPolarNewtonStop * kPolarNewtonStop) {
      if (iterations != nullptr) *iterations = it;
      rotation = x;
      return true;
    }
  }
  return false;
}

}  // namespace deform
