#include "deform/patch/bspline.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "support/tolerances.h"

namespace {

using deform::BSplineSurface;
using testsupport::kFiniteDiffTol;
using testsupport::kKnotInsertionTol;
using testsupport::kSplineTol;

// Independent reference: the recursive Cox-de Boor definition (0/0 := 0),
// with the right end closed so that u = 1 gives the last basis function.
double NaiveBasis(const std::vector<double>& U, int i, int p, double u, int num_control) {
  if (p == 0) {
    if (U[i] <= u && u < U[i + 1]) return 1.0;
    // u = 1 belongs to the last non-empty span.
    if (u == U.back() && i == num_control - 1) return 1.0;
    return 0.0;
  }
  double a = 0.0, b = 0.0;
  if (U[i + p] - U[i] != 0.0) a = (u - U[i]) / (U[i + p] - U[i]) * NaiveBasis(U, i, p - 1, u, num_control);
  if (U[i + p + 1] - U[i + 1] != 0.0) {
    b = (U[i + p + 1] - u) / (U[i + p + 1] - U[i + 1]) * NaiveBasis(U, i + 1, p - 1, u, num_control);
  }
  return a + b;
}

std::vector<double> NonUniformKnots() {
  // 7 control points, cubic, uneven interior knots and one double knot.
  return {0, 0, 0, 0, 0.1, 0.45, 0.45, 1, 1, 1, 1};
}

BSplineSurface RandomSurface(int m, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  std::vector<glm::dvec3> q;
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < n; ++j) q.emplace_back(i + jitter(rng), j + jitter(rng), jitter(rng) * 3);
  }
  std::vector<double> ku = deform::MakeClampedUniformKnots(m, 3);
  ku[4] = 0.8 * ku[4] + 0.03;  // make u non-uniform
  auto s = BSplineSurface::Create(3, 3, ku, deform::MakeClampedUniformKnots(n, 3), m, n, q);
  EXPECT_TRUE(s.ok()) << s.error().ToString();
  return *s;
}

TEST(BSplineBasis, PartitionOfUnityAndNonNegative) {
  const std::vector<double> U = NonUniformKnots();
  for (int k = 0; k <= 1000; ++k) {
    const double u = k / 1000.0;
    const int span = deform::FindSpan(U, 7, 3, u);
    ASSERT_GE(span, 3);
    ASSERT_LE(span, 6);
    double n[4];
    deform::BasisFuns(U, span, 3, u, n);
    double sum = 0.0;
    for (double x : n) {
      EXPECT_GE(x, 0.0);
      sum += x;
    }
    EXPECT_NEAR(sum, 1.0, kSplineTol) << "u=" << u;
  }
}

TEST(BSplineBasis, AgreesWithNaiveCoxDeBoor) {
  const std::vector<double> U = NonUniformKnots();
  for (int k = 0; k <= 200; ++k) {
    const double u = k / 200.0;
    const int span = deform::FindSpan(U, 7, 3, u);
    double n[4];
    deform::BasisFuns(U, span, 3, u, n);
    for (int i = 0; i < 7; ++i) {
      const double expected = NaiveBasis(U, i, 3, u, 7);
      const double got = (i >= span - 3 && i <= span) ? n[i - span + 3] : 0.0;
      EXPECT_NEAR(got, expected, kSplineTol) << "i=" << i << " u=" << u;
    }
  }
}

TEST(BSplineBasis, DerivativesMatchFiniteDifferences) {
  const std::vector<double> U = NonUniformKnots();
  const double h = 1e-6;
  for (int k = 1; k < 100; ++k) {
    const double u = k / 100.0 + 0.0013;  // stay off the knots
    const int span = deform::FindSpan(U, 7, 3, u);
    const deform::BasisDerivs d = deform::BasisFunsDerivs(U, span, 3, u, 2);
    const deform::BasisDerivs dp = deform::BasisFunsDerivs(U, span, 3, u + h, 2);
    const deform::BasisDerivs dm = deform::BasisFunsDerivs(U, span, 3, u - h, 2);
    for (int a = 0; a < 4; ++a) {
      EXPECT_NEAR(d.ders[1][a], (dp.ders[0][a] - dm.ders[0][a]) / (2 * h), kFiniteDiffTol);
      EXPECT_NEAR(d.ders[2][a], (dp.ders[1][a] - dm.ders[1][a]) / (2 * h), kFiniteDiffTol * 10);
    }
  }
}

