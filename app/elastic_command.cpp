#include "app/elastic_command.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <vector>

#include "app/exit_code.h"
#include "app/motion_source.h"
#include "deform/elastic/mass_spring.h"
#include "mocap/kinematics.h"
#include "tools/synthetic.h"
#include "render/output/image_io.h"
#include "render/output/plot.h"

namespace app {
int RunElastic(const ElasticOptions& o) {
  mocap::Skeleton skel;
  mocap::Motion motion;
  float upm = o.units_per_metre;
  std::string source = "built-in jump";
  if (o.file.empty()) {
    skel = synthetic::MakeHumanoidSkeleton();
    synthetic::JumpOptions jump;
    jump.frame_time_s = 1.0 / 60.0;
    auto m = synthetic::MakeJumpMotion(skel, jump);
    if (!m.ok()) return ReportInternal(m.error());
    motion = std::move(m).value();
    if (upm <= 0.0f) upm = 100.0f;
  } else {
    MotionSourceOptions mo;
    mo.scale = o.scale;
    auto loaded = LoadMotionSource(o.file, mo);
    if (!loaded.ok()) return ReportError(loaded.error());
    skel = std::move(loaded->skeleton);
    motion = std::move(loaded->motion);
    if (upm <= 0.0f) upm = 1.0f;
    source = o.file;
  }
  base::FileLoc loc;
  loc.file = o.file.empty() ? "elastic" : o.file;
  const int joint = skel.FindJoint(o.joint);
  if (joint < 0) {
    return ReportError(
        base::MakeError(base::ErrorCode::kNotFound, loc, "no joint named '" + o.joint + "'"));
  }
  if (motion.num_frames < 2) {
    return ReportError(base::InvalidArgument(loc, "expected at least 2 frames"));
  }
  auto kin = mocap::ComputeKinematics(skel, motion, o.cutoff_hz);
  if (!kin.ok()) return ReportError(kin.error());
  const std::size_t nj = static_cast<std::size_t>(skel.num_joints());
  float max_w = 0.0f;
  for (std::size_t f = 0; f < static_cast<std::size_t>(motion.num_frames); ++f) {
    max_w = std::max(max_w, glm::length((*kin)[f * nj + static_cast<std::size_t>(joint)]
                                            .local_angular_velocity));
  }

  // A flat grid 10 cm in front of the joint, facing +Z of its frame.
  const int n = o.grid;
  std::vector<glm::vec3> pts;
  const float spacing = o.spacing_m * upm;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      pts.emplace_back((static_cast<float>(j) - 0.5f * static_cast<float>(n - 1)) * spacing,
                       (static_cast<float>(i) - 0.5f * static_cast<float>(n - 1)) * spacing,
                       0.1f * upm);
  deform::MassSpringParams params;
  params.frequency_hz = o.frequency_hz;
  params.damping_ratio = o.damping_ratio;
  params.gain = o.gain;
  params.preroll_s = o.preroll_s;
  params.units_per_metre = upm;
  const glm::quat bind = (*kin)[static_cast<std::size_t>(joint)].rotation;
  auto net = deform::BuildMassSpringNetwork(
      {.rows = n, .cols = n, .rest_points = pts, .bind_rotation = bind,
       .max_angular_speed_rad_s = max_w},
      params);
  if (!net.ok()) return ReportError(net.error());
  for (const std::string& m : net->messages) std::printf("note: %s\n", m.c_str());

  deform::MassSpringState state;
  state.Resize(*net);
  std::vector<glm::vec3> disp(pts.size());
  const std::size_t centre = static_cast<std::size_t>((n / 2) * n + n / 2);
  render::PlotOptions plot;
  plot.title = "elastic patch " + std::to_string(n) + "x" + std::to_string(n) + " driven by " +
               o.joint + " (" + source + "), f0 " + std::to_string(o.frequency_hz).substr(0, 4) +
               " Hz, z0 " + std::to_string(o.damping_ratio).substr(0, 4);
  render::PlotCurve accel{"|a| in joint frame", {}, {0.85f, 0.25f, 0.05f, 1.0f}};
  render::PlotCurve magnitude{"|e|", {}, {0.05f, 0.2f, 0.8f, 1.0f}};
  render::PlotCurve normal{"e along patch normal", {}, {0.1f, 0.55f, 0.15f, 1.0f}};
  double peak = 0.0;
  for (int f = 0; f < motion.num_frames; ++f) {
    const double t = f * motion.frame_time_s;
    const deform::MassSpringStepJob job{
        .network = &*net, .state = &state, .time_s = t, .kinematics = *kin,
        .num_joints = skel.num_joints(), .joint = joint, .frame_time_s = motion.frame_time_s,
        .displacements = disp};
    if (const base::JobStatus s = job.Run(); !s) {
      return ReportError(base::MakeError(base::ErrorCode::kInternal, loc, s.what));
    }
    const glm::vec3 a = (*kin)[static_cast<std::size_t>(f) * nj + static_cast<std::size_t>(joint)]
                            .local_linear_acceleration;
    plot.times_s.push_back(t);
    accel.values.push_back(glm::length(a) / upm);
    magnitude.values.push_back(100.0 * glm::length(disp[centre]) / upm);
    normal.values.push_back(100.0 * disp[centre].z / upm);
    peak = std::max(peak, magnitude.values.back());
  }
  plot.panels = {{"driving acceleration", "m/s^2", {accel}},
                 {"patch centre displacement", "cm", {magnitude, normal}}};
  auto image = render::DrawTimePlot(plot);
  if (!image.ok()) return ReportInternal(image.error());
  const std::filesystem::path out(o.out);
  if (out.has_parent_path()) {
    std::error_code ec;
    std::filesystem::create_directories(out.parent_path(), ec);
  }
  if (const base::Status s = render::WriteImage(*image, o.out); !s) return ReportError(s.error());
  const deform::MassSpringCounters& c = state.counters();
  std::printf("%d frames, h = %.6g s, %lld steps, peak |e| %.3f cm (e_max %.3f cm)\n",
              motion.num_frames, net->time_step_s, static_cast<long long>(c.steps), peak,
              100.0 * net->params.max_displacement / upm);
  std::printf("limits: %lld acceleration clamps, %lld displacement clamps, %lld non-finite "
              "inputs, %lld non-finite resets\n",
              static_cast<long long>(c.acceleration_clamps),
              static_cast<long long>(c.displacement_clamps),
              static_cast<long long>(c.non_finite_inputs),
              static_cast<long long>(c.non_finite_resets));
  std::printf("wrote %s\n", o.out.c_str());
  return 0;
}

}  // namespace app
