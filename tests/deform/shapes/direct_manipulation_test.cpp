#include "deform/shapes/direct_manipulation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include <glm/gtc/quaternion.hpp>

#include "deform/patch/patch_fit.h"
#include "support/bound_tube.h"
#include "support/patch_meshes.h"
#include "support/tolerances.h"

namespace {

using deform::BSplineSurface;
using deform::ManipulationOptions;
using deform::PointConstraint;
using testsupport::kConstraintRelTol;
using testsupport::kRotationTol;

// A bumpy 9 x 10 bicubic patch (the paper's elbow grid size).
BSplineSurface MakeSurface(int m = 9, int n = 10) {
  std::vector<glm::dvec3> control;
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < n; ++j) {
      control.emplace_back(i, 0.8 * j, 0.3 * std::sin(i) * std::cos(0.7 * j));
    }
  }
  auto s = BSplineSurface::CreateUniform(m, n, std::move(control));
  EXPECT_TRUE(s.ok());
  return *s;
}

BSplineSurface Moved(const BSplineSurface& s, std::span<const glm::dvec3> delta) {
  BSplineSurface out = s;
  for (size_t c = 0; c < delta.size(); ++c) out.mutable_control()[c] += delta[c];
  return out;
}

double SumSq(std::span<const glm::dvec3> v) {
  double s = 0.0;
  for (const glm::dvec3& x : v) s += glm::dot(x, x);
  return s;
}

// Roughness: sum over the whole grid of |4-neighbour Laplacian of dq|^2.
double Roughness(std::span<const glm::dvec3> dq, int m, int n) {
  double sum = 0.0;
  for (int i = 1; i + 1 < m; ++i) {
    for (int j = 1; j + 1 < n; ++j) {
      const auto at = [&](int a, int b) { return dq[static_cast<size_t>(a * n + b)]; };
      const glm::dvec3 lap =
          4.0 * at(i, j) - at(i - 1, j) - at(i + 1, j) - at(i, j - 1) - at(i, j + 1);
      sum += glm::dot(lap, lap);
    }
  }
  return sum;
}

TEST(DirectManipulation, SinglePointClosedFormIsExactAndMinimal) {
  const BSplineSurface s = MakeSurface();
  const double tol = kConstraintRelTol * s.ControlDiagonal();
  const double u = 0.37, v = 0.61;
  const glm::dvec3 delta(0.1, -0.2, 0.35);
  const std::vector<glm::dvec3> dq = deform::MoveSurfacePointMinNorm(s, u, v, delta);
  const std::vector<double> a = deform::SurfacePointWeights(s, u, v);
  glm::dvec3 moved(0.0);
  for (size_t c = 0; c < a.size(); ++c) moved += a[c] * dq[c];
  EXPECT_LT(glm::length(moved - delta), tol);  // sum a_ij dq_ij = D
  EXPECT_LT(glm::length(Moved(s, dq).Evaluate(u, v) - (s.Evaluate(u, v) + delta)), tol);
  // Any other solution dq + n (sum a n = 0) is at least as long.
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  const double aa = [&] {
    double t = 0;
    for (double x : a) t += x * x;
    return t;
  }();
  for (int t = 0; t < 20; ++t) {
    std::vector<glm::dvec3> z(a.size());
    glm::dvec3 az(0.0);
    for (size_t c = 0; c < a.size(); ++c) {
      z[c] = glm::dvec3(g(rng), g(rng), g(rng));
      az += a[c] * z[c];
    }
    std::vector<glm::dvec3> other(a.size());
    for (size_t c = 0; c < a.size(); ++c) other[c] = dq[c] + 0.1 * (z[c] - (a[c] / aa) * az);
    glm::dvec3 check(0.0);
    for (size_t c = 0; c < a.size(); ++c) check += a[c] * other[c];
    EXPECT_LT(glm::length(check - delta), tol);
    EXPECT_GT(SumSq(other), SumSq(dq));
  }
  // The general solver with every point free gives the same change.
  ManipulationOptions all;
  all.free_mask.assign(a.size(), 1);
  const PointConstraint k{.u = u, .v = v, .target = s.Evaluate(u, v) + delta};
  auto r = deform::SolvePointConstraints(s, std::span(&k, 1), all);
  ASSERT_TRUE(r.ok());
  for (size_t c = 0; c < a.size(); ++c) EXPECT_LT(glm::length(r->delta[c] - dq[c]), tol);
}

