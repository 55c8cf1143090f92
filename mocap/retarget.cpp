#include "mocap/retarget.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "mocap/pose.h"

namespace mocap {
namespace {

// World (model-space) rotation of every joint of a pose, ignoring scale:
// world[j] = world[parent] * local[j].
void WorldRotations(const Skeleton& s, std::span<const JointTransform> locals,
                    std::vector<glm::quat>& world) {
  world.resize(locals.size());
  for (std::size_t j = 0; j < locals.size(); ++j) {
    const int p = s.parents[j];
    world[j] = p == kNoParent ? locals[j].rotation
                              : world[static_cast<std::size_t>(p)] * locals[j].rotation;
  }
}

std::vector<glm::mat4> RestModel(const Skeleton& s) {
  std::vector<JointTransform> locals(static_cast<std::size_t>(s.num_joints()));
  std::vector<glm::mat4> model(locals.size());
  RestPose(s, locals);
  (void)LocalToModelJob{.parents = s.parents, .locals = locals, .model_from_joint = model}.Run();
  return model;
}

bool IsAncestor(const Skeleton& s, int ancestor, int joint) {
  for (int p = s.parents[static_cast<std::size_t>(joint)]; p != kNoParent;
       p = s.parents[static_cast<std::size_t>(p)]) {
    if (p == ancestor) return true;
  }
  return false;
}

}  // namespace

std::string NormalizeJointName(std::string_view name) {
  const std::size_t cut = name.find_last_of(":|");
  if (cut != std::string_view::npos) name.remove_prefix(cut + 1);
  std::string out;
  out.reserve(name.size());
  for (const char c : name) out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (out.rfind("mixamorig", 0) == 0) {
    std::size_t i = 9;
    while (i < out.size() && std::isdigit(static_cast<unsigned char>(out[i]))) ++i;
    if (i < out.size() && out[i] == '_') ++i;
    if (i < out.size()) out.erase(0, i);
  }
  return out;
}

std::vector<int> MapJointsByName(const Skeleton& target, const Skeleton& source) {
  const int nt = target.num_joints();
  std::vector<int> map(static_cast<std::size_t>(nt), -1);
  std::vector<bool> used(static_cast<std::size_t>(source.num_joints()), false);
  for (int j = 0; j < nt; ++j) {
    const int b = source.FindJoint(target.names[static_cast<std::size_t>(j)]);
    if (b >= 0 && !used[static_cast<std::size_t>(b)]) {
      map[static_cast<std::size_t>(j)] = b;
      used[static_cast<std::size_t>(b)] = true;
    }
  }
  std::vector<std::string> normalized;
  for (const std::string& n : source.names) normalized.push_back(NormalizeJointName(n));
  for (int j = 0; j < nt; ++j) {
    if (map[static_cast<std::size_t>(j)] >= 0) continue;
    const std::string key = NormalizeJointName(target.names[static_cast<std::size_t>(j)]);
    for (std::size_t b = 0; b < normalized.size(); ++b) {
      if (!used[b] && !key.empty() && normalized[b] == key) {
        map[static_cast<std::size_t>(j)] = static_cast<int>(b);
        used[b] = true;
        break;
      }
    }
  }
  return map;
}

float HipHeight(const Skeleton& skeleton, int joint) {
  const std::vector<glm::mat4> model = RestModel(skeleton);
  float lowest = model[static_cast<std::size_t>(joint)][3].y;
  for (const glm::mat4& m : model) lowest = std::min(lowest, m[3].y);
  return model[static_cast<std::size_t>(joint)][3].y - lowest;
}

base::Result<RetargetPlan> PlanByName(const Skeleton& target, const Skeleton& source,
                                      const std::string& target_file,
                                      const std::string& source_file,
                                      std::vector<base::Warning>* warnings) {
  RetargetPlan plan;
  plan.source_of_target = MapJointsByName(target, source);
  const int nt = target.num_joints();
  const auto& map = plan.source_of_target;
  auto mapped = [&map](int j) { return map[static_cast<std::size_t>(j)] >= 0; };

  // The root: the target joint driven by the source's first root joint.
  for (int j = 0; j < nt && plan.target_root < 0; ++j) {
    if (map[static_cast<std::size_t>(j)] == 0) plan.target_root = j;
  }
  std::vector<std::string> missing;
  if (plan.target_root < 0 && source.num_joints() > 0) missing.push_back(source.names[0] + " (the root)");
  for (int j = 0; j < nt; ++j) {
    if (mapped(j)) continue;
    bool above = false, below = false;
    for (int k = 0; k < nt; ++k) {
      if (!mapped(k)) continue;
      above = above || IsAncestor(target, k, j);
      below = below || IsAncestor(target, j, k);
    }
    if (above && below) missing.push_back(target.names[static_cast<std::size_t>(j)]);
  }
  if (!missing.empty()) {
    std::string list;
    for (std::size_t i = 0; i < missing.size() && i < 12; ++i) {
      list += (i ? ", " : "") + missing[i];
    }
    if (missing.size() > 12) list += ", ... (" + std::to_string(missing.size()) + " in all)";
    return base::InvalidArgument(
        {source_file, 0, 0, {}},
        "expected the joints of " + target_file +
            " that the motion must drive (matched by name, then case-insensitively "
            "without prefixes such as \"mixamorig:\"), found none for: " +
            list);
  }
  std::string unmapped;
  int num_unmapped = 0;
  for (int j = 0; j < nt; ++j) {
    if (mapped(j)) continue;
    if (++num_unmapped <= 8) unmapped += (unmapped.empty() ? "" : ", ") + target.names[static_cast<std::size_t>(j)];
  }
  if (num_unmapped > 0 && warnings != nullptr) {
    warnings->push_back(
        {{source_file, 0, 0, {}},
         std::to_string(num_unmapped) + " joint(s) of " + target_file +
             " have no joint of that name in the motion and keep their rest pose: " + unmapped +
             (num_unmapped > 8 ? ", ..." : "")});
  }
  const float source_hips = HipHeight(source, 0);
  const float target_hips = HipHeight(target, plan.target_root);
  if (!(source_hips > 0.0f) || !(target_hips > 0.0f)) {
    return base::InvalidArgument(
        {source_hips > 0.0f ? target_file : source_file, 0, 0, {}},
        "expected the root joint above the lowest joint in the rest pose (a hip "
        "height > 0) to scale the root translation");
  }
  plan.translation_scale = target_hips / source_hips;
  return plan;
}

base::Result<RetargetedMotion> ApplyRetargetPlan(const Skeleton& target, const Skeleton& source,
                                                 const Motion& source_motion,
                                                 const RetargetPlan& plan,
                                                 const std::string& source_file) {
  const int nt = target.num_joints();
  const auto ns = static_cast<std::size_t>(source.num_joints());
  const auto& map = plan.source_of_target;
  const bool aligned = !plan.align.empty();
  if (map.size() != static_cast<std::size_t>(nt) ||
      (aligned && plan.align.size() != static_cast<std::size_t>(nt)) || plan.target_root < 0 ||
      plan.target_root >= nt || map[static_cast<std::size_t>(plan.target_root)] < 0 ||
      plan.source_root < 0 || static_cast<std::size_t>(plan.source_root) >= ns) {
    return base::InvalidArgument(
        {source_file, 0, 0, {}},
        "expected a retargeting plan with one entry per target joint and a mapped "
        "root joint");
  }
  for (const int b : map) {
    if (b >= static_cast<int>(ns)) {
      return base::InvalidArgument({source_file, 0, 0, {}},
                                   "retargeting plan names source joint " + std::to_string(b) +
                                       ", expected one of the motion's " + std::to_string(ns));
    }
  }
  auto mapped = [&map](int j) { return map[static_cast<std::size_t>(j)] >= 0; };
  RetargetedMotion out;
  out.source_of_target = map;
  out.root = plan.target_root;
  out.translation_scale = plan.translation_scale;

  // The channel layout: 4 quaternion channels per mapped joint, 3 position
  // channels first on the root.
  out.skeleton = target;
  out.skeleton.position_mode = PositionChannelMode::kReplaceOffset;
  int channels = 0;
  for (int j = 0; j < nt; ++j) {
    JointChannels& ch = out.skeleton.channels[static_cast<std::size_t>(j)];
    ch = {};
    if (!mapped(j)) continue;
    ch.first = static_cast<std::uint32_t>(channels);
    if (j == out.root) {
      ch.types[ch.count++] = ChannelType::kXPosition;
      ch.types[ch.count++] = ChannelType::kYPosition;
      ch.types[ch.count++] = ChannelType::kZPosition;
    }
    for (ChannelType t : {ChannelType::kQuatX, ChannelType::kQuatY, ChannelType::kQuatZ,
                          ChannelType::kQuatW}) {
      ch.types[ch.count++] = t;
    }
    channels += ch.count;
  }
  out.skeleton.num_channels = channels;
  out.motion.num_channels = channels;
  out.motion.num_frames = source_motion.num_frames;
  out.motion.frame_time_s = source_motion.frame_time_s;
  out.motion.values.assign(
      static_cast<std::size_t>(channels) * static_cast<std::size_t>(source_motion.num_frames), 0.0f);

  // Rest state of both skeletons; the target's rest folded into the alignment:
  // world_rot_j(f) = world_rot_b(f) * after[j].
  std::vector<JointTransform> target_rest(static_cast<std::size_t>(nt)), source_locals(ns);
  RestPose(target, target_rest);
  RestPose(source, source_locals);
  std::vector<glm::quat> target_rest_world, source_rest_world, source_world;
  WorldRotations(target, target_rest, target_rest_world);
  WorldRotations(source, source_locals, source_rest_world);
  std::vector<glm::quat> after(static_cast<std::size_t>(nt), glm::quat(1, 0, 0, 0));
  for (int j = 0; j < nt; ++j) {
    const auto ju = static_cast<std::size_t>(j);
    if (!mapped(j)) continue;
    const glm::quat a = aligned ? plan.align[ju] : glm::quat(1, 0, 0, 0);
    after[ju] = glm::inverse(source_rest_world[static_cast<std::size_t>(map[ju])]) * a *
                target_rest_world[ju];
  }
  const std::vector<glm::mat4> target_rest_model = RestModel(target);
  const int root_parent = target.parents[static_cast<std::size_t>(out.root)];
  const glm::mat4 parent_from_model =
      root_parent == kNoParent ? glm::mat4(1.0f)
                               : glm::inverse(target_rest_model[static_cast<std::size_t>(root_parent)]);

  std::vector<glm::mat4> source_model(ns);
  std::vector<glm::quat> world(static_cast<std::size_t>(nt));
  std::vector<glm::quat> previous(static_cast<std::size_t>(nt), glm::quat(1, 0, 0, 0));
  const auto source_root = static_cast<std::size_t>(plan.source_root);
  for (int f = 0; f < source_motion.num_frames; ++f) {
    base::JobStatus s = LocalPoseJob{&source, source_motion.frame(f), source_locals}.Run();
    if (s) s = LocalToModelJob{.parents = source.parents, .locals = source_locals,
                               .model_from_joint = source_model}.Run();
    if (!s) {
      return base::MakeError(base::ErrorCode::kInternal, {source_file, 0, 0, {}},
                             std::string("retargeting: pose evaluation refused to run: ") + s.what);
    }
    WorldRotations(source, source_locals, source_world);
    std::span<float> row = out.motion.frame(f);
    for (int j = 0; j < nt; ++j) {
      const auto ju = static_cast<std::size_t>(j);
      const int p = target.parents[ju];
      const glm::quat parent_world = p == kNoParent ? glm::quat(1, 0, 0, 0)
                                                    : world[static_cast<std::size_t>(p)];
      if (!mapped(j)) {
        world[ju] = parent_world * target_rest[ju].rotation;
        continue;
      }
      const auto b = static_cast<std::size_t>(map[ju]);
      world[ju] = source_world[b] * after[ju];
      glm::quat local = glm::normalize(glm::inverse(parent_world) * world[ju]);
      if (glm::dot(local, previous[ju]) < 0.0f) local = -local;  // continuous for slerp
      previous[ju] = local;
      float* v = row.data() + out.skeleton.channels[ju].first;
      if (j == out.root) {
        const glm::vec3 moved = out.translation_scale * glm::vec3(source_model[source_root][3]);
        const glm::vec3 t = glm::vec3(parent_from_model * glm::vec4(moved, 1.0f));
        *v++ = t.x;
        *v++ = t.y;
        *v++ = t.z;
      }
      *v++ = local.x;
      *v++ = local.y;
      *v++ = local.z;
      *v++ = local.w;
    }
  }
  const base::Status checked = out.skeleton.Check();
  if (!checked.ok()) return checked.error();
  return out;
}

base::Result<RetargetedMotion> RetargetMotion(const Skeleton& target, const Skeleton& source,
                                              const Motion& source_motion,
                                              const std::string& target_file,
                                              const std::string& source_file) {
  std::vector<base::Warning> warnings;
  base::Result<RetargetPlan> plan = PlanByName(target, source, target_file, source_file, &warnings);
  if (!plan.ok()) return std::move(plan).error();
  base::Result<RetargetedMotion> out =
      ApplyRetargetPlan(target, source, source_motion, *plan, source_file);
  if (out.ok()) out->warnings = std::move(warnings);
  return out;
}

}  // namespace mocap
