#include "app/bench_table1.h"

#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "deform/shapes/direct_manipulation.h"
#include "deform/elastic/mass_spring.h"
#include "deform/mesh.h"
#include "deform/patch/patch_binding.h"
#include "deform/patch/patch_fit.h"
#include "deform/shapes/pose_space.h"

namespace app::bench {
namespace {

using ::bench::Clock;
using ::bench::Rates;

// Part of a cylinder about z (200 degrees, radius 4, height 20): the region.
deform::Mesh Tube(int around, int along) {
  deform::Mesh m;
  for (int i = 0; i < around; ++i) {
    const float phi = glm::radians(-90.0f + 200.0f * static_cast<float>(i) / static_cast<float>(around - 1));
    for (int j = 0; j < along; ++j) {
      const float h = 20.0f * static_cast<float>(j) / static_cast<float>(along - 1);
      m.positions.emplace_back(4.0f * std::cos(phi), 4.0f * std::sin(phi), h);
    }
  }
  for (int i = 0; i + 1 < around; ++i) {
    for (int j = 0; j + 1 < along; ++j) {
      const auto a = static_cast<unsigned>(i * along + j), b = static_cast<unsigned>((i + 1) * along + j);
      m.triangles.emplace_back(a, b, b + 1);
      m.triangles.emplace_back(a, b + 1, a + 1);
    }
  }
  return m;
}

struct BoundPatch {
  deform::BSplineSurface surface;
  deform::PatchBinding binding;
};

base::Result<BoundPatch> FitAndBind(const PatchCase& c) {
  const deform::Mesh mesh = Tube(c.around, c.along);
  std::vector<int> region(mesh.positions.size());
  for (std::size_t i = 0; i < region.size(); ++i) region[i] = static_cast<int>(i);
  auto param = deform::ParametrizeCylinder(mesh.positions, region, mesh.triangles, glm::dvec3(0.0),
                                           glm::dvec3(0, 0, 1));
  if (!param.ok()) return param.error();
  auto samples = deform::SampleRegion(mesh.positions, mesh.triangles, *param,
                                      deform::UniformParameters(c.m + 4),
                                      deform::UniformParameters(c.n + 4));
  if (!samples.ok()) return samples.error();
  auto fit = deform::FitSurface(*samples, {.num_u = c.m, .num_v = c.n});
  if (!fit.ok()) return fit.error();
  BoundPatch p;
  p.surface = std::move(fit->surface);
  deform::OrientNormal(p.surface, *param);
  auto bound = deform::BindPatch(p.surface, mesh.positions, param->region, param->uv);
  if (!bound.ok()) return bound.error();
  p.binding = std::move(bound->binding);
  return p;
}

// 5 example poses (6 features: two rotation vectors) with random displacements.
base::Result<deform::RbfModel> FitRbf(int num_control) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
  std::vector<deform::PoseExample> examples;
  for (int e = 0; e < 5; ++e) {
    deform::PoseExample ex;
    ex.name = "example" + std::to_string(e);
    for (int d = 0; d < 6; ++d) ex.features.push_back(uni(rng));
    for (int k = 0; k < num_control; ++k) ex.displacement.emplace_back(uni(rng), uni(rng), uni(rng));
    examples.push_back(std::move(ex));
  }
  return deform::RbfPoseSpace::Fit(examples, 6, num_control);
}

}  // namespace

base::Result<Table1Row> MeasurePatch(const PatchCase& c, const Budget& b) {
  base::Result<BoundPatch> p = FitAndBind(c);
  if (!p.ok()) return p.error();
  const auto count = static_cast<std::size_t>(c.m * c.n);
  std::vector<glm::vec3> control = deform::ControlPointsAsFloat(p->surface);
  for (glm::vec3& q : control) q *= 1.01f;  // a deformed frame
  Table1Row row;
  row.patch = &c;
  row.bound = static_cast<int>(p->binding.size());
  const std::string key = c.name;

  std::vector<glm::vec3> displacement(count), out(count);
  std::function<void()> update;
  deform::RbfModel rbf;
  deform::MassSpringNetwork net;
  deform::MassSpringState state;
  std::vector<float> features = {0.1f, 0.2f, -0.3f, 0.4f, 0.0f, 0.1f};
  const std::vector<glm::quat> frames(count, glm::angleAxis(0.3f, glm::vec3(0, 0, 1)));
  const std::function<deform::DrivingFrame(double)> drive = [](double t) {
    const auto s = static_cast<float>(std::sin(7.0 * t)), co = static_cast<float>(std::cos(7.0 * t));
    return deform::DrivingFrame{glm::angleAxis(0.2f * s, glm::vec3(0, 1, 0)),
                                glm::vec3(300.0f * s, 100.0f * co, 0), glm::vec3(0, 1.4f * co, 0),
                                glm::vec3(0, -9.8f * s, 0)};
  };
  int frame = 0;
  bool failed = false;
  if (c.simulated) {
    auto built = deform::BuildMassSpringNetwork(
        {.rows = c.m, .cols = c.n, .rest_points = control, .max_angular_speed_rad_s = 2.0f});
    if (!built.ok()) return built.error();
    net = std::move(*built);
    state.Resize(net);
    // One 30 fps output frame of simulation (8 RK4 steps at h = 1/240 s).
    update = [&] {
      failed |= !deform::MassSpringStepJob{.network = &net, .state = &state,
                                           .time_s = frame++ / 30.0, .driving = &drive,
                                           .displacements = displacement}
                     .Run()
                     .ok();
    };
  } else {
    auto fitted = FitRbf(c.m * c.n);
    if (!fitted.ok()) return fitted.error();
    rbf = std::move(*fitted);
    // dS(theta) from the RBF, then Q = G + A dS.
    update = [&] {
      features[0] += 1e-7f;
      failed |= !deform::PoseSpaceJob{.model = &rbf, .features = features, .displacement = displacement}
                     .Run()
                     .ok();
      failed |= !deform::PoseSpaceApplyJob{.global = control, .rotations = frames,
                                           .displacement = displacement, .control = out}
                     .Run()
                     .ok();
    };
  }
  std::vector<glm::vec3> positions(p->binding.size());
  const deform::PatchRebuildJob rebuild_job{.control = control, .bindings = p->binding.view(),
                                            .positions = positions};
  const auto rebuild = [&] { failed |= !rebuild_job.Run().ok(); };

  row.update = {key + "_update_per_s", "1/s", Clock::kCpu, Rates(b, Clock::kCpu, 1.0, update),
                c.paper_update, "paper", c.simulated ? "mass-spring, one 30 fps frame" : "RBF dS + Q"};
  row.rebuild = {key + "_rebuild_per_s", "1/s", Clock::kCpu, Rates(b, Clock::kCpu, 1.0, rebuild),
                 c.paper_rebuild, "paper", std::to_string(row.bound) + " bound vertices"};
  row.total = {key + "_total_per_s", "1/s", Clock::kCpu, {}, c.paper_total, "paper",
               "one update + one rebuild"};
  for (std::size_t r = 0; r < row.update.runs.size(); ++r) {
    row.total.runs.push_back(1.0 / (1.0 / row.update.runs[r] + 1.0 / row.rebuild.runs[r]));
  }
  if (failed) {
    return base::MakeError(base::ErrorCode::kInternal, {"bench", 0, 0, {}},
                           std::string("a job refused to run in the ") + c.name + " workload");
  }
  return row;
}
}  // namespace app::bench
