#pragma once
// Small dense LU factorization with partial pivoting, in double, factored once
// and solved for many right-hand sides of 3D points. Used by the patch fit,
// whose systems are at most a few dozen unknowns (banded, but small enough
// that a dense solve costs microseconds).

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

namespace deform::internal {

// Factor() returns false on a (numerically) singular matrix: a pivot below
// 1e-13 of the largest entry.
class DenseLu {
 public:
  bool Factor(std::vector<double> a, int n) {
    a_ = std::move(a);
    n_ = n;
    piv_.resize(static_cast<size_t>(n));
    double scale = 0.0;
    for (double x : a_) scale = std::max(scale, std::abs(x));
    for (int k = 0; k < n; ++k) {
      int best = k;
      for (int r = k + 1; r < n; ++r) {
        if (std::abs(at(r, k)) > std::abs(at(best, k))) best = r;
      }
      if (!(std::abs(at(best, k)) > 1e-13 * scale)) return false;
      piv_[static_cast<size_t>(k)] = best;
      for (int c = 0; c < n; ++c) std::swap(at(k, c), at(best, c));
      for (int r = k + 1; r < n; ++r) {
        const double f = at(r, k) / at(k, k);
        at(r, k) = f;
        for (int c = k + 1; c < n; ++c) at(r, c) -= f * at(k, c);
      }
    }
    return true;
  }
  void Solve(std::vector<glm::dvec3>& b) const {
    for (int k = 0; k < n_; ++k) std::swap(b[static_cast<size_t>(k)], b[static_cast<size_t>(piv_[static_cast<size_t>(k)])]);
    for (int r = 0; r < n_; ++r) {
      for (int c = 0; c < r; ++c) b[static_cast<size_t>(r)] -= at(r, c) * b[static_cast<size_t>(c)];
    }
    for (int r = n_ - 1; r >= 0; --r) {
      for (int c = r + 1; c < n_; ++c) b[static_cast<size_t>(r)] -= at(r, c) * b[static_cast<size_t>(c)];
      b[static_cast<size_t>(r)] /= at(r, r);
    }
  }

 private:
  double& at(int r, int c) { return a_[static_cast<size_t>(r) * n_ + c]; }
  double at(int r, int c) const { return a_[static_cast<size_t>(r) * n_ + c]; }
  std::vector<double> a_;
  std::vector<int> piv_;
  int n_ = 0;
};

}  // namespace deform::internal
