// The elastic layer's conversions between modes and points
// (deform/elastic/internal/mass_spring_modal.h): the AVX and SSE2 paths give the bits of
// the scalar sums they document (e_a = sum_k U[a, k] eta_k, k ascending; eta_k =
// sum_a U[a, k] e_a, a ascending), for every lane grouping.

#include <cmath>
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "deform/elastic/internal/mass_spring_modal.h"
#include "deform/elastic/mass_spring.h"
#include "support/mass_spring_networks.h"

namespace {

TEST(ModalConversion, BothPathsGiveTheScalarSums) {
  // 4x4: 4 modes (one 8-lane group), 5x5: 9 (one 16-lane group), 7x7: 25 (one
  // 32-lane group), 8x8: 36 (a 32-lane group and an 8-lane one), 9x9: 49 (32,
  // 16 and 8 lanes), 16x16: 196.
  for (const auto& [rows, cols] : {std::pair{4, 4}, {5, 5}, {7, 7}, {8, 8}, {9, 9}, {16, 16}}) {
    SCOPED_TRACE(testing::Message() << rows << "x" << cols);
    const deform::MassSpringNetwork net = testsupport::CurvedGridNetwork(rows, cols);
    const std::size_t n = static_cast<std::size_t>(net.num_free);
    const std::size_t stride = static_cast<std::size_t>(net.mode_stride);
    std::vector<float> in(3 * stride, 0.0f);  // padding lanes 0
    for (std::size_t c = 0; c < 3; ++c) {
      for (std::size_t k = 0; k < n; ++k) {
        in[c * stride + k] = std::sin(0.9f * static_cast<float>(k) + 1.7f * static_cast<float>(c)) *
                             (1.0f + 0.01f * static_cast<float>(k));
      }
    }
    // Scalar references in the documented order.
    std::vector<float> to_points(3 * stride, 0.0f), to_modes(3 * stride, 0.0f);
    for (std::size_t c = 0; c < 3; ++c) {
      for (std::size_t a = 0; a < n; ++a) {
        float e = 0.0f, eta = 0.0f;
        for (std::size_t k = 0; k < n; ++k) {
          e = e + net.modes[a * n + k] * in[c * stride + k];    // U[a, k] eta_k
          eta = eta + net.modes[k * n + a] * in[c * stride + k];  // U[k, a] e_k
        }
        to_points[c * stride + a] = e;
        to_modes[c * stride + a] = eta;
      }
    }
    for (const bool avx : {true, false}) {
      SCOPED_TRACE(avx ? "AVX where the CPU has it" : "SSE2");
      std::vector<float> points(3 * stride, -1.0f), modes(3 * stride, -1.0f);
      deform::internal::ModalToPoints(net, in.data(), points.data(), avx);
      deform::internal::PointsToModal(net, in.data(), modes.data(), avx);
      for (std::size_t c = 0; c < 3; ++c) {
        for (std::size_t a = 0; a < n; ++a) {
          const std::size_t at = c * stride + a;
          ASSERT_EQ(std::memcmp(&points[at], &to_points[at], sizeof(float)), 0) << c << " " << a;
          ASSERT_EQ(std::memcmp(&modes[at], &to_modes[at], sizeof(float)), 0) << c << " " << a;
        }
      }
    }
  }
}

}  // namespace
