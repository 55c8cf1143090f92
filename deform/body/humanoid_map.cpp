#include "deform/body/humanoid_map.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>

#include <glm/gtc/quaternion.hpp>

#include "mocap/pose.h"

namespace deform {

using base::ErrorCode;
using base::MakeError;

namespace {

constexpr float kMinBranchExtent = 0.1f;   // fingers and toes fold into their limb
constexpr float kMirrorTolerance = 0.25f;  // left and right limb lengths, relative
constexpr int kCandidateFrames = 16;

glm::vec3 Pos(const BodyChains& c, int point) { return c.points[static_cast<std::size_t>(point)].pos; }

float ChainLength(const BodyChains& c, const std::vector<int>& pts) {
  float total = 0.0f;
  for (std::size_t k = 1; k < pts.size(); ++k) total += glm::distance(Pos(c, pts[k]), Pos(c, pts[k - 1]));
  return total;
}

glm::vec3 Across(glm::vec3 v, glm::vec3 axis) { return v - glm::dot(v, axis) * axis; }

// The wrist: where small side branches (fingers) fold in, else the last joint.
int WristIndex(const BodyChains& c, const BodyChain& chain) {
  if (chain.folded_branches && chain.first_folded > 0) return chain.first_folded;
  for (int k = static_cast<int>(chain.points.size()) - 1; k > 0; --k) {
    if (c.points[static_cast<std::size_t>(chain.points[static_cast<std::size_t>(k)])].joint >= 0) return k;
  }
  return static_cast<int>(chain.points.size()) - 1;
}

// The ankle: the point after the knee, where the two longest consecutive bones of
// the leg (thigh and shin) meet. Read from bone lengths only, so a lifted foot or
// a capture's odd rest pose changes nothing.
int AnkleIndex(const BodyChains& c, const std::vector<int>& pts) {
  int knee = 1;
  float best = -1.0f;
  for (std::size_t k = 1; k + 1 < pts.size(); ++k) {
    const float two = glm::distance(Pos(c, pts[k - 1]), Pos(c, pts[k])) +
                      glm::distance(Pos(c, pts[k]), Pos(c, pts[k + 1]));
    if (two > best) best = two, knee = static_cast<int>(k);
  }
  return knee + 1;
}

int ChainNameSide(const mocap::Skeleton& s, const BodyChains& c, const std::vector<int>& pts) {
  int score = 0;
  for (std::size_t k = 1; k < pts.size(); ++k) {
    const BodyPoint& p = c.points[static_cast<std::size_t>(pts[k])];
    const int j = p.joint >= 0 ? p.joint : p.bone_joint;
    if (j >= 0) score += NameSide(s.names[static_cast<std::size_t>(j)]);
  }
  return score;
}

// Mirror pairs of limb chains hanging from `spine_chain`, as (attachment index in the
// spine, chain a, chain b), lowest attachment first.
struct LimbPair {
  int at;
  int a, b;
};
std::vector<LimbPair> MirrorPairs(const BodyChains& c, int spine_chain) {
  const std::vector<int>& spine = c.chains[static_cast<std::size_t>(spine_chain)].points;
  std::vector<LimbPair> pairs;
  std::vector<bool> used(c.chains.size(), false);
  for (std::size_t a = 0; a < c.chains.size(); ++a) {
    const BodyChain& ca = c.chains[a];
    if (used[a] || ca.parent_chain != spine_chain || ca.kind != BodyChainKind::kLimb) continue;
    for (std::size_t b = a + 1; b < c.chains.size(); ++b) {
      const BodyChain& cb = c.chains[b];
      if (used[b] || cb.parent_chain != spine_chain || cb.points[0] != ca.points[0] ||
          cb.points.size() != ca.points.size()) {
        continue;
      }
      const float la = ChainLength(c, ca.points), lb = ChainLength(c, cb.points);
      if (std::abs(la - lb) > kMirrorTolerance * std::max(la, lb)) continue;
      const auto at = std::find(spine.begin(), spine.end(), ca.points[0]) - spine.begin();
      pairs.push_back({static_cast<int>(at), static_cast<int>(a), static_cast<int>(b)});
      used[a] = used[b] = true;
      break;
    }
  }
  std::sort(pairs.begin(), pairs.end(), [](const LimbPair& x, const LimbPair& y) { return x.at < y.at; });
  return pairs;
}

// Model matrices and world rotations of a pose: the rest pose, or a motion frame.
struct PoseState {
  std::vector<glm::mat4> model;
  std::vector<glm::quat> world;
};
base::Result<PoseState> EvaluatePose(const mocap::Skeleton& s, const mocap::Motion* motion,
                                     int frame) {
  std::vector<mocap::JointTransform> locals(static_cast<std::size_t>(s.num_joints()));
  PoseState out;
  out.model.resize(locals.size());
  out.world.resize(locals.size());
  base::JobStatus st;
  if (motion == nullptr) {
    mocap::RestPose(s, locals);
  } else {
    st = mocap::LocalPoseJob{&s, motion->frame(frame), locals}.Run();
  }
  if (st) st = mocap::LocalToModelJob{.parents = s.parents, .locals = locals, .model_from_joint = out.model}.Run();
  if (!st) {
    return MakeError(ErrorCode::kInternal, {s.info.source_file, 0, 0, {}},
                     std::string("matching skeletons: pose evaluation refused to run: ") + st.what);
  }
  for (std::size_t j = 0; j < locals.size(); ++j) {
    const int p = s.parents[j];
    out.world[j] = p < 0 ? locals[j].rotation : out.world[static_cast<std::size_t>(p)] * locals[j].rotation;
  }
  return out;
}

// The shortest-arc rotation taking unit direction `from` onto unit `to`.
glm::quat Swing(glm::vec3 from, glm::vec3 to) {
  const float d = glm::dot(from, to);
  if (d > 1.0f - 1e-6f) return glm::quat(1, 0, 0, 0);
  if (d < -1.0f + 1e-6f) {  // half turn about any axis across `from`
    glm::vec3 axis = glm::cross(from, glm::vec3(1, 0, 0));
    if (glm::dot(axis, axis) < 1e-6f) axis = glm::cross(from, glm::vec3(0, 1, 0));
    return glm::angleAxis(glm::pi<float>(), glm::normalize(axis));
  }
  const glm::vec3 axis = glm::cross(from, to);
  return glm::normalize(glm::quat(1.0f + d, axis.x, axis.y, axis.z));
}

// Rotation taking the body frame (up, forward) of `a` onto that of `b`.
glm::quat BodyTurn(const Humanoid& a, const Humanoid& b) {
  const glm::mat3 fa(a.left, a.up, a.forward), fb(b.left, b.up, b.forward);
  return glm::normalize(glm::quat_cast(fb * glm::transpose(fa)));
}

// Pelvis height above the lowest leg point, along up.
float PelvisHeight(const Humanoid& h) {
  const float pelvis = glm::dot(Pos(h.chains, h.spine[0]), h.up);
  float low = pelvis;
  for (const HumanoidLimb& leg : h.legs) {
    for (int p : leg.points) low = std::min(low, glm::dot(Pos(h.chains, p), h.up));
  }
  return pelvis - low;
}

// One target joint's match: its source joint and the bone directions to align
// (model space of each reference pose); `inherit` when it has no bone of its own.
struct JointMatch {
  int source = -1;
  glm::vec3 target_dir{0.0f}, source_dir{0.0f};
  bool inherit = true;
  bool pelvis = false;
};

class Matcher {
 public:
  Matcher(const Humanoid& t, const Humanoid& s, int num_target_joints)
      : t_(t), s_(s), match_(static_cast<std::size_t>(num_target_joints)) {}

