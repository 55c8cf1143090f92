#include "deform/pipeline/elastic_layer.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "deform/pipeline/character.h"

namespace deform {
namespace {

base::Error ElasticError(const Character& c, int patch, const std::string& field,
                         const std::string& message,
                         base::ErrorCode code = base::ErrorCode::kInvalidArgument) {
  return base::MakeError(
      code, {c.source, 0, 0, "patches[" + std::to_string(patch) + "].elastic" + field}, message);
}

// Rotation part of a joint matrix with any scale removed.
glm::quat RotationOf(const glm::mat4& m) {
  glm::mat3 r(m);
  for (int i = 0; i < 3; ++i) {
    const float len = glm::length(r[i]);
    if (len > 0.0f) r[i] /= len;
  }
  return glm::normalize(glm::quat_cast(r));
}

}  // namespace

base::Result<std::unique_ptr<ElasticLayer>> ElasticLayer::Create(
    const Character& c, std::span<const PatchSetup> patches, std::vector<ElasticPatchSpec> specs) {
  auto layer = std::unique_ptr<ElasticLayer>(new ElasticLayer());
  layer->character_ = &c;
  layer->duration_s_ = c.motion.duration_s();
  if (specs.empty()) return layer;
  if (c.motion.num_frames < 1 || !(c.motion.frame_time_s > 0.0)) {
    return ElasticError(c, specs.front().patch, "", "expected a motion with frames to drive it");
  }
  base::Result<std::vector<glm::mat4>> bind = BindModelFromJoint(c);
  if (!bind.ok()) return std::move(bind).error();
  const std::size_t nj = static_cast<std::size_t>(c.skeleton.num_joints());
  // One compact kinematics table per distinct cutoff, with a column per
  // distinct driving joint of the patches using that cutoff.
  for (const ElasticPatchSpec& spec : specs) {
    if (spec.patch < 0 || static_cast<std::size_t>(spec.patch) >= patches.size()) {
      return ElasticError(c, spec.patch, "", "patch index out of range");
    }
    if (spec.joint < 0 || static_cast<std::size_t>(spec.joint) >= nj) {
      return ElasticError(c, spec.patch, ".joint", "driving joint out of range");
    }
    auto group = std::find_if(layer->kinematics_.begin(), layer->kinematics_.end(),
                              [&](const Kinematics& k) { return k.cutoff_hz == spec.cutoff_hz; });
    if (group == layer->kinematics_.end()) {
      layer->kinematics_.push_back({spec.cutoff_hz, {}, {}});
      group = layer->kinematics_.end() - 1;
    }
    if (std::find(group->joints.begin(), group->joints.end(), spec.joint) == group->joints.end()) {
      group->joints.push_back(spec.joint);
    }
  }
  for (Kinematics& k : layer->kinematics_) {
    auto kin =
        mocap::ComputeKinematicsOf(c.skeleton, c.motion, k.joints, k.cutoff_hz, c.world_from_model);
    if (!kin.ok()) return std::move(kin).error();
    k.frames = std::move(*kin);
  }
  for (ElasticPatchSpec& spec : specs) {
    const PatchSetup& ps = patches[static_cast<std::size_t>(spec.patch)];
    Patch p;
    p.spec = spec;
    for (std::size_t k = 0; k < layer->kinematics_.size(); ++k) {
      if (layer->kinematics_[k].cutoff_hz == spec.cutoff_hz) p.kinematics = static_cast<int>(k);
    }
    const Kinematics& table = layer->kinematics_[static_cast<std::size_t>(p.kinematics)];
    p.slot = static_cast<int>(std::find(table.joints.begin(), table.joints.end(), spec.joint) -
                              table.joints.begin());
    const std::size_t nd = table.joints.size();
    // Step rule: the driving joint's largest angular speed over the whole
    // motion, from its column of the compact table.
    float max_w = 0.0f;
    for (std::size_t f = 0; f < static_cast<std::size_t>(c.motion.num_frames); ++f) {
      max_w = std::max(
          max_w,
          glm::length(
              table.frames[f * nd + static_cast<std::size_t>(p.slot)].local_angular_velocity));
    }
    // Rest control points in the driving joint's (rigid) bind frame.
    const glm::mat4& model_from_joint = (*bind)[static_cast<std::size_t>(spec.joint)];
    const glm::quat bind_rotation = RotationOf(model_from_joint);
    const glm::vec3 origin(model_from_joint[3]);
    std::vector<glm::vec3> rest(ps.rest_control.size());
    for (std::size_t k = 0; k < rest.size(); ++k) {
      rest[k] = glm::conjugate(bind_rotation) * (ps.rest_control[k] - origin);
    }
    auto network = BuildMassSpringNetwork({.rows = ps.fit.surface.num_u(),
                                           .cols = ps.fit.surface.num_v(),
                                           .rest_points = rest,
                                           .bind_rotation = bind_rotation,
                                           .max_angular_speed_rad_s = max_w},
                                          spec.params);
    if (!network.ok()) {
      base::Error e = std::move(network).error();
      e.loc.file = c.source;
      e.loc.field_path = "patches[" + std::to_string(spec.patch) + "].elastic";
      return e;
    }
    p.network = std::move(*network);
    p.state.Resize(p.network);
    p.local.assign(rest.size(), glm::vec3(0.0f));
    layer->piece_s_ =
        std::min(layer->piece_s_, 0.5 * static_cast<double>(spec.params.max_time_gap_s));
    layer->patches_.push_back(std::move(p));
  }
  return layer;
}

base::Status ElasticLayer::RunAll(double time_s) {
  const Character& c = *character_;
  for (Patch& p : patches_) {
    const Kinematics& table = kinematics_[static_cast<std::size_t>(p.kinematics)];
    const base::JobStatus s = MassSpringStepJob{.network = &p.network,
                                                .state = &p.state,
                                                .time_s = time_s,
                                                .kinematics = table.frames,
                                                .num_joints = static_cast<int>(table.joints.size()),
                                                .joint = p.slot,
                                                .frame_time_s = c.motion.frame_time_s,
                                                .displacements = p.local}
                                  .Run();
    if (!s) {
      return base::MakeError(base::ErrorCode::kInternal, {c.source, 0, 0, {}},
                             std::string("elastic layer refused to run: ") + s.what);
    }
  }
  return base::Status::Ok();
}

base::Status ElasticLayer::Advance(double time_s, std::span<const glm::mat4> model_from_joint,
                                   std::vector<std::vector<glm::vec3>>& displacements) {
  if (patches_.empty()) return base::Status::Ok();
  constexpr double kEps = 1e-9;
  time_s = std::clamp(time_s, 0.0, duration_s_);
  if (!started_ || time_s < time_s_ - kEps) {
    // (Re)start: zero state, preroll at the first frame, then t = 0.
    for (Patch& p : patches_) {
      p.state.Reset();
      p.baseline = p.state.counters();
    }
    if (base::Status s = RunAll(0.0); !s.ok()) return s;
    started_ = true;
    time_s_ = 0.0;
  }
  // Forward in pieces shorter than the networks' gap reset; the step grid, so
  // the state, does not depend on where the pieces end.
  while (time_s_ < time_s - kEps) {
    const double t = std::min(time_s, time_s_ + piece_s_);
    if (base::Status s = RunAll(t); !s.ok()) return s;
    time_s_ = t;
  }
  for (Patch& p : patches_) {
    const glm::quat r = RotationOf(model_from_joint[static_cast<std::size_t>(p.spec.joint)]);
    std::vector<glm::vec3>& out = displacements[static_cast<std::size_t>(p.spec.patch)];
    out.resize(p.local.size());
    float largest = 0.0f;
    for (std::size_t k = 0; k < p.local.size(); ++k) {
      out[k] = r * p.local[k];
      largest = std::max(largest, glm::length(p.local[k]));
    }
    p.displacement = largest;
  }
  return base::Status::Ok();
}

std::vector<ElasticPatchReport> ElasticLayer::Report() const {
  std::vector<ElasticPatchReport> out;
  for (const Patch& p : patches_) {
    ElasticPatchReport r;
    r.patch = p.spec.patch;
    r.joint = p.spec.joint;
    r.time_step_s = p.network.time_step_s;
    r.max_displacement = p.network.params.max_displacement;
    r.displacement = p.displacement;
    const MassSpringCounters& now = p.state.counters();
    r.counters.steps = now.steps - p.baseline.steps;
    r.counters.displacement_clamps = now.displacement_clamps - p.baseline.displacement_clamps;
    r.counters.acceleration_clamps = now.acceleration_clamps - p.baseline.acceleration_clamps;
    r.counters.non_finite_inputs = now.non_finite_inputs - p.baseline.non_finite_inputs;
    r.counters.non_finite_resets = now.non_finite_resets - p.baseline.non_finite_resets;
    r.counters.time_resets = now.time_resets - p.baseline.time_resets;
    r.messages = p.network.messages;
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace deform
