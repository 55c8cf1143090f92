#include "deform/patch/patch_binding.h"

#include <cstring>
#include <random>

#include <gtest/gtest.h>

#include "deform/patch/patch_fit.h"
#include "deform/simd.h"
#include "support/patch_meshes.h"
#include "support/tolerances.h"

namespace {

using base::JobStatus;
using deform::BSplineSurface;
using deform::PatchRebuildJob;
using testsupport::kProjectionTol;
using testsupport::kRebuildRelTol;

// A fitted patch with its parametrization.
struct Fitted {
  deform::RegionParametrization param;
  BSplineSurface surface;
};

Fitted FitTube(const deform::Mesh& tube, int m, int n) {
  const std::vector<int> region = testsupport::AllVertices(tube);
  auto param = deform::ParametrizeCylinder(tube.positions, region, tube.triangles, glm::dvec3(0.0),
                                           glm::dvec3(0, 0, 1));
  EXPECT_TRUE(param.ok());
  auto samples = deform::SampleRegion(tube.positions, tube.triangles, *param,
                                      deform::UniformParameters(2 * m), deform::UniformParameters(2 * n));
  EXPECT_TRUE(samples.ok());
  auto fit = deform::FitSurface(*samples, {.num_u = m, .num_v = n});
  EXPECT_TRUE(fit.ok());
  deform::OrientNormal(fit->surface, *param);
  return {*param, fit->surface};
}

Fitted FitPlane(const deform::Mesh& mesh, std::span<const int> region, int m, int n) {
  auto param = deform::ParametrizePlane(mesh.positions, region, mesh.triangles);
  EXPECT_TRUE(param.ok());
  auto samples = deform::SampleRegion(mesh.positions, mesh.triangles, *param,
                                      deform::UniformParameters(2 * m), deform::UniformParameters(2 * n));
  EXPECT_TRUE(samples.ok());
  auto fit = deform::FitSurface(*samples, {.num_u = m, .num_v = n});
  EXPECT_TRUE(fit.ok());
  deform::OrientNormal(fit->surface, *param);
  return {*param, fit->surface};
}

std::vector<glm::vec3> Rebuild(const deform::PatchBinding& b, std::span<const glm::vec3> control,
                               std::vector<glm::vec3>* normals = nullptr, bool simd = true) {
  std::vector<glm::vec3> out(b.size());
  if (normals != nullptr) normals->resize(b.size());
  const PatchRebuildJob job{
      .control = control,
      .bindings = b.view(),
      .positions = out,
      .normals = normals != nullptr ? std::span<glm::vec3>(*normals) : std::span<glm::vec3>()};
  // simd = false: the process capped to the baseline, so the scalar loop runs.
  deform::SetSimdCap(simd ? deform::SimdLevel::kAvx : deform::SimdLevel::kBaseline);
  EXPECT_TRUE(job.Run().ok());
  deform::SetSimdCap(deform::SimdLevel::kAvx);
  return out;
}

TEST(PatchProjection, RecoversKnownOffsets) {
  const deform::Mesh tube = testsupport::MakeTube(40, 30, 2.0f, 180.0f, 5.0f);
  const Fitted f = FitTube(tube, 9, 6);
  const deform::ProjectionGrid grid = deform::MakeProjectionGrid(f.surface, 4);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uni(0.05, 0.95), off(-0.3, 0.3);
  for (int t = 0; t < 200; ++t) {
    const double u = uni(rng), v = uni(rng), d = off(rng);
    const glm::dvec3 p = f.surface.Evaluate(u, v) + d * f.surface.Normal(u, v);
    const deform::Projection pr = deform::Project(f.surface, grid, p);
    EXPECT_FALSE(pr.on_border);
    EXPECT_NEAR(pr.u, u, kProjectionTol);
    EXPECT_NEAR(pr.v, v, kProjectionTol);
    EXPECT_NEAR(pr.d, d, kProjectionTol);
  }
}

TEST(PatchBinding, RestRebuildOfTubeRegion) {
  const deform::Mesh tube = testsupport::MakeTube(46, 25, 1.5f, 220.0f, 6.0f);
  const Fitted f = FitTube(tube, 9, 10);
  auto bound = deform::BindPatch(f.surface, tube.positions, f.param.region, f.param.uv);
  ASSERT_TRUE(bound.ok()) << bound.error().ToString();
  const deform::BindingReport& rep = bound->report;
  EXPECT_GT(rep.bound, tube.num_vertices() * 9 / 10);
  EXPECT_LT(rep.max_rest_error, kRebuildRelTol * rep.patch_diagonal);
  // Independent check: rebuild and compare with the mesh.
  const std::vector<glm::vec3> control = deform::ControlPointsAsFloat(f.surface);
  std::vector<glm::vec3> normals;
  const std::vector<glm::vec3> out = Rebuild(bound->binding, control, &normals);
  for (size_t i = 0; i < out.size(); ++i) {
    const glm::vec3 p = tube.positions[static_cast<size_t>(bound->binding.vertex[i])];
    EXPECT_LT(glm::length(out[i] - p), kRebuildRelTol * rep.patch_diagonal);
    EXPECT_GT(glm::dot(normals[i], glm::normalize(glm::vec3(p.x, p.y, 0.0f))), 0.99f);
  }
  // Every bound or reported vertex is accounted for exactly once.
  EXPECT_EQ(rep.bound + static_cast<int>(rep.border_vertices.size() + rep.far_vertices.size()),
            tube.num_vertices());
}

TEST(PatchBinding, RestRebuildOfSphereCap) {
  const deform::Mesh cap = testsupport::MakeSphereCap(25, 3.0f, 1.6f);
  const std::vector<int> region = testsupport::AllVertices(cap);
  const Fitted f = FitPlane(cap, region, 7, 7);
  auto bound = deform::BindPatch(f.surface, cap.positions, region, f.param.uv);
  ASSERT_TRUE(bound.ok());
  EXPECT_GT(bound->report.bound, cap.num_vertices() * 9 / 10);
  EXPECT_LT(bound->report.max_rest_error, kRebuildRelTol * bound->report.patch_diagonal);
  const std::vector<glm::vec3> out = Rebuild(bound->binding, deform::ControlPointsAsFloat(f.surface));
  for (size_t i = 0; i < out.size(); ++i) {
    const glm::vec3 p = cap.positions[static_cast<size_t>(bound->binding.vertex[i])];
    EXPECT_LT(glm::length(out[i] - p), kRebuildRelTol * bound->report.patch_diagonal);
  }
}

TEST(PatchBinding, ReportsBorderAndFarVertices) {
  // Fit a patch to the middle of a sheet, then bind the whole sheet plus a
  // vertex lifted far above it.
  deform::Mesh sheet = testsupport::MakeBumpySheet(30, 20, 10.0f, 0.2f);
  std::vector<int> middle;
  for (int i = 8; i < 22; ++i) {
    for (int j = 5; j < 15; ++j) middle.push_back(i * 20 + j);
  }
  const Fitted f = FitPlane(sheet, middle, 6, 6);
  const int far_vertex = sheet.num_vertices();
  sheet.positions.push_back(glm::vec3(f.surface.Evaluate(0.5, 0.5) + 4.0 * f.surface.Normal(0.5, 0.5)));
  const std::vector<int> all = testsupport::AllVertices(sheet);
  auto bound = deform::BindPatch(f.surface, sheet.positions, all, {});
  ASSERT_TRUE(bound.ok());
  const deform::BindingReport& rep = bound->report;
  EXPECT_EQ(rep.far_vertices, std::vector<int>{far_vertex});
  // Vertices outside the middle block project onto the border: a corner one must be among them.
  EXPECT_NE(std::find(rep.border_vertices.begin(), rep.border_vertices.end(), 0), rep.border_vertices.end());
  EXPECT_GT(rep.border_vertices.size(), static_cast<size_t>(sheet.num_vertices() / 2));
  EXPECT_LT(rep.max_rest_error, kRebuildRelTol * rep.patch_diagonal);
}

TEST(PatchRebuildJob, MovedControlPointsMatchTheSurface) {
  const deform::Mesh cap = testsupport::MakeSphereCap(15, 3.0f, 1.6f);
  const std::vector<int> region = testsupport::AllVertices(cap);
  const Fitted f = FitPlane(cap, region, 5, 6);
  auto bound = deform::BindPatch(f.surface, cap.positions, region, f.param.uv);
  ASSERT_TRUE(bound.ok());
  // Deform the control grid; the rebuild must be s'(u,v) + d n'(u,v) of the
  // deformed surface, evaluated here in double with BSplineSurface.
  BSplineSurface moved = f.surface;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  for (glm::dvec3& q : moved.mutable_control()) q += glm::dvec3(jitter(rng), jitter(rng), jitter(rng));
  const std::vector<glm::vec3> control = deform::ControlPointsAsFloat(moved);
  std::vector<glm::vec3> normals;
  const std::vector<glm::vec3> out = Rebuild(bound->binding, control, &normals);
  const deform::PatchBinding& b = bound->binding;
  for (size_t i = 0; i < out.size(); ++i) {
    const glm::dvec3 n = moved.Normal(b.u[i], b.v[i]);
    const glm::dvec3 expected = moved.Evaluate(b.u[i], b.v[i]) + static_cast<double>(b.d[i]) * n;
    EXPECT_LT(glm::length(glm::dvec3(out[i]) - expected), 1e-4);
    EXPECT_LT(glm::length(glm::dvec3(normals[i]) - n), 1e-4);
  }
}

TEST(PatchRebuildJob, SplitRangesAreBitIdentical) {
  const deform::Mesh tube = testsupport::MakeTube(40, 31, 1.5f, 200.0f, 6.0f);
  const Fitted f = FitTube(tube, 7, 7);
  auto bound = deform::BindPatch(f.surface, tube.positions, f.param.region, f.param.uv);
  ASSERT_TRUE(bound.ok());
  BSplineSurface moved = f.surface;
  for (glm::dvec3& q : moved.mutable_control()) q = q * 1.1 + glm::dvec3(0.1, -0.2, 0.3);
  const std::vector<glm::vec3> control = deform::ControlPointsAsFloat(moved);
  std::vector<glm::vec3> whole_n;
  const std::vector<glm::vec3> whole = Rebuild(bound->binding, control, &whole_n);
  std::vector<glm::vec3> scalar_n;
  const std::vector<glm::vec3> scalar = Rebuild(bound->binding, control, &scalar_n, false);
  ASSERT_EQ(std::memcmp(whole.data(), scalar.data(), whole.size() * sizeof(glm::vec3)), 0);
  ASSERT_EQ(std::memcmp(whole_n.data(), scalar_n.data(), whole.size() * sizeof(glm::vec3)), 0);
  // Odd split points so batches of 8 fall differently.
  const size_t n = bound->binding.size();
  const size_t cuts[] = {0, 3, 77, n / 2 + 5, n - 9, n};
  std::vector<glm::vec3> split(n), split_n(n);
  for (int c = 0; c + 1 < 6; ++c) {
    const PatchRebuildJob job{
        .control = control,
        .bindings = bound->binding.view().Slice(cuts[c], cuts[c + 1]),
        .positions = std::span<glm::vec3>(split).subspan(cuts[c], cuts[c + 1] - cuts[c]),
        .normals = std::span<glm::vec3>(split_n).subspan(cuts[c], cuts[c + 1] - cuts[c])};
    ASSERT_TRUE(job.Run().ok());
  }
  EXPECT_EQ(std::memcmp(whole.data(), split.data(), n * sizeof(glm::vec3)), 0);
  EXPECT_EQ(std::memcmp(whole_n.data(), split_n.data(), n * sizeof(glm::vec3)), 0);
}

TEST(PatchBinding, RefreshAfterKnotRefinementKeepsTheRebuild) {
  const deform::Mesh tube = testsupport::MakeTube(30, 20, 1.5f, 200.0f, 6.0f);
  const Fitted f = FitTube(tube, 6, 5);
  auto bound = deform::BindPatch(f.surface, tube.positions, f.param.region, f.param.uv);
  ASSERT_TRUE(bound.ok());
  const std::vector<glm::vec3> before = Rebuild(bound->binding, deform::ControlPointsAsFloat(f.surface));
  BSplineSurface refined = f.surface;
  ASSERT_TRUE(refined.RefineU(refined.SpanMidpointsU()).ok());
  ASSERT_TRUE(refined.InsertKnotV(0.3).ok());
  auto fresh = deform::RefreshBinding(bound->binding, refined);
  ASSERT_TRUE(fresh.ok());
  ASSERT_EQ(fresh->size(), bound->binding.size());
  EXPECT_EQ(fresh->num_u, refined.num_u());
  const std::vector<glm::vec3> after = Rebuild(*fresh, deform::ControlPointsAsFloat(refined));
  // Records may be reordered by span: match them by vertex.
  std::vector<glm::vec3> by_vertex(tube.positions.size());
  for (size_t i = 0; i < before.size(); ++i) by_vertex[bound->binding.vertex[i]] = before[i];
  for (size_t i = 0; i < after.size(); ++i) {
    EXPECT_LT(glm::length(after[i] - by_vertex[fresh->vertex[i]]),
              kRebuildRelTol * bound->report.patch_diagonal);
  }
}

TEST(PatchRebuildJob, Validity) {
  const deform::Mesh cap = testsupport::MakeSphereCap(10, 3.0f, 1.5f);
  const std::vector<int> region = testsupport::AllVertices(cap);
  const Fitted f = FitPlane(cap, region, 5, 5);
  auto bound = deform::BindPatch(f.surface, cap.positions, region, f.param.uv);
  ASSERT_TRUE(bound.ok());
  const std::vector<glm::vec3> control = deform::ControlPointsAsFloat(f.surface);
  std::vector<glm::vec3> out(bound->binding.size()), small(1);
  const PatchRebuildJob ok{.control = control, .bindings = bound->binding.view(), .positions = out};
  EXPECT_EQ(ok.Validate().code, JobStatus::kOk);
  PatchRebuildJob job = ok;
  job.control = std::span<const glm::vec3>(control).first(control.size() - 1);
  EXPECT_EQ(job.Validate().code, JobStatus::kSizeMismatch);
  job = ok;
  job.positions = small;
  EXPECT_EQ(job.Validate().code, JobStatus::kSizeMismatch);
  EXPECT_EQ(job.Run().code, JobStatus::kSizeMismatch);
  job = ok;
  job.normals = small;
  EXPECT_EQ(job.Validate().code, JobStatus::kSizeMismatch);
  job = ok;
  job.bindings.span_table_u = {};
  EXPECT_EQ(job.Validate().code, JobStatus::kSizeMismatch);
  job = ok;
  job.bindings.sigma = 0.5f;
  EXPECT_EQ(job.Validate().code, JobStatus::kOutOfRange);
  job = ok;
  job.bindings.num_u = 3;
  EXPECT_EQ(job.Validate().code, JobStatus::kOutOfRange);
  job = ok;
  job.bindings.nu1 = job.bindings.nu1.first(1);
  EXPECT_EQ(job.Validate().code, JobStatus::kSizeMismatch);
  // An empty slice is valid and writes nothing.
  job = ok;
  job.bindings = ok.bindings.Slice(5, 5);
  job.positions = {};
  EXPECT_TRUE(job.Run().ok());
}

TEST(PatchBinding, RejectsBadInput) {
  const deform::Mesh cap = testsupport::MakeSphereCap(10, 3.0f, 1.5f);
  const std::vector<int> region = testsupport::AllVertices(cap);
  const Fitted f = FitPlane(cap, region, 5, 5);
  const std::vector<int> bad = {0, 1000};
  auto r = deform::BindPatch(f.surface, cap.positions, bad, {});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, base::ErrorCode::kInvalidArgument);
  const std::vector<glm::dvec2> uv(3);
  EXPECT_FALSE(deform::BindPatch(f.surface, cap.positions, region, uv).ok());
  auto quad = BSplineSurface::CreateUniform(4, 4, std::vector<glm::dvec3>(16), 2);
  ASSERT_TRUE(quad.ok());
  EXPECT_EQ(deform::BindPatch(*quad, cap.positions, region, {}).error().code,
            base::ErrorCode::kUnsupported);
  EXPECT_EQ(deform::PatchBinding::kStoredBytesPerVertex, 42);
}

}  // namespace