  std::vector<JointMatch>& matches() { return match_; }

  // The joints sitting at two corresponding points; the bone directions are those
  // leaving the points along the chains (none at a chain's tip).
  void Anchor(const std::vector<int>& tp, int ti, const std::vector<int>& sp, int si) {
    const BodyPoint& a = t_.chains.points[static_cast<std::size_t>(tp[static_cast<std::size_t>(ti)])];
    const BodyPoint& b = s_.chains.points[static_cast<std::size_t>(sp[static_cast<std::size_t>(si)])];
    const int tj = a.joint;
    const int sj = b.joint >= 0 ? b.joint : b.bone_joint;
    if (tj < 0 || sj < 0 || match_[static_cast<std::size_t>(tj)].source >= 0) return;
    JointMatch& m = match_[static_cast<std::size_t>(tj)];
    m.source = sj;
    if (ti + 1 < static_cast<int>(tp.size()) && si + 1 < static_cast<int>(sp.size())) {
      m.target_dir = Dir(t_, tp, ti);
      m.source_dir = Dir(s_, sp, si);
      m.inherit = false;
    }
  }

  // Bones of target points [ta, tb] onto source points [sa, sb] by arc-length fraction.
  void Stretch(const std::vector<int>& tp, int ta, int tb, const std::vector<int>& sp, int sa, int sb) {
    if (tb <= ta || sb <= sa) return;
    const std::vector<float> tu = Fractions(t_, tp, ta, tb), su = Fractions(s_, sp, sa, sb);
    for (int k = ta; k < tb; ++k) {
      const int tj = t_.chains.points[static_cast<std::size_t>(tp[static_cast<std::size_t>(k + 1)])].bone_joint;
      if (tj < 0 || match_[static_cast<std::size_t>(tj)].source >= 0) continue;
      // The source bone overlapping the target bone's stretch the most (the first
      // covering its start when it has no length).
      const float u0 = tu[static_cast<std::size_t>(k - ta)], u1 = tu[static_cast<std::size_t>(k + 1 - ta)];
      int m = sa;
      while (m + 1 < sb && su[static_cast<std::size_t>(m + 1 - sa)] <= u0 + 1e-4f) ++m;
      float best = 0.0f;
      for (int i = sa; i < sb; ++i) {
        const float overlap = std::min(u1, su[static_cast<std::size_t>(i + 1 - sa)]) -
                              std::max(u0, su[static_cast<std::size_t>(i - sa)]);
        if (overlap > best + 1e-4f) best = overlap, m = i;
      }
      JointMatch& jm = match_[static_cast<std::size_t>(tj)];
      jm.source = s_.chains.points[static_cast<std::size_t>(sp[static_cast<std::size_t>(m + 1)])].bone_joint;
      jm.target_dir = Dir(t_, tp, k);
      jm.source_dir = Dir(s_, sp, m);
      jm.inherit = false;
    }
  }