TEST(DirectManipulation, SeveralConstraintsMetExactlyAndBoundaryRingUntouched) {
  const BSplineSurface s = MakeSurface();
  const std::vector<PointConstraint> cons = {
      {.u = 0.3, .v = 0.4, .target = s.Evaluate(0.3, 0.4) + glm::dvec3(0, 0, 0.5)},
      {.u = 0.6, .v = 0.5, .target = s.Evaluate(0.6, 0.5) + glm::dvec3(0.1, 0, 0.3)},
      {.u = 0.5, .v = 0.8, .target = s.Evaluate(0.5, 0.8) + glm::dvec3(0, -0.2, 0)},
      {.u = 0.7, .v = 0.2, .target = s.Evaluate(0.7, 0.2)}};
  for (auto spread : {deform::SpreadMode::kPseudoInverse, deform::SpreadMode::kLaplacian}) {
    ManipulationOptions opt;
    opt.spread = spread;
    auto r = deform::SolvePointConstraints(s, cons, opt);
    ASSERT_TRUE(r.ok()) << r.error().ToString();
    EXPECT_TRUE(r->unsatisfied.empty());
    EXPECT_EQ(r->lambda, 0.0);
    EXPECT_GE(r->condition, 1.0);
    const BSplineSurface after = Moved(s, r->delta);
    for (const PointConstraint& k : cons) {
      EXPECT_LT(glm::length(after.Evaluate(k.u, k.v) - k.target),
                kConstraintRelTol * s.ControlDiagonal());
    }
    for (int i = 0; i < s.num_u(); ++i) {
      for (int j = 0; j < s.num_v(); ++j) {
        if (i == 0 || j == 0 || i + 1 == s.num_u() || j + 1 == s.num_v()) {
          EXPECT_EQ(r->delta[static_cast<size_t>(i * s.num_v() + j)], glm::dvec3(0.0));
        }
      }
    }
  }
}

TEST(DirectManipulation, UserMaskRespected) {
  const BSplineSurface s = MakeSurface();
  ManipulationOptions opt;
  opt.free_mask.assign(90, 0);
  for (int i = 3; i < 6; ++i) {
    for (int j = 3; j < 7; ++j) opt.free_mask[static_cast<size_t>(i * 10 + j)] = 1;
  }
  const PointConstraint k{
      .u = 0.5, .v = 0.5, .target = s.Evaluate(0.5, 0.5) + glm::dvec3(0, 0, 0.4)};
  auto r = deform::SolvePointConstraints(s, std::span(&k, 1), opt);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r->unsatisfied.empty());
  for (size_t c = 0; c < 90; ++c) {
    if (opt.free_mask[c] == 0) {
      EXPECT_EQ(r->delta[c], glm::dvec3(0.0));
    }
  }
}

