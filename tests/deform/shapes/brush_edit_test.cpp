#include "deform/shapes/brush_edit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "support/tolerances.h"

namespace {

using deform::BrushFalloff;
using deform::BrushStroke;
using deform::BSplineSurface;
using testsupport::kDoubleTol;

// A flat 9 x 10 bicubic patch over [0,8] x [0,9] (the paper's elbow grid size).
BSplineSurface Flat(int m = 9, int n = 10) {
  std::vector<glm::dvec3> control;
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < n; ++j) control.emplace_back(i, j, 0.0);
  }
  auto s = BSplineSurface::CreateUniform(m, n, std::move(control));
  EXPECT_TRUE(s.ok());
  return *s;
}

// How far s(u,v) moves under a control-point change.
glm::dvec3 MovedBy(const BSplineSurface& s, std::span<const glm::dvec3> delta, double u, double v) {
  const std::vector<double> a = deform::SurfacePointWeights(s, u, v);
  glm::dvec3 sum(0.0);
  for (std::size_t c = 0; c < a.size(); ++c) sum += a[c] * delta[c];
  return sum;
}

TEST(BrushFalloff, AnalyticValues) {
  EXPECT_NEAR(BrushFalloff(0.0), 1.0, kDoubleTol);
  EXPECT_NEAR(BrushFalloff(1.0), 0.0, kDoubleTol);
  EXPECT_NEAR(BrushFalloff(0.5), 0.0625 * 3.0, kDoubleTol);  // (1/2)^4 (4/2 + 1)
  EXPECT_EQ(BrushFalloff(1.5), 0.0);
  // Flat at the centre and at the rim: first differences vanish to second order.
  const double h = 1e-4;
  EXPECT_NEAR((BrushFalloff(h) - BrushFalloff(0.0)) / h, 0.0, 1e-6 * 20.0 + 20.0 * h);
  EXPECT_LT(BrushFalloff(1.0 - h), 1e-12);  // (h^4)(5): C2 at the rim
  // Decreasing on (0, 1).
  for (double x = 0.0; x < 1.0; x += 0.05) EXPECT_GT(BrushFalloff(x), BrushFalloff(x + 0.05));
}

TEST(BrushStrokes, CentreMovesByTheRequestedMove) {
  const BSplineSurface s = Flat();
  const BrushStroke stroke{.u = 0.5, .v = 0.45, .radius = 0.35, .delta = {0.0, 0.0, 1.0}};
  auto r = deform::SolveBrushStrokes(s, std::span(&stroke, 1));
  ASSERT_TRUE(r.ok()) << r.error().message;
  const glm::dvec3 moved = MovedBy(s, r->delta, 0.5, 0.45);
  EXPECT_LT(glm::length(moved - stroke.delta), 1e-4 * s.ControlDiagonal());
  EXPECT_TRUE(r->unsatisfied.empty());
  // The border ring stays put.
  for (int j = 0; j < s.num_v(); ++j) EXPECT_EQ(r->delta[static_cast<std::size_t>(j)], glm::dvec3(0.0));
}

// The surface follows the falloff: half-way out it has risen by about
// phi(0.5) = 0.1875 of the move, beyond the radius by nearly nothing; on a
// 16 x 16 grid the control change is far smoother than a minimum-norm edit's
// (whose bump is one basis function wide).
TEST(BrushStrokes, FollowsTheFalloffAndIsSmootherThanAMinNormEdit) {
  const BSplineSurface s = Flat(16, 16);
  const BrushStroke stroke{.u = 0.5, .v = 0.5, .radius = 0.45, .delta = {0.0, 0.0, 1.0}};
  auto brush = deform::SolveBrushStrokes(s, std::span(&stroke, 1));
  ASSERT_TRUE(brush.ok());
  const deform::PointConstraint pin{.u = 0.5, .v = 0.5, .target = s.Evaluate(0.5, 0.5) + stroke.delta};
  auto min_norm = deform::SolvePointConstraints(s, std::span(&pin, 1));
  ASSERT_TRUE(min_norm.ok());

  const double half = MovedBy(s, brush->delta, 0.5 + 0.225, 0.5).z;
  const double far = MovedBy(s, brush->delta, 0.5 + 0.48, 0.5).z;
  std::printf("brush rise at r/2: %.4f (phi 0.1875), beyond r: %.4f\n", half, far);
  EXPECT_NEAR(half, BrushFalloff(0.5), 0.03);
  EXPECT_LT(std::abs(far), 0.02);

  const BrushStroke wide{.u = 0.5, .v = 0.5, .radius = 0.6, .delta = stroke.delta};
  auto wide_brush = deform::SolveBrushStrokes(s, std::span(&wide, 1));
  ASSERT_TRUE(wide_brush.ok());
  const double rough_wide = deform::MaxSecondDifference(wide_brush->delta, s.num_u(), s.num_v());
  const double rough_brush = deform::MaxSecondDifference(brush->delta, s.num_u(), s.num_v());
  const double rough_min = deform::MaxSecondDifference(min_norm->delta, s.num_u(), s.num_v());
  std::printf("max second difference of dQ: brush r 0.45 %.4f, r 0.6 %.4f, min-norm %.4f\n",
              rough_brush, rough_wide, rough_min);
  EXPECT_LT(rough_brush, 0.4 * rough_min);
  EXPECT_LT(rough_wide, 0.3 * rough_min);
}

TEST(BrushStrokes, ZeroRadiusIsAHardPointOnly) {
  const BSplineSurface s = Flat();
  const BrushStroke stroke{.u = 0.5, .v = 0.5, .radius = 0.0, .delta = {0.3, 0.0, 0.0}};
  auto r = deform::SolveBrushStrokes(s, std::span(&stroke, 1));
  ASSERT_TRUE(r.ok());
  EXPECT_LT(glm::length(MovedBy(s, r->delta, 0.5, 0.5) - stroke.delta), 1e-4 * s.ControlDiagonal());
}

TEST(BrushStrokes, RejectsBadInput) {
  const BSplineSurface s = Flat();
  EXPECT_FALSE(deform::SolveBrushStrokes(s, {}).ok());
  BrushStroke bad{.u = 1.5, .v = 0.5, .radius = 0.2, .delta = {0, 0, 1}};
  EXPECT_FALSE(deform::SolveBrushStrokes(s, std::span(&bad, 1)).ok());
  bad = {.u = 0.5, .v = 0.5, .radius = -0.1, .delta = {0, 0, 1}};
  EXPECT_FALSE(deform::SolveBrushStrokes(s, std::span(&bad, 1)).ok());
  bad = {.u = 0.5, .v = 0.5, .radius = 0.2, .delta = {0, NAN, 1}};
  EXPECT_FALSE(deform::SolveBrushStrokes(s, std::span(&bad, 1)).ok());
  const BrushStroke ok{.u = 0.5, .v = 0.5, .radius = 0.2, .delta = {0, 0, 1}};
  EXPECT_FALSE(deform::SolveBrushStrokes(s, std::span(&ok, 1), {.free_mask = {1, 0}}).ok());
  EXPECT_FALSE(deform::SolveBrushStrokes(
                   s, std::span(&ok, 1),
                   {.free_mask = std::vector<std::uint8_t>(static_cast<std::size_t>(90), 0)})
                   .ok());
}

}  // namespace