  // A limb: stretches between attachment, shoulder/hip, elbow/knee, wrist/ankle, tip.
  void Limb(const HumanoidLimb& t, const HumanoidLimb& s) {
    const int tk[5] = {0, t.root, t.extremity - 1, t.extremity, static_cast<int>(t.points.size()) - 1};
    const int sk[5] = {0, s.root, s.extremity - 1, s.extremity, static_cast<int>(s.points.size()) - 1};
    for (int i = 1; i < 4; ++i) Anchor(t.points, tk[i], s.points, sk[i]);
    for (int i = 0; i < 4; ++i) Stretch(t.points, tk[i], tk[i + 1], s.points, sk[i], sk[i + 1]);
    Anchor(t.points, tk[4], s.points, sk[4]);
  }

 private:
  static glm::vec3 Dir(const Humanoid& h, const std::vector<int>& pts, int k) {
    const glm::vec3 d = Pos(h.chains, pts[static_cast<std::size_t>(k + 1)]) - Pos(h.chains, pts[static_cast<std::size_t>(k)]);
    const float len = glm::length(d);
    return len > 0.0f ? d / len : glm::vec3(0.0f);
  }
  static std::vector<float> Fractions(const Humanoid& h, const std::vector<int>& pts, int a, int b) {
    std::vector<float> u(static_cast<std::size_t>(b - a + 1), 0.0f);
    for (int k = a + 1; k <= b; ++k) {
      u[static_cast<std::size_t>(k - a)] = u[static_cast<std::size_t>(k - a - 1)] +
          glm::distance(Pos(h.chains, pts[static_cast<std::size_t>(k)]), Pos(h.chains, pts[static_cast<std::size_t>(k - 1)]));
    }
    const float total = u.back();
    for (float& x : u) x = total > 0.0f ? x / total : 0.0f;
    return u;
  }