TEST(DirectManipulation, LaplacianSpreadIsSmootherThanPseudoInverse) {
  const BSplineSurface s = MakeSurface();
  const PointConstraint k{
      .u = 0.45, .v = 0.55, .target = s.Evaluate(0.45, 0.55) + glm::dvec3(0, 0, 0.5)};
  ManipulationOptions pinv, smooth;
  smooth.spread = deform::SpreadMode::kLaplacian;
  smooth.laplacian_mu = 4.0;
  auto a = deform::SolvePointConstraints(s, std::span(&k, 1), pinv);
  auto b = deform::SolvePointConstraints(s, std::span(&k, 1), smooth);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_TRUE(a->unsatisfied.empty() && b->unsatisfied.empty());
  const double ra = Roughness(a->delta, 9, 10), rb = Roughness(b->delta, 9, 10);
  EXPECT_LT(rb, 0.5 * ra) << "pseudo-inverse " << ra << ", laplacian " << rb;
  // The smooth change reaches more control points (it spreads).
  auto count = [](std::span<const glm::dvec3> d) {
    int n = 0;
    for (const glm::dvec3& x : d) n += glm::length(x) > 1e-6 ? 1 : 0;
    return n;
  };
  EXPECT_GT(count(b->delta), count(a->delta));
}

TEST(DirectManipulation, KeepHereLimitsTheSpread) {
  const BSplineSurface s = MakeSurface();
  const std::vector<PointConstraint> cons = {
      {.u = 0.4, .v = 0.5, .target = s.Evaluate(0.4, 0.5) + glm::dvec3(0, 0, 0.5)},
      deform::KeepHere(s, 0.55, 0.5)};
  auto r = deform::SolvePointConstraints(s, cons);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r->unsatisfied.empty());
  const BSplineSurface after = Moved(s, r->delta);
  EXPECT_LT(glm::length(after.Evaluate(0.55, 0.5) - s.Evaluate(0.55, 0.5)),
            kConstraintRelTol * s.ControlDiagonal());
}

TEST(DirectManipulation, TangentRowsConstrainDerivatives) {
  const BSplineSurface s = MakeSurface();
  const double u = 0.5, v = 0.45;
  const deform::SurfaceDerivs d0 = s.EvaluateDerivs(u, v, 1);
  const std::vector<PointConstraint> cons = {
      {.u = u, .v = v, .target = d0.s + glm::dvec3(0, 0, 0.3)},
      {.u = u, .v = v, .target = d0.su, .kind = deform::ConstraintKind::kTangentU},
      {.u = u,
       .v = v,
       .target = d0.sv + glm::dvec3(0, 0, 1.0),
       .kind = deform::ConstraintKind::kTangentV}};
  auto r = deform::SolvePointConstraints(s, cons);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r->unsatisfied.empty());
  const deform::SurfaceDerivs d1 = Moved(s, r->delta).EvaluateDerivs(u, v, 1);
  const double tol = kConstraintRelTol * s.ControlDiagonal();
  EXPECT_LT(glm::length(d1.s - cons[0].target), tol);
  EXPECT_LT(glm::length(d1.su - cons[1].target), tol);
  EXPECT_LT(glm::length(d1.sv - cons[2].target), tol);
}

TEST(DirectManipulation, CoincidentConflictingConstraintsAreReported) {
  const BSplineSurface s = MakeSurface();
  const glm::dvec3 p = s.Evaluate(0.5, 0.5);
  const std::vector<PointConstraint> cons = {
      {.u = 0.5, .v = 0.5, .target = p + glm::dvec3(0, 0, 0.2)},
      {.u = 0.5, .v = 0.5, .target = p - glm::dvec3(0, 0, 0.2)}};
  for (auto solve : {deform::ConstraintSolve::kRegularized, deform::ConstraintSolve::kSvd}) {
    ManipulationOptions opt;
    opt.solve = solve;
    auto r = deform::SolvePointConstraints(s, cons, opt);
    ASSERT_TRUE(r.ok());
    EXPECT_GT(r->condition, 1e10);
    EXPECT_EQ(r->unsatisfied.size(), 2u);
    if (solve == deform::ConstraintSolve::kRegularized) {
      EXPECT_GT(r->lambda, 0.0);
    }
    // The compromise: the point stays (nearly) where it was.
    EXPECT_LT(glm::length(Moved(s, r->delta).Evaluate(0.5, 0.5) - p), 1e-6);
  }
}