TEST(BSplineBasis, GrevilleOfUniformKnots) {
  const std::vector<double> xi = deform::GrevilleAbscissae(deform::MakeClampedUniformKnots(5, 3), 5, 3);
  const double expected[] = {0.0, 1.0 / 6.0, 0.5, 5.0 / 6.0, 1.0};
  for (int i = 0; i < 5; ++i) EXPECT_NEAR(xi[i], expected[i], kSplineTol);
}

TEST(BSplineBasis, RejectsBadKnots) {
  EXPECT_FALSE(deform::CheckKnots(std::vector<double>{0, 0, 0, 0, 1, 1, 1}, 4, 3, "u").ok());
  EXPECT_FALSE(deform::CheckKnots(std::vector<double>{0, 0, 0, 0.5, 1, 1, 1, 1}, 4, 3, "u").ok());
  EXPECT_FALSE(deform::CheckKnots(std::vector<double>{0, 0, 0, 0, 0.6, 0.4, 1, 1, 1, 1}, 6, 3, "u").ok());
  EXPECT_TRUE(deform::CheckKnots(NonUniformKnots(), 7, 3, "u").ok());
}

TEST(BSplineSurface, BilinearGridIsThePlane) {
  // Control points on a plane placed at the Greville abscissae reproduce the
  // linear map (linear precision): s(u,v) = o + u*a + v*b.
  const int m = 6, n = 5;
  const std::vector<double> ku = deform::MakeClampedUniformKnots(m, 3);
  const std::vector<double> kv = deform::MakeClampedUniformKnots(n, 3);
  const auto xu = deform::GrevilleAbscissae(ku, m, 3);
  const auto xv = deform::GrevilleAbscissae(kv, n, 3);
  const glm::dvec3 o(1, 2, 3), a(4, 0, 1), b(0, 3, -1);
  std::vector<glm::dvec3> q;
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < n; ++j) q.push_back(o + xu[i] * a + xv[j] * b);
  }
  auto s = BSplineSurface::Create(3, 3, ku, kv, m, n, q);
  ASSERT_TRUE(s.ok());
  const glm::dvec3 normal = glm::normalize(glm::cross(a, b));
  for (int k = 0; k <= 20; ++k) {
    for (int l = 0; l <= 20; ++l) {
      const double u = k / 20.0, v = l / 20.0;
      const glm::dvec3 p = s->Evaluate(u, v);
      EXPECT_LT(glm::length(p - (o + u * a + v * b)), kSplineTol * 100);
      EXPECT_LT(glm::length(s->Normal(u, v) - normal), kSplineTol * 100);
    }
  }
}

TEST(BSplineSurface, PartialDerivativesMatchFiniteDifferences) {
  const BSplineSurface s = RandomSurface(7, 6, 3);
  const double h = 1e-6;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uni(0.01, 0.99);
  for (int t = 0; t < 200; ++t) {
    const double u = uni(rng), v = uni(rng);
    const deform::SurfaceDerivs d = s.EvaluateDerivs(u, v, 2);
    EXPECT_LT(glm::length(d.s - s.Evaluate(u, v)), kSplineTol * 100);
    const glm::dvec3 su = (s.Evaluate(u + h, v) - s.Evaluate(u - h, v)) / (2 * h);
    const glm::dvec3 sv = (s.Evaluate(u, v + h) - s.Evaluate(u, v - h)) / (2 * h);
    EXPECT_LT(glm::length(d.su - su), kFiniteDiffTol * 10);
    EXPECT_LT(glm::length(d.sv - sv), kFiniteDiffTol * 10);
    const auto dp = s.EvaluateDerivs(u + h, v, 1), dm = s.EvaluateDerivs(u - h, v, 1);
    const auto ep = s.EvaluateDerivs(u, v + h, 1), em = s.EvaluateDerivs(u, v - h, 1);
    EXPECT_LT(glm::length(d.suu - (dp.su - dm.su) / (2 * h)), kFiniteDiffTol * 100);
    EXPECT_LT(glm::length(d.suv - (dp.sv - dm.sv) / (2 * h)), kFiniteDiffTol * 100);
    EXPECT_LT(glm::length(d.svv - (ep.sv - em.sv) / (2 * h)), kFiniteDiffTol * 100);
  }
}

