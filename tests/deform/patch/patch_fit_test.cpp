#include "deform/patch/patch_fit.h"

#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "support/patch_meshes.h"
#include "support/tolerances.h"

namespace {

using base::ErrorCode;
using deform::FitOptions;
using deform::PatchSamples;
using testsupport::kDoubleTol;

PatchSamples RandomSamples(int s, int t, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  PatchSamples out;
  out.num_s = s;
  out.num_t = t;
  out.us = deform::UniformParameters(s);
  out.vs = deform::UniformParameters(t);
  for (int k = 0; k < s; ++k) {
    for (int l = 0; l < t; ++l) out.points.emplace_back(k + jitter(rng), l + jitter(rng), jitter(rng));
  }
  out.vertex.assign(out.points.size(), -1);
  return out;
}

TEST(PatchFit, InterpolatesExactlyWhenGridsMatch) {
  const PatchSamples samples = RandomSamples(6, 7, 1);
  auto fit = deform::FitSurface(samples, {.num_u = 6, .num_v = 7});
  ASSERT_TRUE(fit.ok()) << fit.error().ToString();
  EXPECT_TRUE(fit->interpolating);
  EXPECT_LT(fit->max_error, kDoubleTol);
  // Independent check of the reported error.
  for (int k = 0; k < 6; ++k) {
    for (int l = 0; l < 7; ++l) {
      EXPECT_LT(glm::length(fit->surface.Evaluate(samples.us[k], samples.vs[l]) - samples.points[k * 7 + l]),
                kDoubleTol);
    }
  }
}

TEST(PatchFit, ChordLengthInterpolationAlsoExact) {
  const PatchSamples samples = RandomSamples(5, 5, 4);
  auto fit = deform::FitSurface(samples, {.num_u = 5, .num_v = 5,
                                          .parameterization = deform::FitParameterization::kChordLength});
  ASSERT_TRUE(fit.ok());
  EXPECT_LT(fit->max_error, kDoubleTol);
  EXPECT_EQ(fit->ub.front(), 0.0);
  EXPECT_EQ(fit->ub.back(), 1.0);
}

TEST(PatchFit, LeastSquaresRecoversAKnownSpline) {
  const int s = 20, t = 17, m = 9, n = 7;
  // The least-squares knots depend only on the parameters: get them from a
  // first fit, build a random spline on them, sample it and fit again.
  const PatchSamples probe = RandomSamples(s, t, 2);
  auto first = deform::FitSurface(probe, {.num_u = m, .num_v = n});
  ASSERT_TRUE(first.ok());
  EXPECT_FALSE(first->interpolating);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  std::vector<glm::dvec3> q;
  for (int i = 0; i < m * n; ++i) q.emplace_back(uni(rng), uni(rng), uni(rng));
  auto known = deform::BSplineSurface::Create(3, 3, first->surface.knots_u(), first->surface.knots_v(), m, n, q);
  ASSERT_TRUE(known.ok());
  PatchSamples samples = probe;
  for (int k = 0; k < s; ++k) {
    for (int l = 0; l < t; ++l) samples.points[k * t + l] = known->Evaluate(samples.us[k], samples.vs[l]);
  }
  auto fit = deform::FitSurface(samples, {.num_u = m, .num_v = n});
  ASSERT_TRUE(fit.ok());
  EXPECT_LT(fit->max_error, kDoubleTol);
  for (size_t i = 0; i < q.size(); ++i) EXPECT_LT(glm::length(fit->surface.control()[i] - q[i]), 1e3 * kDoubleTol);
}

TEST(PatchFit, SmoothingStaysCloseOnSmoothData) {
  const deform::Mesh sheet = testsupport::MakeBumpySheet(30, 30, 10.0f, 0.5f);
  const std::vector<int> region = testsupport::AllVertices(sheet);
  auto param = deform::ParametrizePlane(sheet.positions, region, sheet.triangles);
  ASSERT_TRUE(param.ok());
  auto samples = deform::SampleRegion(sheet.positions, sheet.triangles, *param,
                                      deform::UniformParameters(16), deform::UniformParameters(16));
  ASSERT_TRUE(samples.ok());
  auto plain = deform::FitSurface(*samples, {.num_u = 8, .num_v = 8});
  auto smooth = deform::FitSurface(*samples, {.num_u = 8, .num_v = 8, .smoothing = 1e-3});
  ASSERT_TRUE(plain.ok() && smooth.ok());
  EXPECT_GE(smooth->rms_error, plain->rms_error);  // least squares is the minimum
  EXPECT_LT(smooth->max_error, 0.05);              // 0.5% of the sheet
}

TEST(PatchFit, PlanePatchOnBumpySheet) {
  const deform::Mesh sheet = testsupport::MakeBumpySheet(40, 30, 10.0f, 0.4f);
  const std::vector<int> region = testsupport::AllVertices(sheet);
  auto param = deform::ParametrizePlane(sheet.positions, region, sheet.triangles);
  ASSERT_TRUE(param.ok()) << param.error().ToString();
  EXPECT_GT(param->mean_normal.z, 0.99);
  EXPECT_EQ(param->region_triangles, 2 * 39 * 29);
  // The longer side is e1, so u runs along x; e2 = cross(e3, e1).
  EXPECT_GT(std::abs(param->axis_u.x), 0.99);
  auto samples = deform::SampleRegion(sheet.positions, sheet.triangles, *param,
                                      deform::UniformParameters(18), deform::UniformParameters(18));
  ASSERT_TRUE(samples.ok());
  EXPECT_TRUE(samples->warnings.empty());
  auto fit = deform::FitSurface(*samples, {.num_u = 9, .num_v = 10});
  ASSERT_TRUE(fit.ok());
  deform::OrientNormal(fit->surface, *param);
  EXPECT_LT(fit->max_error, 0.01 * 10.0);
  // Away from the samples the patch follows the analytic sheet.
  for (int k = 1; k < 10; ++k) {
    const glm::dvec3 p = fit->surface.Evaluate(k / 10.0, 0.37);
    const double x = p.x, y = p.y;
    const double z = 0.4 * std::sin(2 * std::numbers::pi * x / 10.0) * std::cos(std::numbers::pi * y / 10.0);
    EXPECT_NEAR(p.z, z, 0.02);
    EXPECT_GT(fit->surface.Normal(k / 10.0, 0.37).z, 0.5);
  }
}

TEST(PatchFit, CylinderPatchOnTube) {
  const deform::Mesh tube = testsupport::MakeTube(48, 30, 1.5f, 200.0f, 6.0f);
  const std::vector<int> region = testsupport::AllVertices(tube);
  auto param = deform::ParametrizeCylinder(tube.positions, region, tube.triangles, glm::dvec3(0.0),
                                           glm::dvec3(0, 0, 2));
  ASSERT_TRUE(param.ok()) << param.error().ToString();
  EXPECT_NEAR(param->angular_span_deg, 200.0, 1e-3);
  auto samples = deform::SampleRegion(tube.positions, tube.triangles, *param,
                                      deform::UniformParameters(14), deform::UniformParameters(10));
  ASSERT_TRUE(samples.ok());
  auto fit = deform::FitSurface(*samples, {.num_u = 9, .num_v = 6});
  ASSERT_TRUE(fit.ok());
  deform::OrientNormal(fit->surface, *param);
  EXPECT_EQ(fit->surface.sigma(), 1);  // cross(s_u, s_v) already points out
  EXPECT_LT(fit->max_error, 0.01);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  for (int t = 0; t < 100; ++t) {
    const double u = uni(rng), v = uni(rng);
    const glm::dvec3 p = fit->surface.Evaluate(u, v);
    EXPECT_NEAR(std::hypot(p.x, p.y), 1.5, 0.01);
    const glm::dvec3 n = fit->surface.Normal(u, v);
    EXPECT_GT(glm::dot(n, glm::normalize(glm::dvec3(p.x, p.y, 0.0))), 0.99);
  }
}

TEST(PatchFit, PlaneMapRejectsAFoldingRegion) {
  const deform::Mesh tube = testsupport::MakeTube(40, 6, 1.0f, 300.0f, 2.0f);
  auto param = deform::ParametrizePlane(tube.positions, testsupport::AllVertices(tube), tube.triangles);
  ASSERT_FALSE(param.ok());
  EXPECT_EQ(param.error().code, ErrorCode::kUnsupported);
  EXPECT_NE(param.error().message.find("fold"), std::string::npos);
}

TEST(PatchFit, CylinderMapRejectsAClosedTube) {
  const deform::Mesh tube = testsupport::MakeTube(40, 6, 1.0f, 350.0f, 2.0f);
  auto param = deform::ParametrizeCylinder(tube.positions, testsupport::AllVertices(tube),
                                           tube.triangles, glm::dvec3(0.0), glm::dvec3(0, 0, 1));
  ASSERT_FALSE(param.ok());
  EXPECT_EQ(param.error().code, ErrorCode::kUnsupported);
}

TEST(PatchFit, NearestVertexSamplingWarnsOnSharedVertices) {
  const deform::Mesh sheet = testsupport::MakeBumpySheet(4, 4, 1.0f, 0.0f);
  auto param = deform::ParametrizePlane(sheet.positions, testsupport::AllVertices(sheet), sheet.triangles);
  ASSERT_TRUE(param.ok());
  auto samples = deform::SampleRegion(sheet.positions, sheet.triangles, *param, deform::UniformParameters(6),
                                      deform::UniformParameters(6), deform::SampleMode::kNearestVertex);
  ASSERT_TRUE(samples.ok());
  EXPECT_FALSE(samples->warnings.empty());
  for (int idx : samples->vertex) EXPECT_GE(idx, 0);
  // Barycentric sampling of a flat sheet gives exact grid points instead.
  auto exact = deform::SampleRegion(sheet.positions, sheet.triangles, *param, deform::UniformParameters(6),
                                    deform::UniformParameters(6));
  ASSERT_TRUE(exact.ok());
  EXPECT_TRUE(exact->warnings.empty());
  for (int k = 0; k < 6; ++k) {
    for (int l = 0; l < 6; ++l) {
      const glm::dvec3 p = exact->points[k * 6 + l];
      EXPECT_NEAR(std::abs(p.z), 0.0, kDoubleTol);
    }
  }
}

TEST(PatchFit, NonUniformAndHandPickedSampling) {
  const deform::Mesh sheet = testsupport::MakeBumpySheet(12, 12, 2.0f, 0.1f);
  auto param = deform::ParametrizePlane(sheet.positions, testsupport::AllVertices(sheet), sheet.triangles);
  ASSERT_TRUE(param.ok());
  const std::vector<double> us = {0.0, 0.1, 0.3, 0.6, 0.8, 1.0};
  auto samples = deform::SampleRegion(sheet.positions, sheet.triangles, *param, us, us);
  ASSERT_TRUE(samples.ok());
  EXPECT_EQ(samples->us, us);
  EXPECT_TRUE(deform::FitSurface(*samples, {.num_u = 6, .num_v = 6}).ok());
  std::vector<int> picked;
  for (int i = 0; i < 12; i += 2) {
    for (int j = 0; j < 12; j += 3) picked.push_back(i * 12 + j);
  }
  auto hand = deform::SampleHandPicked(sheet.positions, picked, 6, 4);
  ASSERT_TRUE(hand.ok());
  EXPECT_EQ(hand->us.front(), 0.0);
  EXPECT_EQ(hand->us.back(), 1.0);
  for (size_t k = 1; k < hand->us.size(); ++k) EXPECT_GT(hand->us[k], hand->us[k - 1]);
  auto fit = deform::FitSurface(*hand, {.num_u = 6, .num_v = 4});
  ASSERT_TRUE(fit.ok());
  EXPECT_LT(fit->max_error, kDoubleTol);
}

TEST(PatchFit, LargerGridByRefiningASampleResolutionFit) {
  // The paper's 9x10 grid from 6x6 samples (3.4): interpolate at 6x6, then
  // insert knots; the surface, and so the fit error, stay the same.
  const PatchSamples samples = RandomSamples(6, 6, 8);
  auto fit = deform::FitSurface(samples, {.num_u = 6, .num_v = 6});
  ASSERT_TRUE(fit.ok());
  deform::BSplineSurface grid = fit->surface;
  const double extra_u[] = {0.2, 0.5, 0.8};
  const double extra_v[] = {0.15, 0.4, 0.6, 0.85};
  ASSERT_TRUE(grid.RefineU(extra_u).ok());
  ASSERT_TRUE(grid.RefineV(extra_v).ok());
  EXPECT_EQ(grid.num_u(), 9);
  EXPECT_EQ(grid.num_v(), 10);
  for (int k = 0; k < 6; ++k) {
    for (int l = 0; l < 6; ++l) {
      EXPECT_LT(glm::length(grid.Evaluate(samples.us[k], samples.vs[l]) - samples.points[k * 6 + l]),
                testsupport::kKnotInsertionTol);
    }
  }
}

TEST(PatchFit, RejectsBadInput) {
  const deform::Mesh sheet = testsupport::MakeBumpySheet(4, 4, 1.0f, 0.0f);
  const std::vector<int> bad_region = {0, 1, 99};
  auto param = deform::ParametrizePlane(sheet.positions, bad_region, sheet.triangles);
  ASSERT_FALSE(param.ok());
  EXPECT_EQ(param.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(param.error().message.find("99"), std::string::npos);
  auto fit = deform::FitSurface(RandomSamples(5, 5, 1), {.num_u = 6, .num_v = 5});
  ASSERT_FALSE(fit.ok());
  EXPECT_EQ(fit.error().code, ErrorCode::kInvalidArgument);
  auto good = deform::ParametrizePlane(sheet.positions, testsupport::AllVertices(sheet), sheet.triangles);
  ASSERT_TRUE(good.ok());
  const std::vector<double> decreasing = {0.0, 0.7, 0.5, 1.0};
  EXPECT_FALSE(deform::SampleRegion(sheet.positions, sheet.triangles, *good, decreasing, decreasing).ok());
}

}  // namespace