TEST(DirectManipulation, RejectsBadInput) {
  const BSplineSurface s = MakeSurface();
  EXPECT_FALSE(deform::SolvePointConstraints(s, {}).ok());
  const PointConstraint outside{.u = 1.5, .v = 0.5};
  EXPECT_FALSE(deform::SolvePointConstraints(s, std::span(&outside, 1)).ok());
  const PointConstraint ok{.u = 0.5, .v = 0.5, .target = s.Evaluate(0.5, 0.5)};
  ManipulationOptions wrong_size;
  wrong_size.free_mask.assign(10, 1);
  EXPECT_FALSE(deform::SolvePointConstraints(s, std::span(&ok, 1), wrong_size).ok());
  ManipulationOptions none;
  none.free_mask.assign(90, 0);
  auto r = deform::SolvePointConstraints(s, std::span(&ok, 1), none);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("free control point"), std::string::npos);
}

// Binds a tube (the fixture of patch_binding_test) to a 9 x 10 patch, edits
// vertices and rebuilds them with the per-frame job.
TEST(DirectManipulation, VertexEditMovesRebuiltVertexByTheRequestedVector) {
  const std::optional<testsupport::BoundTube> fixture = testsupport::MakeBoundTube();
  ASSERT_TRUE(fixture.has_value());
  const BSplineSurface& surface = fixture->surface;
  const deform::PatchBinding& b = fixture->binding;

  auto rebuild = [&](const BSplineSurface& s) {
    const std::vector<glm::vec3> control = deform::ControlPointsAsFloat(s);
    std::vector<glm::vec3> out(b.size());
    const deform::PatchRebuildJob job{.control = control, .bindings = b.view(), .positions = out};
    EXPECT_TRUE(job.Run().ok());
    return out;
  };
  auto record = [&](int vertex) {
    for (size_t r = 0; r < b.size(); ++r) {
      if (b.vertex[r] == vertex) return r;
    }
    ADD_FAILURE() << "vertex " << vertex << " not bound";
    return size_t{0};
  };
  const std::vector<glm::vec3> before = rebuild(surface);
  const int v1 = 20 * 30 + 15, v2 = 12 * 30 + 8;  // interior vertices of the 40 x 30 grid
  const glm::dvec3 d1(0.05, 0.1, 0.2), d2(0.0, -0.15, 0.05);
  for (int which = 0; which < 2; ++which) {
    std::vector<deform::VertexEdit> edits;
    auto e1 = deform::MakeVertexEdit(b, v1, d1);
    ASSERT_TRUE(e1.ok());
    edits.push_back(*e1);
    if (which == 1) edits.push_back(*deform::MakeVertexEdit(b, v2, d2));
    auto r = deform::MoveBoundVertices(surface, edits);
    ASSERT_TRUE(r.ok()) << r.error().ToString();
    EXPECT_TRUE(r->unsatisfied.empty());
    const BSplineSurface after = Moved(surface, r->delta);
    const std::vector<glm::vec3> now = rebuild(after);
    const double tol = testsupport::kVertexEditRelTol * surface.ControlDiagonal();
    const size_t r1 = record(v1);
    EXPECT_LT(glm::length(glm::dvec3(now[r1] - before[r1]) - d1), tol);
    if (which == 1) {
      const size_t r2 = record(v2);
      EXPECT_LT(glm::length(glm::dvec3(now[r2] - before[r2]) - d2), tol);
    }
  }
  EXPECT_FALSE(deform::MakeVertexEdit(b, -3, d1).ok());
}

glm::mat4 Rigid(const glm::quat& q, const glm::vec3& t) {
  glm::mat4 m = glm::mat4_cast(q);
  m[3] = glm::vec4(t, 1.0f);
  return m;
}