TEST(BSplineSurface, NormalSignFollowsSigma) {
  BSplineSurface s = RandomSurface(5, 5, 5);
  const glm::dvec3 n = s.Normal(0.3, 0.6);
  EXPECT_NEAR(glm::length(n), 1.0, kSplineTol * 100);
  s.set_sigma(-1);
  EXPECT_LT(glm::length(s.Normal(0.3, 0.6) + n), kSplineTol);
}

TEST(BSplineSurface, KnotInsertionKeepsTheSurface) {
  const BSplineSurface before = RandomSurface(7, 6, 7);
  BSplineSurface after = before;
  auto mu = after.InsertKnotU(0.37);
  ASSERT_TRUE(mu.ok());
  auto mv = after.InsertKnotV(0.81);
  ASSERT_TRUE(mv.ok());
  EXPECT_EQ(after.num_u(), 8);
  EXPECT_EQ(after.num_v(), 7);
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  for (int t = 0; t < 500; ++t) {
    const double u = uni(rng), v = uni(rng);
    EXPECT_LT(glm::length(after.Evaluate(u, v) - before.Evaluate(u, v)), kKnotInsertionTol);
  }
  // The returned maps carry the control grid: Q' = Tu Q Tv^T, rows convex.
  for (int i = 0; i < after.num_u(); ++i) {
    double row = 0.0;
    for (int c = 0; c < before.num_u(); ++c) row += mu->at(i, c);
    EXPECT_NEAR(row, 1.0, kSplineTol);
    for (int j = 0; j < after.num_v(); ++j) {
      glm::dvec3 q(0.0);
      for (int a = 0; a < before.num_u(); ++a) {
        for (int b = 0; b < before.num_v(); ++b) q += mu->at(i, a) * mv->at(j, b) * before.control(a, b);
      }
      EXPECT_LT(glm::length(q - after.control(i, j)), kSplineTol * 100);
    }
  }
}

TEST(BSplineSurface, MidpointRefinementKeepsTheSurface) {
  const BSplineSurface before = RandomSurface(5, 5, 9);
  BSplineSurface after = before;
  const std::vector<double> mu = after.SpanMidpointsU();
  const std::vector<double> mv = after.SpanMidpointsV();
  auto tu = after.RefineU(mu);
  auto tv = after.RefineV(mv);
  ASSERT_TRUE(tu.ok() && tv.ok());
  EXPECT_EQ(after.num_u(), 5 + static_cast<int>(mu.size()));
  EXPECT_EQ(tu->num_new, after.num_u());
  EXPECT_EQ(tu->num_old, 5);
  for (int k = 0; k <= 30; ++k) {
    for (int l = 0; l <= 30; ++l) {
      const double u = k / 30.0, v = l / 30.0;
      EXPECT_LT(glm::length(after.Evaluate(u, v) - before.Evaluate(u, v)), kKnotInsertionTol);
    }
  }
}

TEST(BSplineSurface, InsertionBeyondDegreeIsRefused) {
  BSplineSurface s = RandomSurface(5, 5, 1);
  ASSERT_TRUE(s.InsertKnotU(0.25).ok());
  ASSERT_TRUE(s.InsertKnotU(0.25).ok());
  ASSERT_TRUE(s.InsertKnotU(0.25).ok());
  EXPECT_FALSE(s.InsertKnotU(0.25).ok());
  EXPECT_FALSE(s.InsertKnotV(1.0).ok());
  EXPECT_FALSE(s.InsertKnotV(std::nan("")).ok());
}

}  // namespace
