#include "deform/body/body_chains.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "deform/mesh.h"
#include "mocap/channel_use.h"

namespace deform {

using base::ErrorCode;
using base::MakeError;

namespace {
constexpr float kMergeFraction = 1e-4f;
// Two subtrees whose total bone lengths differ by less than this fraction (of the
// longer) can be a mirror pair; captured left and right limbs differ by a few percent.
constexpr float kMirrorLengthTolerance = 0.2f;

// Total bone length of the subtree under `child`, including the bone into it.
float SubtreeLength(const std::vector<BodyPoint>& pts, int child) {
  float total = 0.0f;
  std::vector<int> stack = {child};
  while (!stack.empty()) {
    const BodyPoint& p = pts[static_cast<std::size_t>(stack.back())];
    stack.pop_back();
    total += glm::distance(p.pos, pts[static_cast<std::size_t>(p.parent)].pos);
    for (int g : p.children) stack.push_back(g);
  }
  return total;
}

// Per child of one point: 1 when it belongs to a mirror pair, a sibling whose subtree has
// as many points and about the same total bone length (left and right arm or leg). A
// pose-independent test: it reads bone lengths and topology only, never directions, so
// arms raised beside the head or legs lying along the spine in a rest pose change
// nothing. When every child is paired (a fork into two equal halves) none is marked.
std::vector<std::uint8_t> MirrorPaired(const std::vector<BodyPoint>& pts,
                                       const std::vector<int>& children) {
  const std::size_t n = children.size();
  std::vector<std::uint8_t> paired(n, 0);
  std::vector<float> length(n);
  for (std::size_t i = 0; i < n; ++i) length[i] = SubtreeLength(pts, children[i]);
  for (std::size_t a = 0; a < n; ++a) {
    for (std::size_t b = a + 1; b < n; ++b) {
      const BodyPoint& pa = pts[static_cast<std::size_t>(children[a])];
      const BodyPoint& pb = pts[static_cast<std::size_t>(children[b])];
      const float longer = std::max(length[a], length[b]);
      if (pa.descendants == pb.descendants &&
          std::abs(length[a] - length[b]) <= kMirrorLengthTolerance * longer) {
        paired[a] = paired[b] = 1;
      }
    }
  }
  if (std::find(paired.begin(), paired.end(), std::uint8_t{0}) == paired.end()) {
    std::fill(paired.begin(), paired.end(), std::uint8_t{0});
  }
  return paired;
}

// True when a joint has channels and none of them rotates it.
bool MovesOnly(const mocap::JointChannels& channels) {
  if (channels.count == 0) return false;  // not animated at all (a glTF node, a test skeleton)
  for (std::size_t k = 0; k < channels.count; ++k) {
    switch (channels.types[k]) {
      case mocap::ChannelType::kXPosition:
      case mocap::ChannelType::kYPosition:
      case mocap::ChannelType::kZPosition:
        break;
      default:
        return false;
    }
  }
  return true;
}

// A link longer than this many times the body's reach is no bone of it.
constexpr float kFarLinkReaches = 1.5f;

// The child of `p` with the most descendants (the first on ties), or -1.
int HeaviestChild(const std::vector<BodyPoint>& pts, int p) {
  int heavy = -1;
  for (int c : pts[static_cast<std::size_t>(p)].children) {
    if (heavy < 0 || pts[static_cast<std::size_t>(c)].descendants > pts[static_cast<std::size_t>(heavy)].descendants) {
      heavy = c;
    }
  }
  return heavy;
}

// Length of the path from `top` down the heaviest child at each point: about
// the body's reach from its spine's start (the spine and an arm, for a
// humanoid), whatever the pose.
float HeavyPathLength(const std::vector<BodyPoint>& pts, int top) {
  float length = 0.0f;
  for (int p = top, heavy = HeaviestChild(pts, p); heavy >= 0; p = heavy, heavy = HeaviestChild(pts, p)) {
    length += glm::distance(pts[static_cast<std::size_t>(p)].pos, pts[static_cast<std::size_t>(heavy)].pos);
  }
  return length;
}

// What each point's link to its parent point is, from the motion's use of the
// channels (Skeleton::channel_use; without it, channels only say whether a
// joint can rotate at all).
struct LinkRoles {
  // The point's joints only position the body: position channels alone, or
  // rotation channels that never change (a "World" or "Reference" node).
  std::vector<std::uint8_t> position_only;
  // The motion moves the point away from its parent point by position channels:
  // a positioning link (hips walking away from a root on the floor, an IK target).
  std::vector<std::uint8_t> pulled;
};

LinkRoles FindLinkRoles(const mocap::Skeleton& skeleton, const std::vector<BodyPoint>& pts,
                        const std::vector<int>& point_of) {
  const int nj = skeleton.num_joints();
  const bool known = skeleton.channel_use.size() == static_cast<std::size_t>(nj);
  const auto use = [&](int j) {
    return known ? skeleton.channel_use[static_cast<std::size_t>(j)] : std::uint8_t{mocap::kJointRotates};
  };
  LinkRoles roles{std::vector<std::uint8_t>(pts.size(), 1), std::vector<std::uint8_t>(pts.size(), 0)};
  for (int j = 0; j < nj; ++j) {
    const mocap::JointChannels* ch =
        static_cast<std::size_t>(j) < skeleton.channels.size() ? &skeleton.channels[static_cast<std::size_t>(j)] : nullptr;
    const bool positions = ch != nullptr && (MovesOnly(*ch) || (ch->count > 0 && (use(j) & mocap::kJointRotates) == 0));
    if (!positions) roles.position_only[static_cast<std::size_t>(point_of[static_cast<std::size_t>(j)])] = 0;
  }
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (pts[i].parent < 0) continue;
    // Every joint between the parent point's and this one (merged joints
    // included) can pull the link.
    const int stop = pts[static_cast<std::size_t>(pts[i].parent)].joint;
    for (int j = pts[i].joint >= 0 ? pts[i].joint : pts[i].bone_joint; j >= 0 && j != stop;
         j = skeleton.parents[static_cast<std::size_t>(j)]) {
      if ((use(j) & mocap::kJointStretches) != 0) roles.pulled[i] = 1;
    }
  }
  return roles;
}

// A root on the floor under the body it holds: at or below every point of its
// subtree (within 5 % of the subtree's height), its heavy child straight above
// it, and that child carrying at least three quarters of the subtree (so a
// root with the legs hanging from it is not one).
bool IsFloorAnchor(const std::vector<BodyPoint>& pts, int root, int heavy, const glm::vec3& up) {
  const BodyPoint& r = pts[static_cast<std::size_t>(root)];
  if (4 * (pts[static_cast<std::size_t>(heavy)].descendants + 1) < 3 * r.descendants) return false;
  float lo = std::numeric_limits<float>::max(), hi = std::numeric_limits<float>::lowest();
  std::vector<int> stack(r.children.begin(), r.children.end());
  while (!stack.empty()) {
    const BodyPoint& p = pts[static_cast<std::size_t>(stack.back())];
    stack.pop_back();
    lo = std::min(lo, glm::dot(p.pos, up));
    hi = std::max(hi, glm::dot(p.pos, up));
    stack.insert(stack.end(), p.children.begin(), p.children.end());
  }
  const float height = glm::dot(r.pos, up);
  const glm::vec3 link = pts[static_cast<std::size_t>(heavy)].pos - r.pos;
  const bool upright = glm::dot(link, up) > 0.87f * glm::length(link);  // within 30 degrees
  return hi > lo && height <= lo + 0.05f * (hi - lo) && upright;
}

}  // namespace