  const Humanoid& t_;
  const Humanoid& s_;
  std::vector<JointMatch> match_;
};

// A joint's own bone in a pose: toward its first child at a distinct position.
bool OwnBone(const mocap::Skeleton& s, const std::vector<glm::mat4>& model, int j, glm::vec3& dir) {
  for (int c = j + 1; c < s.num_joints(); ++c) {
    if (s.parents[static_cast<std::size_t>(c)] != j) continue;
    const glm::vec3 d = glm::vec3(model[static_cast<std::size_t>(c)][3]) - glm::vec3(model[static_cast<std::size_t>(j)][3]);
    if (glm::length(d) > 1e-6f) {
      dir = glm::normalize(d);
      return true;
    }
  }
  return false;
}

}  // namespace

int NameSide(const std::string& name) {
  const std::string n = mocap::NormalizeJointName(name);
  if (n.find("left") != std::string::npos) return 1;
  if (n.find("right") != std::string::npos) return -1;
  std::string token;
  for (std::size_t i = 0; i <= n.size(); ++i) {
    if (i < n.size() && std::isalnum(static_cast<unsigned char>(n[i]))) {
      token += n[i];
      continue;
    }
    if (token == "l") return 1;
    if (token == "r") return -1;
    token.clear();
  }
  if (name.size() >= 2 && std::isupper(static_cast<unsigned char>(name[1]))) {
    if (name[0] == 'L') return 1;
    if (name[0] == 'R') return -1;
  }
  return 0;
}

base::Result<Humanoid> FindHumanoid(const mocap::Skeleton& skeleton,
                                    std::span<const glm::mat4> model_from_joint) {
  base::Result<BodyChains> built = BuildBodyChains(skeleton, model_from_joint, kMinBranchExtent);
  if (!built.ok()) return std::move(built).error();
  Humanoid h;
  h.chains = std::move(*built);
  const BodyChains& c = h.chains;
  const auto fail = [&skeleton](const std::string& what) {
    return base::InvalidArgument(
        {skeleton.info.source_file, 0, 0, {}},
        "expected a humanoid skeleton (a spine with a pair of legs and, above them, "
        "a pair of arms), found " +
            what);
  };
  int spine_chain = -1;
  std::vector<LimbPair> pairs;
  for (std::size_t i = 0; i < c.chains.size() && spine_chain < 0; ++i) {
    if (c.chains[i].kind != BodyChainKind::kSpine) continue;
    pairs = MirrorPairs(c, static_cast<int>(i));
    if (pairs.size() >= 2) spine_chain = static_cast<int>(i);
  }
  if (spine_chain < 0) return fail("fewer than two pairs of mirror limbs on the spine");
  h.spine = c.chains[static_cast<std::size_t>(spine_chain)].points;
  const LimbPair legs = pairs[0], arms = pairs[1];
  h.chest = arms.at;
  if (h.chest <= 0) return fail("the arms hanging from the pelvis");
  h.up = glm::normalize(Pos(c, h.spine[static_cast<std::size_t>(h.chest)]) - Pos(c, h.spine[0]));

  HumanoidLimb limb[4];  // legs a, b, arms a, b
  const int ids[4] = {legs.a, legs.b, arms.a, arms.b};
  for (int i = 0; i < 4; ++i) {
    const BodyChain& chain = c.chains[static_cast<std::size_t>(ids[i])];
    limb[i].points = chain.points;
    if (chain.points.size() < 3) return fail("a limb of fewer than two bones");
    limb[i].extremity = i < 2 ? AnkleIndex(c, chain.points) : WristIndex(c, chain);
    limb[i].extremity = std::max(limb[i].extremity, 2);
    limb[i].root = std::max(limb[i].extremity - 2, 0);
  }
  h.standing = true;
  for (int i = 0; i < 2; ++i) {
    const glm::vec3 leg = Pos(c, limb[i].points[static_cast<std::size_t>(limb[i].extremity)]) -
                          Pos(c, limb[i].points[static_cast<std::size_t>(limb[i].root)]);
    h.standing = h.standing && glm::dot(leg, h.up) < -0.5f * glm::length(leg);
  }

  // Forward from the feet; left = up x forward decides which limb is which.
  glm::vec3 feet(0.0f);
  float foot_length = 0.0f;
  for (int i = 0; i < 2; ++i) {
    const glm::vec3 ankle = Pos(c, limb[i].points[static_cast<std::size_t>(limb[i].extremity)]);
    const glm::vec3 tip = Pos(c, limb[i].points.back());
    feet += Across(tip - ankle, h.up);
    foot_length += glm::distance(tip, ankle);
  }
  const auto side_of = [&](const HumanoidLimb& a, const HumanoidLimb& b) {
    return glm::dot(Pos(c, a.points[static_cast<std::size_t>(a.root)]) -
                        Pos(c, b.points[static_cast<std::size_t>(b.root)]),
                    h.left);
  };
  bool swap_legs = false, swap_arms = false;
  if (foot_length > 0.0f && glm::length(feet) > 0.2f * foot_length) {
    h.forward = glm::normalize(feet);
    h.left = glm::normalize(glm::cross(h.up, h.forward));
    h.forward = glm::cross(h.left, h.up);
    h.sides = "geometry";
    swap_legs = side_of(limb[0], limb[1]) < 0.0f;
    swap_arms = side_of(limb[2], limb[3]) < 0.0f;
  } else {
    const int legs_named = ChainNameSide(skeleton, c, limb[0].points) - ChainNameSide(skeleton, c, limb[1].points);
    const int arms_named = ChainNameSide(skeleton, c, limb[2].points) - ChainNameSide(skeleton, c, limb[3].points);
    h.sides = legs_named != 0 && arms_named != 0 ? "names" : "guess";
    swap_legs = legs_named < 0;
    swap_arms = arms_named < 0;
    const HumanoidLimb& l = swap_legs ? limb[1] : limb[0];
    const HumanoidLimb& r = swap_legs ? limb[0] : limb[1];
    const glm::vec3 across = Across(Pos(c, l.points[static_cast<std::size_t>(l.root)]) -
                                        Pos(c, r.points[static_cast<std::size_t>(r.root)]), h.up);
    if (!(glm::length(across) > 0.0f)) return fail("legs that start at one point");
    h.left = glm::normalize(across);
    h.forward = glm::cross(h.left, h.up);
    if (h.sides == "names" && side_of(swap_arms ? limb[3] : limb[2], swap_arms ? limb[2] : limb[3]) < 0.0f) {
      h.sides = "guess";  // names that contradict the legs' sides
    }
  }
  h.legs[0] = limb[swap_legs ? 1 : 0];
  h.legs[1] = limb[swap_legs ? 0 : 1];
  h.arms[0] = limb[swap_arms ? 3 : 2];
  h.arms[1] = limb[swap_arms ? 2 : 3];
  // The feet gave the sides; the hips give the exact axes (a running frame's feet
  // point anywhere within 90 degrees of forward, the hip line stays across it).
  const glm::vec3 hips = Across(Pos(c, h.legs[0].points[static_cast<std::size_t>(h.legs[0].root)]) -
                                    Pos(c, h.legs[1].points[static_cast<std::size_t>(h.legs[1].root)]), h.up);
  if (glm::length(hips) > 0.0f) {
    h.left = glm::normalize(hips);
    h.forward = glm::cross(h.left, h.up);
  }
  return h;
}

base::Result<HumanoidMatch> MatchHumanoids(const mocap::Skeleton& target,
                                           const mocap::Skeleton& source,
                                           const mocap::Motion& source_motion,
                                           const JointMapEntries& joint_map,
                                           const std::string& target_file,
                                           const std::string& source_file,
                                           const std::string& joint_map_file) {
  HumanoidMatch out;
  const int nt = target.num_joints();
  base::Result<PoseState> target_rest = EvaluatePose(target, nullptr, 0);
  if (!target_rest.ok()) return std::move(target_rest).error();
  base::Result<PoseState> source_rest = EvaluatePose(source, nullptr, 0);
  if (!source_rest.ok()) return std::move(source_rest).error();
  base::Result<Humanoid> th = FindHumanoid(target, target_rest->model);

  // The source's reference pose: its rest pose if it stands, else a sampled frame.
  base::Result<Humanoid> sh = FindHumanoid(source, source_rest->model);
  PoseState source_ref = *source_rest;
  out.source_pose = "rest";
  if (th.ok() && sh.ok() && !sh->standing) {
    for (int i = 0; i < kCandidateFrames && source_motion.num_frames > 0; ++i) {
      const int f = static_cast<int>(static_cast<long long>(i) * source_motion.num_frames / kCandidateFrames);
      base::Result<PoseState> pose = EvaluatePose(source, &source_motion, f);
      if (!pose.ok()) return std::move(pose).error();
      base::Result<Humanoid> at = FindHumanoid(source, pose->model);
      if (at.ok() && at->standing) {
        sh = std::move(at);
        source_ref = std::move(*pose);
        out.source_pose = "frame " + std::to_string(f);
        break;
      }
    }
    if (out.source_pose == "rest") {
      out.warnings.push_back({{source_file, 0, 0, {}},
                              "no sampled pose of the motion stands on its legs; its rest pose "
                              "is aligned with the character's as it is"});
    }
  }

  std::vector<JointMatch> match(static_cast<std::size_t>(nt));
  glm::quat body_turn(1, 0, 0, 0);
  if (th.ok() && sh.ok()) {
    out.method = "topology";
    out.target_sides = th->sides;
    out.source_sides = sh->sides;
    Matcher m(*th, *sh, nt);
    const BodyPoint& tp = th->chains.points[static_cast<std::size_t>(th->spine[0])];
    const BodyPoint& sp = sh->chains.points[static_cast<std::size_t>(sh->spine[0])];
    JointMatch& pelvis = m.matches()[static_cast<std::size_t>(tp.joint)];
    pelvis.source = sp.joint;
    pelvis.pelvis = true;
    out.plan.target_root = tp.joint;
    out.plan.source_root = sp.joint;
    const int tn = static_cast<int>(th->spine.size()) - 1, sn = static_cast<int>(sh->spine.size()) - 1;
    m.Anchor(th->spine, th->chest, sh->spine, sh->chest);
    m.Stretch(th->spine, 0, th->chest, sh->spine, 0, sh->chest);
    m.Stretch(th->spine, th->chest, tn, sh->spine, sh->chest, sn);
    m.Anchor(th->spine, tn, sh->spine, sn);
    for (int side = 0; side < 2; ++side) {
      m.Limb(th->arms[side], sh->arms[side]);
      m.Limb(th->legs[side], sh->legs[side]);
    }
    match = std::move(m.matches());
    body_turn = BodyTurn(*th, *sh);
    const float source_height = PelvisHeight(*sh), target_height = PelvisHeight(*th);
    if (!(source_height > 0.0f) || !(target_height > 0.0f)) {
      return base::InvalidArgument(
          {source_height > 0.0f ? target_file : source_file, 0, 0, {}},
          "expected the pelvis above the feet to scale the root translation");
    }
    out.plan.translation_scale = target_height / source_height;
    for (const auto& [sides, file] : {std::pair{th->sides, target_file}, std::pair{sh->sides, source_file}}) {
      if (sides == "guess") {
        out.warnings.push_back({{file, 0, 0, {}},
                                "left and right could not be told from the feet or the joint "
                                "names; the limbs' order in the file was taken (use --joint-map "
                                "to fix it)"});
      }
    }
  } else {
    base::Result<mocap::RetargetPlan> by_name =
        mocap::PlanByName(target, source, target_file, source_file, &out.warnings);
    if (!by_name.ok()) {
      base::Error e = std::move(by_name).error();
      e.message += "; nor could the skeletons be matched by body topology: " +
                   (th.ok() ? sh.error() : th.error()).message;
      return e;
    }
    out.method = "names";
    out.plan = std::move(*by_name);
    for (int j = 0; j < nt; ++j) match[static_cast<std::size_t>(j)].source = out.plan.source_of_target[static_cast<std::size_t>(j)];
  }

  // The user's overrides, each aligned along its joint's own bone.
  for (const auto& [target_name, source_name] : joint_map) {
    const int tj = target.FindJoint(target_name);
    const int sj = source_name.empty() ? -1 : source.FindJoint(source_name);
    if (tj < 0 || (!source_name.empty() && sj < 0)) {
      const bool bad_target = tj < 0;
      return base::InvalidArgument({joint_map_file, 0, 0, {}},
                                   "expected joint map entries naming a joint of " +
                                       (bad_target ? target_file : source_file) + ", found \"" +
                                       (bad_target ? target_name : source_name) + "\"");
    }
    JointMatch& jm = match[static_cast<std::size_t>(tj)];
    jm = {};
    jm.source = sj;
    if (sj >= 0 && out.method == "topology") {
      jm.inherit = !(OwnBone(target, target_rest->model, tj, jm.target_dir) &&
                     OwnBone(source, source_ref.model, sj, jm.source_dir));
    }
  }
  if (out.plan.target_root >= 0 && match[static_cast<std::size_t>(out.plan.target_root)].source < 0) {
    return base::InvalidArgument({joint_map.empty() ? source_file : joint_map_file, 0, 0, {}},
                                 "expected the character's root joint '" +
                                     target.names[static_cast<std::size_t>(out.plan.target_root)] +
                                     "' to be driven by the motion, found it left at rest");
  }

  // Per-bone rest alignment (topology only; names keep the documented identity).
  out.plan.source_of_target.assign(static_cast<std::size_t>(nt), -1);
  for (int j = 0; j < nt; ++j) out.plan.source_of_target[static_cast<std::size_t>(j)] = match[static_cast<std::size_t>(j)].source;
  if (out.method != "topology") return out;
  std::vector<glm::quat> turn(static_cast<std::size_t>(nt), body_turn);  // Q_j
  out.plan.align.assign(static_cast<std::size_t>(nt), glm::quat(1, 0, 0, 0));
  for (int j = 0; j < nt; ++j) {
    const auto ju = static_cast<std::size_t>(j);
    const int p = target.parents[ju];
    const JointMatch& jm = match[ju];
    if (jm.pelvis || jm.source < 0) {
      turn[ju] = p >= 0 && !jm.pelvis ? turn[static_cast<std::size_t>(p)] : body_turn;
    } else if (jm.inherit) {
      turn[ju] = p >= 0 ? turn[static_cast<std::size_t>(p)] : body_turn;
    } else {
      turn[ju] = Swing(glm::normalize(body_turn * jm.target_dir), jm.source_dir) * body_turn;
    }
    if (jm.source < 0) continue;
    const auto b = static_cast<std::size_t>(jm.source);
    out.plan.align[ju] = glm::normalize(source_rest->world[b] * glm::inverse(source_ref.world[b]) * turn[ju]);
  }
  return out;
}

}  // namespace deform
