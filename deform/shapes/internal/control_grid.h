#pragma once
// Shared by the brush (brush_edit.cpp) and the computed corrective examples
// (corrective_example.cpp): which control points are free and the
// second-difference smoothness term over the control grid, in Eigen triplets.
#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Sparse>

namespace deform::internal {

// #C entries: the unknown's index of each free control point, -1 if fixed.
// Empty mask: all but the boundary ring. Returns the count of free points.
inline int FreeIndex(int nu, int nv, const std::vector<std::uint8_t>& mask, std::vector<int>& index) {
  index.assign(static_cast<std::size_t>(nu) * static_cast<std::size_t>(nv), -1);
  int nf = 0;
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      const auto c = static_cast<std::size_t>(i * nv + j);
      const bool free = mask.empty() ? (i > 0 && i + 1 < nu && j > 0 && j + 1 < nv) : mask[c] != 0;
      if (free) index[c] = nf++;
    }
  }
  return nf;
}

// Adds mu L2^T L2, L2 = the second differences (1, -2, 1) of the control-grid
// change along u and along v; fixed points are zero values (their columns drop).
inline void AddSecondDifferences(int nu, int nv, const std::vector<int>& free_index, double mu,
                                 std::vector<Eigen::Triplet<double>>& entries) {
  auto add_stencil = [&](const std::array<int, 3>& idx) {
    const std::array<double, 3> c{1.0, -2.0, 1.0};
    for (std::size_t a = 0; a < 3; ++a) {
      const int fa = free_index[static_cast<std::size_t>(idx[a])];
      if (fa < 0) continue;
      for (std::size_t b = 0; b < 3; ++b) {
        const int fb = free_index[static_cast<std::size_t>(idx[b])];
        if (fb >= 0) entries.emplace_back(fa, fb, mu * c[a] * c[b]);
      }
    }
  };
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      if (i > 0 && i + 1 < nu) add_stencil({(i - 1) * nv + j, i * nv + j, (i + 1) * nv + j});
      if (j > 0 && j + 1 < nv) add_stencil({i * nv + j - 1, i * nv + j, i * nv + j + 1});
    }
  }
}

}  // namespace deform::internal
