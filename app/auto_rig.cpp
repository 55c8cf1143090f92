#include "app/auto_rig.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "app/character_motion.h"
#include "app/frame_plan.h"
#include "app/rig_patches.h"
#include "deform/body/body_chains.h"
#include "deform/body/humanoid_map.h"
#include "mocap/pose.h"

namespace app {
namespace {

constexpr float kMinBranchExtent = 0.15f;  // as the generated bodies fold fingers
constexpr int kMaxScannedFrames = 2000;    // frames read for the largest bends
constexpr float kMinBendDeg = 20.0f;       // below this a hinge's side comes from the body axes

// Rounds to three significant digits (any units: cm or m) so the rig file reads
// as typed; directions (components <= 1) to 0.01.
float Round2(float x) {
  if (x == 0.0f || !std::isfinite(x)) return 0.0f;
  const float scale = std::pow(10.0f, 2.0f - std::floor(std::log10(std::abs(x))));
  return std::round(x * scale) / scale + 0.0f;  // + 0: no "-0"
}
float RoundUnit(float x) { return std::round(x * 100.0f) / 100.0f + 0.0f; }
glm::vec3 Round2(glm::vec3 v) { return {RoundUnit(v.x), RoundUnit(v.y), RoundUnit(v.z)}; }

glm::vec3 Perp(glm::vec3 v, glm::vec3 axis) { return v - glm::dot(v, axis) * axis; }

glm::vec3 UnitOr(glm::vec3 v, glm::vec3 fallback) {
  const float n = glm::length(v);
  return n > 1e-6f ? v / n : fallback;
}

// The model matrices of sampled frames of the motion, frame-major.
struct SampledPoses {
  std::vector<int> frames;
  std::vector<glm::mat4> model_from_joint;  // frames.size() x #J
};

SampledPoses SamplePoses(const mocap::Skeleton& skeleton, const mocap::Motion& motion) {
  SampledPoses s;
  const int count = motion.num_frames;
  const int step = std::max(1, (count + kMaxScannedFrames - 1) / kMaxScannedFrames);
  const std::size_t joints = skeleton.parents.size();
  std::vector<mocap::JointTransform> locals(joints);
  std::vector<glm::mat4> model(joints);
  for (int f = 0; f < count; f += step) {
    const mocap::LocalPoseJob local{&skeleton, motion.frame(f), locals};
    const mocap::LocalToModelJob to_model{skeleton.parents, locals, glm::mat4(1.0f), model};
    if (!local.Run() || !to_model.Run()) continue;  // a bad frame is left out of the scan
    s.frames.push_back(f);
    s.model_from_joint.insert(s.model_from_joint.end(), model.begin(), model.end());
  }
  return s;
}

// A hinge: parent point a, the joint's point p, child point c (BodyChains ids).
struct Hinge {
  glm::vec3 bend{0.0f};  // unit, bind space: where the child bone swings to
  float angle_deg = 0.0f;
  int frame = -1;        // motion frame of the largest bend
};

// The largest bend of the hinge a-p-c over the sampled frames, measured in the
// bind frame of the bone a->p (so the whole body's turning does not count).
Hinge LargestBend(const deform::BodyChains& chains, int a, int p, int c,
                  std::span<const glm::mat4> bind, const SampledPoses& poses, std::size_t joints) {
  Hinge h;
  const deform::BodyPoint& pp = chains.points[static_cast<std::size_t>(p)];
  const deform::BodyPoint& pc = chains.points[static_cast<std::size_t>(c)];
  const int upper = pp.bone_joint;
  if (upper < 0 || pp.joint < 0 || pc.joint < 0) return h;
  const glm::vec3 axis = UnitOr(pp.pos - chains.points[static_cast<std::size_t>(a)].pos, {0, 1, 0});
  const glm::vec3 rest = UnitOr(pc.pos - pp.pos, axis);
  const glm::mat3 bind_upper(bind[static_cast<std::size_t>(upper)]);
  for (std::size_t k = 0; k < poses.frames.size(); ++k) {
    const glm::mat4* m = &poses.model_from_joint[k * joints];
    const glm::vec3 d = glm::vec3(m[pc.joint][3]) - glm::vec3(m[pp.joint][3]);
    const glm::mat3 pose_upper(m[upper]);
    // Back to the bind pose of the upper bone: rotation-only (scale is removed
    // by normalising the result).
    const glm::vec3 in_bind = UnitOr(bind_upper * glm::inverse(pose_upper) * d, rest);
    const float angle = glm::degrees(std::acos(std::clamp(glm::dot(in_bind, rest), -1.0f, 1.0f)));
    if (angle > h.angle_deg) {
      h.angle_deg = angle;
      h.frame = poses.frames[k];
      h.bend = UnitOr(Perp(in_bind - rest, axis), h.bend);
    }
  }
  return h;
}

const std::string* JointName(const mocap::Skeleton& s, const deform::BodyChains& chains, int point) {
  const int j = chains.points[static_cast<std::size_t>(point)].joint;
  return j < 0 ? nullptr : &s.names[static_cast<std::size_t>(j)];
}

RigPatch JointPatch(const std::string& name, const std::string& joint, float radius, glm::vec3 side,
                    float half_angle, glm::ivec2 grid, glm::ivec2 sampling, bool cylinder) {
  RigPatch p;
  p.name = name;
  p.region.kind = RigRegion::Kind::kJoint;
  p.region.joint = joint;
  p.region.radius = Round2(radius);
  p.region.side = Round2(side);
  p.region.half_angle_deg = half_angle;
  p.grid = grid;
  p.sampling = sampling;
  p.cylinder = cylinder;
  p.border_width = 0.15f;
  return p;
}

float Dist(const deform::BodyChains& c, int a, int b) {
  return glm::distance(c.points[static_cast<std::size_t>(a)].pos, c.points[static_cast<std::size_t>(b)].pos);
}

// A computed corrective example (`"auto": "volume"`, deform/shapes/
// corrective_example.h) at the capture's frame of the joint's largest bend;
// none when the joint hardly bends.
void AddVolumeExample(RigPatch& p, const Hinge& hinge) {
  if (hinge.frame < 0 || hinge.angle_deg < kMinBendDeg) return;
  RigExample e;
  e.pose.frame = hinge.frame;
  e.auto_kind = "volume";
  p.examples.push_back(std::move(e));
}

// The elbow (knee) of a limb: the point between its two longest consecutive
// bones up to the extremity, upper arm and forearm (thigh and shin), so a hand
// end site does not shift it. 0 when the limb is too short.
int MiddleOfLongestPair(const deform::BodyChains& c, const deform::HumanoidLimb& limb) {
  int best = 0;
  float best_len = 0.0f;
  const int last = std::min(limb.extremity + 1, static_cast<int>(limb.points.size()) - 1);
  // From 2: the first bone leaves the trunk (a collar, a pelvis half) and may
  // be as long as a forearm (CMU's collar 3.6 against the forearm's 3.5).
  for (int k = 2; k < last; ++k) {
    const auto at = [&](int i) { return limb.points[static_cast<std::size_t>(i)]; };
    const float len = Dist(c, at(k - 1), at(k)) + Dist(c, at(k), at(k + 1));
    if (len > best_len) best = k, best_len = len;
  }
  return best;
}

// The patches of one arm and one leg (side 0 left, 1 right).
void PlaceLimbs(const mocap::Skeleton& s, const deform::Humanoid& h, int side,
                std::span<const glm::mat4> bind, const SampledPoses& poses, AutoRig& out) {
  const deform::BodyChains& c = h.chains;
  const std::string prefix = side == 0 ? "left_" : "right_";
  const std::size_t joints = s.parents.size();
  const auto hinge_side = [&](const char* what, int a, int p, int e, glm::vec3 fallback) {
    Hinge hinge = LargestBend(c, a, p, e, bind, poses, joints);
    if (hinge.angle_deg >= kMinBendDeg && glm::dot(hinge.bend, fallback) < 0.0f) {
      // Against the anatomical way (a retargeted rest pose straightening a
      // bent bind pose): the body's axes decide.
      out.notes.push_back(prefix + what + ": its largest change straightens it; its side comes "
                                          "from the body's front");
      hinge.bend = fallback;
    } else if (hinge.angle_deg < kMinBendDeg) {
      out.notes.push_back(prefix + what + ": bends at most " +
                          std::to_string(static_cast<int>(hinge.angle_deg)) +
                          " degrees; its side comes from the body's front");
      hinge.bend = fallback;
    } else {
      out.notes.push_back(prefix + what + ": largest bend " +
                          std::to_string(static_cast<int>(hinge.angle_deg)) + " degrees at frame " +
                          std::to_string(hinge.frame));
    }
    return hinge;
  };

  const deform::HumanoidLimb& arm = h.arms[side];
  if (const int k = MiddleOfLongestPair(c, arm); k > 0) {
    const int wrist = arm.points[static_cast<std::size_t>(k + 1)];
    const int elbow = arm.points[static_cast<std::size_t>(k)];
    const int shoulder = arm.points[static_cast<std::size_t>(k - 1)];
    const std::string* elbow_joint = JointName(s, c, elbow);
    const std::string* shoulder_joint = JointName(s, c, shoulder);
    const float upper = Dist(c, shoulder, elbow), fore = Dist(c, elbow, wrist);
    if (elbow_joint != nullptr && shoulder_joint != nullptr) {
      const Hinge e = hinge_side("elbow", shoulder, elbow, wrist, h.forward);
      RigPatch back = JointPatch(prefix + "elbow_back", *elbow_joint, 0.45f * fore, -e.bend, 80,
                                 {7, 7}, {16, 16}, true);
      RigPatch biceps = JointPatch(prefix + "biceps", *elbow_joint, 0.75f * upper, e.bend, 80,
                                   {9, 10}, {18, 20}, true);
      RigPatch top = JointPatch(prefix + "shoulder_top", *shoulder_joint, 0.4f * upper, h.up, 60,
                                {9, 6}, {18, 12}, false);
      // The biceps and shoulder are left without one: restoring their region's
      // volume swelled the walk's upper arms into lumps (seen at 1280x720).
      AddVolumeExample(back, e);
      out.rig.patches.push_back(std::move(back));
      out.rig.patches.push_back(std::move(biceps));
      out.rig.patches.push_back(std::move(top));
    }
  }
  const deform::HumanoidLimb& leg = h.legs[side];
  if (const int k = MiddleOfLongestPair(c, leg); k > 0) {
    const int ankle = leg.points[static_cast<std::size_t>(k + 1)];
    const int knee = leg.points[static_cast<std::size_t>(k)];
    const int hip = leg.points[static_cast<std::size_t>(k - 1)];
    const std::string* knee_joint = JointName(s, c, knee);
    const std::string* hip_joint = JointName(s, c, hip);
    const float thigh = Dist(c, hip, knee), shin = Dist(c, knee, ankle);
    if (knee_joint != nullptr && hip_joint != nullptr) {
      // A knee bends backwards: its front is away from the bend.
      const Hinge bent = hinge_side("knee", hip, knee, ankle, -h.forward);
      const Hinge flex = LargestBend(c, leg.points[static_cast<std::size_t>(k - 2)], hip, knee, bind,
                                     poses, joints);
      RigPatch front = JointPatch(prefix + "knee_front", *knee_joint, 0.4f * shin, -bent.bend, 80,
                                  {7, 7}, {16, 16}, true);
      RigPatch buttock = JointPatch(prefix + "hip_back", *hip_joint, 0.4f * thigh, -h.forward, 70,
                                    {7, 7}, {16, 16}, false);
      AddVolumeExample(front, bent);
      AddVolumeExample(buttock, flex);
      out.rig.patches.push_back(std::move(front));
      out.rig.patches.push_back(std::move(buttock));
    }
  }
}

// Gentler than the demo rigs (gain 0.5 on the belly, stiffer bending) and a
// displacement limit of 8 % of the region's radius: a capture of any violence
// (Bandai's run) must jiggle the patch, never crease it.
RigElastic Elastic(float frequency_hz, float damping_ratio, float gain, float radius) {
  RigElastic e;
  e.params.frequency_hz = frequency_hz;
  e.params.damping_ratio = damping_ratio;
  e.params.gain = gain;
  e.params.bending_ratio = 1.0f;
  e.params.max_displacement = Round2(0.08f * radius);
  return e;
}

// An elastic patch fades out over a wider border (0.3) than a sculpted one: on
// the generated body's jagged chest underside a narrow fade left a notch.
RigPatch ElasticPatch(RigPatch p, RigElastic e) {
  p.border_width = 0.3f;
  p.elastic = std::move(e);
  return p;
}

// Belly and jowl on a humanoid's spine.
void PlaceTrunk(const mocap::Skeleton& s, const deform::Humanoid& h, AutoRig& out) {
  const deform::BodyChains& c = h.chains;
  const int pelvis = h.spine.front();
  const int chest = h.spine[static_cast<std::size_t>(h.chest)];
  const glm::vec3 p0 = c.points[static_cast<std::size_t>(pelvis)].pos;
  const glm::vec3 p1 = c.points[static_cast<std::size_t>(chest)].pos;
  const glm::vec3 target = glm::mix(p0, p1, 0.45f);
  int belly = -1;
  float best = 0.0f;
  for (int k = 1; k <= h.chest; ++k) {
    const int id = h.spine[static_cast<std::size_t>(k)];
    if (JointName(s, c, id) == nullptr) continue;
    const float d = glm::distance(c.points[static_cast<std::size_t>(id)].pos, target);
    if (belly < 0 || d < best) belly = id, best = d;
  }
  const float trunk = glm::distance(p0, p1);
  if (belly >= 0) {
    RigPatch p = JointPatch("belly", *JointName(s, c, belly), 0.4f * trunk, h.forward, 70, {6, 6},
                            {10, 10}, true);
    p = ElasticPatch(p, Elastic(4.0f, 0.2f, 0.5f, p.region.radius));
    for (int k = 1; k <= h.chest; ++k) {  // the other trunk joints, should its skin be elsewhere
      const int id = h.spine[static_cast<std::size_t>(k)];
      if (id != belly && JointName(s, c, id) != nullptr) {
        out.alternate_joints.emplace_back("belly", *JointName(s, c, id));
      }
    }
    out.rig.patches.push_back(std::move(p));
  } else {
    out.notes.push_back("belly: skipped (no spine joint between the pelvis and the chest)");
  }
  // The head: the spine point before the tip (its bone is the neck's end), the
  // one before that when the body gives it no skin; size from the head's bone.
  if (h.spine.size() >= 3) {
    const int tip = h.spine.back();
    const int head = h.spine[h.spine.size() - 2];
    const std::string* head_joint = JointName(s, c, head);
    const float head_len = Dist(c, head, tip);
    if (head_joint != nullptr && head_len > 0.0f) {
      RigPatch p = JointPatch("jowl", *head_joint, 0.9f * head_len, h.forward, 75, {5, 5}, {8, 8},
                              true);
      p = ElasticPatch(p, Elastic(5.0f, 0.25f, 1.0f, p.region.radius));
      if (const std::string* neck = JointName(s, c, h.spine[h.spine.size() - 3])) {
        out.alternate_joints.emplace_back("jowl", *neck);
      }
      out.rig.patches.push_back(std::move(p));
      return;
    }
  }
  out.notes.push_back("jowl: skipped (no head joint at the end of the spine)");
}

// A skeleton that is no humanoid: an elastic belly under its first spine.
void PlaceNonHumanoid(const mocap::Skeleton& s, std::span<const glm::mat4> bind,
                      const std::string& why, AutoRig& out) {
  out.notes.push_back("not a humanoid (" + why +
                      "): skipped elbows, biceps, shoulders, knees, hips and jowl");
  base::Result<deform::BodyChains> chains = deform::BuildBodyChains(s, bind, kMinBranchExtent);
  if (!chains.ok() || chains->chains.empty() ||
      chains->chains.front().kind != deform::BodyChainKind::kSpine) {
    out.notes.push_back("belly: skipped (no spine chain)");
    return;
  }
  const deform::BodyChains& c = *chains;
  const std::vector<int>& spine = c.chains.front().points;
  // Arc length along the spine; the belly sits at the joint nearest its middle.
  std::vector<float> arc(spine.size(), 0.0f);
  for (std::size_t k = 1; k < spine.size(); ++k) arc[k] = arc[k - 1] + Dist(c, spine[k - 1], spine[k]);
  int belly = -1;
  float best = 0.0f;
  for (std::size_t k = 1; k < spine.size(); ++k) {
    if (JointName(s, c, spine[k]) == nullptr) continue;
    const float d = std::abs(arc[k] - 0.5f * arc.back());
    if (belly < 0 || d < best) belly = spine[k], best = d;
  }
  // Down: from the spine's middle towards the tips of the limbs hanging from it.
  glm::vec3 tips(0.0f);
  int limbs = 0;
  for (const deform::BodyChain& chain : c.chains) {
    if (chain.kind != deform::BodyChainKind::kLimb || chain.parent_chain != 0) continue;
    tips += c.points[static_cast<std::size_t>(chain.points.back())].pos;
    ++limbs;
  }
  if (belly < 0 || limbs == 0) {
    out.notes.push_back("belly: skipped (no spine joint with limbs below it)");
    return;
  }
  const glm::vec3 mid = c.points[static_cast<std::size_t>(belly)].pos;
  // Across the spine's axis, so a tail among the limbs does not tilt it.
  const glm::vec3 axis = UnitOr(c.points[static_cast<std::size_t>(spine.back())].pos -
                                    c.points[static_cast<std::size_t>(spine.front())].pos,
                                {0, 0, 1});
  const glm::vec3 down = UnitOr(Perp(tips / static_cast<float>(limbs) - mid, axis), {0, -1, 0});
  RigPatch p = JointPatch("belly", *JointName(s, c, belly), 0.2f * arc.back(), down, 70, {6, 6},
                          {10, 10}, true);
  p = ElasticPatch(p, Elastic(4.0f, 0.2f, 0.5f, p.region.radius));
  out.notes.push_back("belly: placed under the spine at joint " + p.region.joint);
  out.rig.patches.push_back(std::move(p));
}

// A humanoid's legs hang along its spine (hip -> ankle against pelvis -> chest);
// four legs under a horizontal spine pass FindHumanoid's pairing as "arms" and
// "legs" but are no humanoid. Empty when upright, else the reason.
std::string UprightProblem(const deform::Humanoid& h) {
  for (const deform::HumanoidLimb& leg : h.legs) {
    const glm::vec3 hip = h.chains.points[static_cast<std::size_t>(leg.points.front())].pos;
    const glm::vec3 ankle =
        h.chains.points[static_cast<std::size_t>(leg.points[static_cast<std::size_t>(leg.extremity)])].pos;
    if (glm::dot(UnitOr(ankle - hip, h.up), -h.up) < 0.5f) {
      return "the legs do not hang along the spine: a horizontal spine, four legs?";
    }
  }
  return {};
}

// Keeps the patches that build on this character's mesh: a region the skin
// weights leave empty, or a cylinder wrapping too far round, is tried again
// wider and looser (1.5 x the radius, bone weight 0.25, a narrower side; then
// flat), then smaller (0.7 x, flat, 50 degrees: a map that folded), then on an
// alternate joint, and else dropped with a note; never an error.
void KeepBuildable(const Character& character, AutoRig& out) {
  std::vector<RigPatch> kept;
  for (RigPatch& p : out.rig.patches) {
    Rig one = out.rig;
    one.patches = {p};
    base::Result<std::vector<deform::PatchSetup>> built = BuildRigPatches(one, character);
    if (!built.ok()) {
      RigPatch looser = p;
      looser.region.radius = Round2(1.5f * p.region.radius);
      looser.region.min_bone_weight = 0.25f;
      looser.region.half_angle_deg = std::min(p.region.half_angle_deg, 80.0f);
      one.patches = {looser};
      // An elastic patch keeps its size: widened ones jiggled into ridges on
      // Bandai's run; it moves to another joint instead.
      bool ok = !p.elastic && BuildRigPatches(one, character).ok();
      if (!ok && !p.elastic && looser.cylinder) {  // a limb too thin for a partial tube: a flat map
        looser.cylinder = false;
        one.patches = {looser};
        ok = BuildRigPatches(one, character).ok();
      }
      if (!ok && !p.elastic) {  // folds in the map: a smaller, flatter cap
        looser = p;
        looser.region.radius = Round2(0.7f * p.region.radius);
        looser.region.half_angle_deg = std::min(p.region.half_angle_deg, 50.0f);
        looser.cylinder = false;
        one.patches = {looser};
        ok = BuildRigPatches(one, character).ok();
      }
      for (const auto& [name, joint] : out.alternate_joints) {
        if (ok || name != p.name) continue;
        looser = p;
        looser.region.joint = joint;
        one.patches = {looser};
        ok = BuildRigPatches(one, character).ok();
      }
      if (ok) {
        out.notes.push_back(p.name + ": " +
                            (looser.region.joint != p.region.joint ? "on " + looser.region.joint
                                                                   : std::string("resized")) +
                            " (" + built.error().message + ")");
        p = looser;
      } else {
        out.notes.push_back(p.name + ": skipped (" + built.error().message + ")");
        continue;
      }
    }
    kept.push_back(p);
  }
  out.rig.patches = std::move(kept);
  // Messages name examples by their place in the rig, as a parsed rig does.
  for (std::size_t i = 0; i < out.rig.patches.size(); ++i) {
    std::vector<RigExample>& examples = out.rig.patches[i].examples;
    for (std::size_t k = 0; k < examples.size(); ++k) {
      examples[k].path = "patches[" + std::to_string(i) + "].examples[" + std::to_string(k) + "]";
    }
  }
}

}  // namespace

base::Result<AutoRig> BuildAutoRig(const Character& character, const std::string& character_name,
                                   const std::string& motion_file, const std::string& label) {
  base::Result<std::vector<glm::mat4>> bind = deform::BindModelFromJoint(character);
  if (!bind.ok()) return std::move(bind).error();
  AutoRig out;
  out.rig.file = label;
  out.rig.character = character_name;
  out.rig.motion = motion_file;
  out.rig.render.size = {1280, 720};
  const mocap::Skeleton& s = character.skeleton;
  base::Result<deform::Humanoid> h = deform::FindHumanoid(s, *bind);
  std::string why = h.ok() ? UprightProblem(*h) : h.error().message;
  if (!why.empty()) {
    PlaceNonHumanoid(s, *bind, why, out);
    KeepBuildable(character, out);
    return out;
  }
  const SampledPoses poses = SamplePoses(s, character.motion);
  for (int side = 0; side < 2; ++side) PlaceLimbs(s, *h, side, *bind, poses, out);
  PlaceTrunk(s, *h, out);
  KeepBuildable(character, out);
  return out;
}

base::Result<AutoRig> MakeAutoRig(const std::string& capture, const std::string& body,
                                  const std::string& up, bool quiet) {
  const base::Result<std::optional<mocap::UpAxis>> up_axis = ParseUpAxis(up);
  if (!up_axis.ok()) return up_axis.error();
  const std::string ext = std::filesystem::path(body).extension().string();
  const bool gltf = ext == ".glb" || ext == ".gltf";
  BodyKind kind = BodyKind::kGenerated;
  if (!gltf) {
    base::Result<BodyKind> parsed = ParseBodyKind(body);
    if (!parsed.ok()) return parsed.error();
    kind = *parsed;
  }
  base::Result<Character> ch =
      gltf ? LoadCommandCharacter(body, capture, quiet, *up_axis)
           : LoadCommandCharacter(capture, "", quiet, *up_axis, {}, nullptr, kind);
  if (!ch.ok()) return std::move(ch).error();
  const std::string name = gltf ? body : kind == BodyKind::kTubes ? "tubes" : "generated";
  base::Result<AutoRig> made = BuildAutoRig(*ch, name, capture, capture);
  // An up axis given for the capture is part of the rig: the rig is read the same way again.
  if (made.ok() && *up_axis) made->rig.up = *up_axis == mocap::UpAxis::kZ ? "z" : "y";
  return made;
}

base::Result<Rig> AutoRigForCommand(const std::string& layer, const std::string& input,
                                    const std::string& motion, const std::string& body,
                                    const std::string& up, bool quiet) {
  if (layer != "auto") {
    return base::InvalidArgument({"--layer", 0, 0, {}}, "expected auto, found '" + layer + "'");
  }
  if (std::filesystem::path(input).extension() == ".json") {
    return base::InvalidArgument({"--layer", 0, 0, {}},
                                 "expected a capture (BVH) as the input, found the rig file " +
                                     input + " (a rig names its own patches)");
  }
  const std::string ext = std::filesystem::path(input).extension().string();
  if (motion.empty() && (ext == ".glb" || ext == ".gltf")) {
    return base::InvalidArgument({"--layer", 0, 0, {}},
                                 "expected a BVH capture: give the glTF character's motion with "
                                 "--motion, or the capture as the input with --body " +
                                     input);
  }
  const std::string& capture = motion.empty() ? input : motion;
  base::Result<AutoRig> made = MakeAutoRig(capture, motion.empty() ? body : input, up, quiet);
  if (!made.ok()) return std::move(made).error();
  if (!quiet) {
    const std::string name = capture.empty() ? "demo" : capture;
    for (const std::string& note : made->notes) {
      std::fprintf(stderr, "%s: --layer auto: note: %s\n", name.c_str(), note.c_str());
    }
  }
  if (capture.empty()) made->rig.file = "demo";
  return std::move(made->rig);
}

}  // namespace app