TEST(ControlFrames, PolarRotationOfPureRotationIsItself) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  for (int t = 0; t < 20; ++t) {
    const glm::dquat q = glm::normalize(glm::dquat(uni(rng), uni(rng), uni(rng), uni(rng)));
    const glm::dmat3 r = glm::mat3_cast(q);
    const glm::dmat3 p = deform::PolarRotation(r);
    for (int c = 0; c < 3; ++c) EXPECT_LT(glm::length(p[c] - r[c]), 1e-12);
    // R times a symmetric positive definite stretch: the rotation comes back.
    const glm::dmat3 stretch(1.3, 0.2, 0.0, 0.2, 0.8, 0.1, 0.0, 0.1, 1.1);
    const glm::dmat3 ps = deform::PolarRotation(r * stretch);
    for (int c = 0; c < 3; ++c) EXPECT_LT(glm::length(ps[c] - r[c]), 1e-10);
  }
  // A reflection still gives a proper rotation (the SVD fallback).
  const glm::dmat3 mirror(-1.0, 0, 0, 0, 1.0, 0, 0, 0, 1.0);
  EXPECT_NEAR(glm::determinant(deform::PolarRotation(mirror)), 1.0, 1e-12);
}

TEST(ControlFrames, SsdAndDqsRotationsOfEqualInfluences) {
  const glm::quat q = glm::angleAxis(0.7f, glm::normalize(glm::vec3(1, 2, 3)));
  const std::vector<glm::mat4> palette = {Rigid(q, glm::vec3(1, 2, 3)),
                                          Rigid(q, glm::vec3(-1, 0, 2))};
  std::vector<deform::DualQuat> dq(2);
  ASSERT_TRUE(deform::BuildDualQuatPalette(palette, dq).ok());
  const std::vector<std::uint16_t> joints = {0, 1, 1, 0};
  const std::vector<float> weights = {0.3f, 0.7f, 1.0f, 0.0f};
  std::vector<glm::quat> ssd(2), dqs(2);
  ASSERT_TRUE(deform::SsdControlRotations(palette, 2, joints, weights, ssd).ok());
  ASSERT_TRUE(deform::DqsControlRotations(dq, 2, joints, weights, dqs).ok());
  for (int c = 0; c < 2; ++c) {
    EXPECT_NEAR(std::abs(glm::dot(ssd[static_cast<size_t>(c)], q)), 1.0f, kRotationTol);
    EXPECT_NEAR(std::abs(glm::dot(dqs[static_cast<size_t>(c)], q)), 1.0f, kRotationTol);
  }
  EXPECT_EQ(deform::SsdControlRotations(palette, 2, joints, std::span(weights).first(3), ssd).code,
            base::JobStatus::kSizeMismatch);
}

