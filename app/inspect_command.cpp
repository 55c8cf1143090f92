#include "app/inspect_command.h"

#include <cstdio>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

#include "app/frame_plan.h"
#include "app/character_motion.h"
#include "app/motion_source.h"
#include "app/character.h"
#include "deform/global/rig_artifacts.h"
#include "deform/global/swd_rig.h"
#include "mocap/joint_angles.h"
#include "mocap/pose.h"

namespace app {
namespace {

const char* UpAxisName(mocap::UpAxis up) { return up == mocap::UpAxis::kY ? "Y" : "Z"; }

const char* UpAxisSourceName(mocap::UpAxisSource source) {
  switch (source) {
    case mocap::UpAxisSource::kAnimatedPoses: return "animated poses";
    case mocap::UpAxisSource::kGiven: return "given";
    case mocap::UpAxisSource::kRestPose: break;
  }
  return "rest pose";
}

std::string ChannelList(const mocap::JointChannels& c) {
  std::string out;
  for (int i = 0; i < c.count; ++i) {
    if (i > 0) out += ' ';
    out += mocap::ChannelTypeName(c.types[static_cast<std::size_t>(i)]);
  }
  return out;
}

// Depth of each joint in the tree (roots 0); parents precede children.
std::vector<int> JointDepths(const mocap::Skeleton& s) {
  std::vector<int> depth(static_cast<std::size_t>(s.num_joints()), 0);
  for (std::size_t j = 0; j < depth.size(); ++j) {
    const int p = s.parents[j];
    if (p != mocap::kNoParent) depth[j] = depth[static_cast<std::size_t>(p)] + 1;
  }
  return depth;
}

struct PoseAtFrame {
  std::vector<glm::vec3> positions;   // #J world positions
  std::vector<glm::quat> rotations;   // #J world rotations
};

PoseAtFrame EvaluateFrame(const mocap::Skeleton& s, const mocap::Motion& m, int frame) {
  const auto n = static_cast<std::size_t>(s.num_joints());
  std::vector<mocap::JointTransform> locals(n);
  std::vector<glm::mat4> model(n);
  if (m.num_frames > 0) {
    (void)mocap::LocalPoseJob{&s, m.frame(frame), locals}.Run();
  } else {
    mocap::RestPose(s, locals);
  }
  (void)mocap::LocalToModelJob{.parents = s.parents, .locals = locals, .model_from_joint = model}
      .Run();
  PoseAtFrame pose;
  for (const glm::mat4& mj : model) {
    pose.positions.emplace_back(mj[3]);
    pose.rotations.push_back(glm::normalize(glm::quat_cast(glm::mat3(mj))));
  }
  return pose;
}

nlohmann::json Vec(const glm::vec3& v) { return {v.x, v.y, v.z}; }

void PrintText(const MotionSource& src, const InspectOptions& options) {
  const mocap::Skeleton& s = src.skeleton;
  const mocap::Motion& m = src.motion;
  std::printf("file:        %s (%s)\n", options.file.c_str(), src.format.c_str());
  std::printf("joints:      %d (+%zu end sites), %d channels\n", s.num_joints(), s.end_sites.size(),
              s.num_channels);
  std::printf("frames:      %d\n", m.num_frames);
  std::printf("frame time:  %.9g s (%g fps)\n", m.frame_time_s, mocap::NominalFps(m.frame_time_s));
  std::printf("duration:    %.6g s\n", m.duration_s());
  std::printf("up axis:     %s (%s)\n", UpAxisName(s.info.up_axis),
              UpAxisSourceName(s.info.up_axis_source));
  std::printf("units:       %s (rest height %.6g, scale applied %g)\n",
              s.info.detected_units.c_str(), s.info.rest_height, s.info.scale_applied);
  if (src.mesh_vertices > 0) {
    std::printf("mesh:        %d vertices, %d triangles\n", src.mesh_vertices, src.mesh_triangles);
  }
  std::printf("\nhierarchy:\n");
  const std::vector<int> depth = JointDepths(s);
  for (int j = 0; j < s.num_joints(); ++j) {
    const auto js = static_cast<std::size_t>(j);
    const glm::vec3 o = s.rest_translations[js];
    std::printf("%*s%s  offset (%g, %g, %g)  [%s]\n", 2 + 2 * depth[js], "", s.names[js].c_str(),
                o.x, o.y, o.z, ChannelList(s.channels[js]).c_str());
  }
  if (!options.frame) return;
  const PoseAtFrame pose = EvaluateFrame(s, m, *options.frame);
  std::printf("\nframe %d (t = %.6g s): world position, rotation (w x y z)\n", *options.frame,
              *options.frame * m.frame_time_s);
  for (int j = 0; j < s.num_joints(); ++j) {
    const auto js = static_cast<std::size_t>(j);
    const glm::vec3 p = pose.positions[js];
    const glm::quat q = pose.rotations[js];
    std::printf("  %-24s (%.6g, %.6g, %.6g)  (%.6f %.6f %.6f %.6f)\n", s.names[js].c_str(), p.x,
                p.y, p.z, q.w, q.x, q.y, q.z);
  }
}

void PrintJson(const MotionSource& src, const InspectOptions& options) {
  const mocap::Skeleton& s = src.skeleton;
  const mocap::Motion& m = src.motion;
  nlohmann::ordered_json doc;
  doc["file"] = options.file;
  doc["format"] = src.format;
  doc["num_joints"] = s.num_joints();
  doc["num_channels"] = s.num_channels;
  doc["frames"] = m.num_frames;
  doc["frame_time_s"] = m.frame_time_s;
  doc["fps"] = mocap::NominalFps(m.frame_time_s);
  doc["duration_s"] = m.duration_s();
  doc["up_axis"] = UpAxisName(s.info.up_axis);
  doc["up_axis_from"] = UpAxisSourceName(s.info.up_axis_source);
  doc["units"] = s.info.detected_units;
  doc["rest_height"] = s.info.rest_height;
  doc["scale_applied"] = s.info.scale_applied;
  nlohmann::ordered_json joints = nlohmann::ordered_json::array();
  for (int j = 0; j < s.num_joints(); ++j) {
    const auto js = static_cast<std::size_t>(j);
    nlohmann::ordered_json jj;
    jj["name"] = s.names[js];
    jj["parent"] = s.parents[js] == mocap::kNoParent
                       ? nlohmann::ordered_json(nullptr)
                       : nlohmann::ordered_json(s.names[static_cast<std::size_t>(s.parents[js])]);
    jj["offset"] = Vec(s.rest_translations[js]);
    nlohmann::ordered_json channels = nlohmann::ordered_json::array();
    for (int c = 0; c < s.channels[js].count; ++c) {
      channels.push_back(mocap::ChannelTypeName(s.channels[js].types[static_cast<std::size_t>(c)]));
    }
    jj["channels"] = channels;
    joints.push_back(jj);
  }
  doc["joints"] = joints;
  nlohmann::ordered_json ends = nlohmann::ordered_json::array();
  for (const mocap::EndSite& e : s.end_sites) {
    ends.push_back({{"name", e.name},
                    {"parent", s.names[static_cast<std::size_t>(e.parent)]},
                    {"offset", Vec(e.offset)}});
  }
  doc["end_sites"] = ends;
  if (options.frame) {
    const PoseAtFrame pose = EvaluateFrame(s, m, *options.frame);
    doc["frame"] = *options.frame;
    doc["time_s"] = *options.frame * m.frame_time_s;
    nlohmann::ordered_json positions;
    nlohmann::ordered_json rotations;
    for (int j = 0; j < s.num_joints(); ++j) {
      const auto js = static_cast<std::size_t>(j);
      positions[s.names[js]] = Vec(pose.positions[js]);
      const glm::quat q = pose.rotations[js];
      rotations[s.names[js]] = {q.w, q.x, q.y, q.z};
    }
    doc["positions"] = positions;
    doc["rotations"] = rotations;
  }
  std::printf("%s\n", doc.dump(2).c_str());
}

// Collapse and candy-wrapper figures of SSD, DQS and SWD on the file's body.
int PrintArtifacts(MotionSource&& src, const std::string& file) {
  base::Result<Character> ch = MakeCharacter(std::move(src));
  if (!ch.ok()) {
    std::fprintf(stderr, "%s\n", ch.error().ToString().c_str());
    return 2;
  }
  base::Result<std::vector<glm::mat4>> bind = deform::BindModelFromJoint(*ch);
  base::Result<deform::SwdRig> rig =
      bind.ok() ? deform::BuildSwdRig(ch->skeleton, *bind, ch->mesh.bind,
                                      {.vertex_chains = ch->mesh.body_chain_coords})
                : base::Result<deform::SwdRig>(bind.error());
  if (!rig.ok()) {
    base::Error e = std::move(rig).error();
    if (e.loc.file.empty()) e.loc.file = file;
    std::fprintf(stderr, "%s\n", e.ToString().c_str());
    return 2;
  }
  const std::vector<double> bends = {90.0, 120.0, 150.0};
  const std::vector<double> twists = {90.0, 180.0};
  base::Result<std::vector<deform::LimbArtifacts>> figures =
      deform::MeasureLimbArtifacts(ch->skeleton, *bind, ch->mesh, *rig, bends, twists);
  if (!figures.ok()) {
    base::Error e = std::move(figures).error();
    if (e.loc.file.empty()) e.loc.file = file;
    std::fprintf(stderr, "%s\n", e.ToString().c_str());
    return 2;
  }
  std::printf("artifact figures of %s (%d vertices%s): ring area / rest area, 1 = kept\n",
              file.c_str(), ch->mesh.bind.num_vertices(),
              ch->bound_at_first_frame ? ", bound at frame 0" : "");
  std::printf("%-8s %-24s %-9s %7s %7s %7s\n", "limb", "joint", "pose", "SSD", "DQS", "SWD");
  for (const deform::LimbArtifacts& l : *figures) {
    const char* kind = l.arm ? "arm" : "leg";
    for (const deform::AngleFigures& a : l.collapse) {
      std::printf("%-8s %-24s bend %3.0f  %7.3f %7.3f %7.3f\n", kind, l.joint.c_str(), a.degrees,
                  a.figures.ssd, a.figures.dqs, a.figures.swd);
    }
    for (const deform::AngleFigures& a : l.candy) {
      std::printf("%-8s %-24s twist %3.0f %7.3f %7.3f %7.3f\n", kind, l.end_joint.c_str(),
                  a.degrees, a.figures.ssd, a.figures.dqs, a.figures.swd);
    }
  }
  std::printf("bend: collapse figure at the elbow/knee; twist: candy-wrapper figure along the "
              "forearm (hand turned about it)\n");
  return 0;
}

// `inspect MODEL --motion X.bvh`: how the motion's joints drive the character's.
int PrintRetarget(const InspectOptions& options) {
  RetargetReport r;
  const base::Result<std::optional<mocap::UpAxis>> up = ParseUpAxis(options.up);
  if (!up.ok()) {
    std::fprintf(stderr, "%s\n", up.error().ToString().c_str());
    return 2;
  }
  base::Result<Character> ch = LoadCommandCharacter(options.file, options.motion,
                                                    /*quiet=*/false, *up, options.joint_map, &r);
  if (!ch.ok()) {
    std::fprintf(stderr, "%s\n", ch.error().ToString().c_str());
    return 2;
  }
  if (options.json) {
    nlohmann::json joints = nlohmann::json::array();
    for (const auto& [character, motion] : r.joints) {
      joints.push_back({{"character", character},
                        {"motion", motion.empty() ? nlohmann::json() : nlohmann::json(motion)}});
    }
    const nlohmann::json doc = {
        {"file", options.file},
        {"motion", options.motion},
        {"joint_map", options.joint_map.empty() ? nlohmann::json() : nlohmann::json(options.joint_map)},
        {"method", r.method},
        {"motion_reference_pose", r.source_pose},
        {"sides", {{"character", r.target_sides}, {"motion", r.source_sides}}},
        {"root", {{"character", r.target_root}, {"motion", r.source_root}}},
        {"translation_scale", r.translation_scale},
        {"joints", joints}};
    std::printf("%s\n", doc.dump(2, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
    return 0;
  }
  std::printf("character:  %s\nmotion:     %s\nmatched by: %s", options.file.c_str(),
              options.motion.c_str(), r.method.c_str());
  if (r.method == "topology") {
    std::printf(" (left/right from: character %s, motion %s; motion pose aligned: %s)",
                r.target_sides.c_str(), r.source_sides.c_str(), r.source_pose.c_str());
  }
  std::printf("\nroot:       %s <- %s, translation x %g\n\njoints (character <- motion):\n",
              r.target_root.c_str(), r.source_root.c_str(), r.translation_scale);
  for (const auto& [character, motion] : r.joints) {
    std::printf("  %-28s <- %s\n", character.c_str(), motion.empty() ? "(rest)" : motion.c_str());
  }
  return 0;
}

}  // namespace

int RunInspect(const InspectOptions& options) {
  if (!options.motion.empty()) return PrintRetarget(options);
  MotionSourceOptions load;
  load.scale = options.scale;
  load.y_up = options.y_up;
  const base::Result<std::optional<mocap::UpAxis>> up = ParseUpAxis(options.up);
  if (!up.ok()) {
    std::fprintf(stderr, "%s\n", up.error().ToString().c_str());
    return 2;
  }
  load.up = *up;
  load.add_position_to_offset = options.add_position_to_offset;
  load.allow_short_motion = options.allow_short;
  load.require_skin = false;  // inspect describes any glTF, an exported (skinless) .glb too
  base::Result<MotionSource> src = LoadMotionSource(options.file, load);
  if (!src.ok()) {
    std::fprintf(stderr, "%s\n", src.error().ToString().c_str());
    return 2;
  }
  for (const base::Warning& w : src->warnings) std::fprintf(stderr, "%s\n", w.ToString().c_str());
  if (options.frame) {
    const int last = src->motion.num_frames - 1;
    if (*options.frame < 0 || *options.frame > std::max(last, 0)) {
      std::fprintf(stderr, "%s: error: --frame %d is outside the capture's frames 0..%d\n",
                   options.file.c_str(), *options.frame, std::max(last, 0));
      return 2;
    }
  }
  if (options.artifacts) return PrintArtifacts(std::move(*src), options.file);
  if (options.json) {
    PrintJson(*src, options);
  } else {
    PrintText(*src, options);
  }
  return 0;
}

}  // namespace app