base::Result<BodyChains> BuildBodyChains(const mocap::Skeleton& skeleton,
                                         std::span<const glm::mat4> rest_model_from_joint,
                                         float min_branch_extent) {
  const int nj = skeleton.num_joints();
  if (rest_model_from_joint.size() != static_cast<std::size_t>(nj)) {
    return MakeError(ErrorCode::kCountMismatch, {},
                     "mannequin needs one rest matrix per joint: expected " + std::to_string(nj) +
                         ", found " + std::to_string(rest_model_from_joint.size()));
  }
  if (nj == 0) return base::InvalidArgument("skeleton has no joints");
  std::vector<glm::vec3> joint_pos(static_cast<std::size_t>(nj));
  Bounds bounds;
  for (int j = 0; j < nj; ++j) {
    const int p = skeleton.parents[static_cast<std::size_t>(j)];
    if (p < mocap::kNoParent || p >= j) {
      return base::InvalidArgument("joint " + std::to_string(j) + " has parent " +
                                   std::to_string(p) + ", expected a parent listed before it");
    }
    const glm::mat4& m = rest_model_from_joint[static_cast<std::size_t>(j)];
    for (int c = 0; c < 4; ++c) {
      for (int r = 0; r < 4; ++r) {
        if (!std::isfinite(m[c][r])) {
          return MakeError(ErrorCode::kNonFinite, {},
                           "rest matrix of joint '" + skeleton.names[static_cast<std::size_t>(j)] +
                               "' is not finite");
        }
      }
    }
    joint_pos[static_cast<std::size_t>(j)] = glm::vec3(m[3]);
    bounds.Extend(glm::vec3(m[3]));
  }
  std::vector<std::pair<int, glm::vec3>> end_sites;  // parent joint, model position
  for (const mocap::EndSite& e : skeleton.end_sites) {
    if (e.parent < 0 || e.parent >= nj) continue;
    const glm::vec3 p(rest_model_from_joint[static_cast<std::size_t>(e.parent)] *
                      glm::vec4(e.offset, 1.0f));
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
    end_sites.emplace_back(e.parent, p);
    bounds.Extend(p);
  }
  const glm::vec3 extent = bounds.size();
  const float raw_size = std::max({extent.x, extent.y, extent.z});
  if (!(raw_size > 0.0f) || !std::isfinite(raw_size)) {
    return base::InvalidArgument(
        "skeleton has no bone of non-zero length (all joints at one point); "
        "cannot build a mannequin");
  }
  const float merge_dist = kMergeFraction * raw_size;

  // 1. The point tree without zero-length bones.
  BodyChains out;
  std::vector<BodyPoint>& pts = out.points;
  std::vector<int> point_of(static_cast<std::size_t>(nj), -1);
  const auto add_point = [&pts](const glm::vec3& pos, int parent, int joint, int bone_joint) {
    BodyPoint pt;
    pt.pos = pos;
    pt.parent = parent;
    pt.joint = joint;
    pt.bone_joint = bone_joint;
    pts.push_back(pt);
    const int id = static_cast<int>(pts.size()) - 1;
    if (parent >= 0) pts[static_cast<std::size_t>(parent)].children.push_back(id);
    return id;
  };
  for (int j = 0; j < nj; ++j) {
    const int p = skeleton.parents[static_cast<std::size_t>(j)];
    const glm::vec3 pos = joint_pos[static_cast<std::size_t>(j)];
    if (p < 0) {
      point_of[static_cast<std::size_t>(j)] = add_point(pos, -1, j, j);
      continue;
    }
    const int pp = point_of[static_cast<std::size_t>(p)];
    point_of[static_cast<std::size_t>(j)] =
        glm::distance(pos, pts[static_cast<std::size_t>(pp)].pos) <= merge_dist
            ? pp
            : add_point(pos, pp, j, p);
  }
  for (const auto& [parent_joint, pos] : end_sites) {
    const int pp = point_of[static_cast<std::size_t>(parent_joint)];
    if (glm::distance(pos, pts[static_cast<std::size_t>(pp)].pos) > merge_dist) {
      add_point(pos, pp, -1, parent_joint);
    }
  }
  for (std::size_t i = pts.size(); i-- > 0;) {  // children come after their parents
    if (pts[i].parent >= 0) {
      pts[static_cast<std::size_t>(pts[i].parent)].descendants += pts[i].descendants + 1;
    }
  }
  const auto pos_of = [&pts](int i) { return pts[static_cast<std::size_t>(i)].pos; };
  const auto reach = [&](int from, int child) {  // farthest point of child's subtree from `from`
    float best = 0.0f;
    std::vector<int> stack = {child};
    while (!stack.empty()) {
      const int c = stack.back();
      stack.pop_back();
      best = std::max(best, glm::distance(pos_of(from), pos_of(c)));
      for (int g : pts[static_cast<std::size_t>(c)].children) stack.push_back(g);
    }
    return best;
  };

  // 2. Chains by topology.
  struct Pending {
    int start, first, parent_chain;
    BodyChainKind kind;
  };
  LinkRoles roles = FindLinkRoles(skeleton, pts, point_of);
  const std::vector<std::uint8_t>& position_only = roles.position_only;
  std::vector<std::uint8_t>& pulled = roles.pulled;
  const auto only_child = [&pts](int p) {
    const std::vector<int>& c = pts[static_cast<std::size_t>(p)].children;
    return c.size() == 1 ? c[0] : -1;
  };
  const auto leads_to_branch = [&](int p) {  // a single-child path from p ends in a branch
    while (only_child(p) >= 0) p = only_child(p);
    return pts[static_cast<std::size_t>(p)].children.size() >= 2;
  };
  const glm::vec3 up = skeleton.info.up_axis == mocap::UpAxis::kZ ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
  std::vector<Pending> todo;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (pts[i].parent >= 0) continue;
    int r = static_cast<int>(i);
    // A root that only positions the body is skipped: one whose only child
    // branches (Bandai's joint_Root on the floor), one moved by position
    // channels alone above a body that branches further down, one the motion
    // pulls the body away from, or one on the floor under the body.
    for (int c = HeaviestChild(pts, r); c >= 0; c = HeaviestChild(pts, r)) {
      const bool single = only_child(r) >= 0;
      const bool child_branches = single && pts[static_cast<std::size_t>(c)].children.size() >= 2;
      const bool carries_body = single && position_only[static_cast<std::size_t>(r)] != 0 && leads_to_branch(c);
      if (!child_branches && !carries_body && pulled[static_cast<std::size_t>(c)] == 0 &&
          !IsFloorAnchor(pts, r, c, up)) {
        break;
      }
      r = c;
    }
    if (pts[static_cast<std::size_t>(r)].children.empty()) continue;
    todo.push_back({r, HeaviestChild(pts, r), -1, BodyChainKind::kSpine});
  }
  // A link far longer than the body reaches (the heaviest path from a spine's
  // start) ends nowhere near the body: a camera or prop joint parked metres
  // away. It is passed over as a pulled one is.
  float body_reach = 0.0f;
  for (const Pending& spine : todo) body_reach = std::max(body_reach, HeavyPathLength(pts, spine.start));
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (pts[i].parent >= 0 && glm::distance(pts[i].pos, pos_of(pts[i].parent)) > kFarLinkReaches * body_reach) {
      pulled[i] = 1;
    }
  }
  // Body size S over the points that make up the body: a positioning root
  // (often left at the origin while the capture walks away) must not count.
  Bounds body;
  for (const Pending& spine : todo) {
    std::vector<int> stack = {spine.start};
    while (!stack.empty()) {
      const int c = stack.back();
      stack.pop_back();
      body.Extend(pos_of(c));
      for (int g : pts[static_cast<std::size_t>(c)].children) {
        if (pulled[static_cast<std::size_t>(g)] == 0) stack.push_back(g);
      }
    }
  }
  const float size = body.empty() ? 0.0f : std::max({body.size().x, body.size().y, body.size().z});
  // The joints of the points at or below a spine's start get body parts; the
  // roots passed over above only position the body, and what the motion pulls
  // away from the body (IK targets, props) is no part of it.
  std::vector<std::uint8_t> body_point(pts.size(), 0);
  for (const Pending& spine : todo) body_point[static_cast<std::size_t>(spine.start)] = 1;
  for (std::size_t i = 0; i < pts.size(); ++i) {  // parents come before their children
    const int p = pts[i].parent;
    if (p >= 0 && body_point[static_cast<std::size_t>(p)] != 0 && pulled[i] == 0) body_point[i] = 1;
  }
  out.body_part_joints.assign(static_cast<std::size_t>(nj), 0);
  for (int j = 0; j < nj; ++j) {
    out.body_part_joints[static_cast<std::size_t>(j)] =
        body_point[static_cast<std::size_t>(point_of[static_cast<std::size_t>(j)])];
  }
  if (!(size > merge_dist)) {
    return base::InvalidArgument(
        "skeleton has no bone of non-zero length; cannot build a mannequin");
  }
  std::vector<BodyChain>& chains = out.chains;
  for (std::size_t t = 0; t < todo.size(); ++t) {
    const Pending job = todo[t];
    BodyChain c;
    c.kind = job.kind;
    c.parent_chain = job.parent_chain;
    c.points = {job.start, job.first};
    const int chain_id = static_cast<int>(chains.size());
    int cur = job.first;
    glm::vec3 dir = glm::normalize(pos_of(job.first) - pos_of(job.start));
    // Children the motion pulls away start no chain.
    const auto body_children = [&](int p) {
      std::vector<int> kept;
      for (int k : pts[static_cast<std::size_t>(p)].children) {
        if (pulled[static_cast<std::size_t>(k)] == 0) kept.push_back(k);
      }
      return kept;
    };
    if (job.kind == BodyChainKind::kSpine) {  // siblings of the spine's first bone hang from the root
      for (int s : body_children(job.start)) {
        if (s != job.first) todo.push_back({job.start, s, chain_id, BodyChainKind::kLimb});
      }
    }
    for (std::vector<int> ch = body_children(cur); !ch.empty(); ch = body_children(cur)) {
      // A spine never continues into one of a mirror pair (arms, legs): mocapbank's
      // collars and neck all start at one point, and the straightest of them was an arm.
      const std::vector<std::uint8_t> paired = job.kind == BodyChainKind::kSpine
                                                   ? MirrorPaired(pts, ch)
                                                   : std::vector<std::uint8_t>(ch.size(), 0);
      int best = ch[0];
      float best_dot = -2.0f;
      for (std::size_t i = 0; i < ch.size(); ++i) {
        const int k = ch[i];
        if (paired[i] != 0) continue;
        const float d = glm::dot(glm::normalize(pos_of(k) - pos_of(cur)), dir);
        if (d > best_dot) best_dot = d, best = k;
      }
      for (int k : ch) {
        if (k == best) continue;
        if (reach(cur, k) < min_branch_extent * size) {
          if (!c.folded_branches) c.first_folded = static_cast<int>(c.points.size()) - 1;
          c.folded_branches = true;
        } else {
          todo.push_back({cur, k, chain_id, BodyChainKind::kLimb});
        }
      }
      dir = glm::normalize(pos_of(best) - pos_of(cur));
      c.points.push_back(best);
      cur = best;
    }
    chains.push_back(std::move(c));
  }
  if (chains.empty()) {
    return base::InvalidArgument(
        "skeleton has no bone of non-zero length; cannot build a mannequin");
  }

  out.size = size;
  return out;
}

base::Result<std::vector<std::uint8_t>> BodyPartJoints(
    const mocap::Skeleton& skeleton, std::span<const glm::mat4> rest_model_from_joint,
    float min_branch_extent) {
  base::Result<BodyChains> chains =
      BuildBodyChains(skeleton, rest_model_from_joint, min_branch_extent);
  if (!chains.ok()) return std::move(chains).error();
  return std::move(chains->body_part_joints);
}

}  // namespace deform