// Examples stored in the local frames stay attached when the whole body turns:
// a rigid rotation R0 of the pose rotates the applied displacement by R0.
TEST(ControlFrames, StoredExampleFollowsARigidRotationOfTheBody) {
  const std::vector<glm::mat4> palette = {
      Rigid(glm::angleAxis(0.4f, glm::vec3(0, 0, 1)), glm::vec3(0, 1, 0)),
      Rigid(glm::angleAxis(-0.9f, glm::vec3(1, 0, 0)), glm::vec3(0.5, 0, 1))};
  const int count = 6;
  std::vector<std::uint16_t> joints;
  std::vector<float> weights;
  for (int c = 0; c < count; ++c) {
    const float w = static_cast<float>(c) / static_cast<float>(count - 1);
    joints.insert(joints.end(), {0, 1});
    weights.insert(weights.end(), {1.0f - w, w});
  }
  std::vector<glm::dvec3> world(count);
  std::vector<glm::vec3> global(count), zero(count, glm::vec3(0.0f)), example(count);
  for (int c = 0; c < count; ++c) {
    world[static_cast<size_t>(c)] = glm::dvec3(0.1 * c, 0.2, -0.05 * c);
    global[static_cast<size_t>(c)] = glm::vec3(static_cast<float>(c), 1.0f, 2.0f);
  }
  std::vector<glm::quat> frames(count);
  ASSERT_TRUE(deform::SsdControlRotations(palette, 2, joints, weights, frames).ok());
  ASSERT_TRUE(deform::StoreExampleDisplacement(frames, zero, world, example).ok());
  // At the example pose, applying the stored example gives back the edit.
  std::vector<glm::vec3> q(count);
  ASSERT_TRUE((deform::PoseSpaceApplyJob{
      .global = global, .rotations = frames, .displacement = example, .control = q}
                   .Run()
                   .ok()));
  for (int c = 0; c < count; ++c) {
    EXPECT_LT(glm::length(glm::dvec3(q[static_cast<size_t>(c)] - global[static_cast<size_t>(c)]) -
                          world[static_cast<size_t>(c)]),
              1e-5);
  }
  // The whole body rotated by r0: the displacement turns with it.
  const glm::quat r0 = glm::angleAxis(1.9f, glm::normalize(glm::vec3(0.3f, 1.0f, -0.2f)));
  std::vector<glm::mat4> turned = palette;
  for (glm::mat4& m : turned) m = Rigid(r0, glm::vec3(3, 0, 1)) * m;
  ASSERT_TRUE(deform::SsdControlRotations(turned, 2, joints, weights, frames).ok());
  ASSERT_TRUE((deform::PoseSpaceApplyJob{
      .global = global, .rotations = frames, .displacement = example, .control = q}
                   .Run()
                   .ok()));
  for (int c = 0; c < count; ++c) {
    const glm::vec3 expected = r0 * glm::vec3(world[static_cast<size_t>(c)]);
    EXPECT_LT(glm::length(q[static_cast<size_t>(c)] - global[static_cast<size_t>(c)] - expected),
              1e-5f);
  }
}

// Q = G + A dS in SSE lanes, four control points at a time, is glm's
// G + q * dS bit for bit (and G where dS is exactly zero, whatever A holds
// there), for every count (whole groups and tails) and in place.
TEST(PoseSpaceApplyJob, GivesGlmsBitsForEveryCountAndInPlace) {
  std::mt19937 rng(53);
  std::uniform_real_distribution<float> uni(-2.0f, 2.0f);
  for (std::size_t count = 0; count <= 13; ++count) {
    std::vector<glm::vec3> global(count), ds(count), q(count);
    std::vector<glm::quat> a(count);
    for (std::size_t c = 0; c < count; ++c) {
      global[c] = glm::vec3(uni(rng), uni(rng), uni(rng));
      ds[c] = c % 3 == 1 ? glm::vec3(0.0f) : glm::vec3(uni(rng), uni(rng), uni(rng));
      a[c] = glm::normalize(glm::quat(uni(rng), uni(rng), uni(rng), uni(rng)));
      if (c % 3 == 1 && c % 2 == 0) a[c] = glm::quat(NAN, NAN, NAN, NAN);  // never read
    }
    if (count > 5) ds[5] = glm::vec3(0.0f, -0.0f, 1e-30f);  // not zero: turned
    ASSERT_TRUE((deform::PoseSpaceApplyJob{.global = global, .rotations = a, .displacement = ds,
                                           .control = q}
                     .Run()));
    for (std::size_t c = 0; c < count; ++c) {
      const glm::vec3 expected = ds[c] == glm::vec3(0.0f) ? global[c] : global[c] + a[c] * ds[c];
      EXPECT_EQ(std::memcmp(&q[c], &expected, sizeof(expected)), 0) << count << " " << c;
    }
    std::vector<glm::vec3> in_place = global;
    ASSERT_TRUE((deform::PoseSpaceApplyJob{.global = in_place, .rotations = a,
                                           .displacement = ds, .control = in_place}
                     .Run()));
    EXPECT_EQ(in_place.size(), q.size());
    for (std::size_t c = 0; c < count; ++c) {  // memcmp of empty vectors would pass null
      EXPECT_EQ(std::memcmp(&in_place[c], &q[c], sizeof(glm::vec3)), 0) << count << " " << c;
    }
  }
}

}  // namespace
