#include "deform/body/implicit_body.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "deform/body/body_chains.h"

namespace deform {
namespace {

using base::ErrorCode;
using base::MakeError;

constexpr int kMaxPrimitives = 4096;
constexpr int kCellsPerAxis = 32;
constexpr float kTorsoRadius = 0.085f;  // generic trunk radius, in body sizes S
constexpr float kMinRadius = 0.012f;
constexpr int kFirstLoneGroup = 1 << 20;  // groups of single parts, after the chains'    // thinnest part, in S: two voxels of the mesher

glm::vec3 Perpendicular(const glm::vec3& axis, const glm::vec3& hint) {
  glm::vec3 v = hint - glm::dot(hint, axis) * axis;
  if (glm::length(v) < 1e-4f * std::max(glm::length(hint), 1e-20f)) {
    v = std::abs(axis.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
    v -= glm::dot(v, axis) * axis;
  }
  return glm::normalize(v);
}

// The frame (along, side, third) of an ellipsoid whose first axis is `along` and second
// lies as close as possible to `side_hint`.
glm::mat3 Frame(const glm::vec3& along, const glm::vec3& side_hint) {
  const glm::vec3 a = glm::normalize(along);
  const glm::vec3 s = Perpendicular(a, side_hint);
  return glm::mat3(a, s, glm::cross(a, s));
}

// Builds the primitives of one body while keeping their bounds.
class PrimitiveList {
 public:
  explicit PrimitiveList(float min_radius, float scale) : min_radius_(min_radius), scale_(scale) {}

  // Round cones of one chain share `group`; ellipsoids each get a group of their own.
  void Cone(int group, const glm::vec3& a, const glm::vec3& b, float r0, float r1) {
    BodyPrimitive p;
    p.group = group;
    p.kind = BodyPrimitiveKind::kRoundCone;
    p.a = a;
    p.b = b;
    p.r0 = std::max(r0 * scale_, min_radius_);
    p.r1 = std::max(r1 * scale_, min_radius_);
    p.thickness = std::min(p.r0, p.r1);
    p.box_min = glm::min(a - p.r0, b - p.r1);
    p.box_max = glm::max(a + p.r0, b + p.r1);
    list.push_back(p);
  }

  // Semi-axes radii along the columns of `frame` (orthonormal).
  void Ellipsoid(const glm::vec3& centre, const glm::mat3& frame, glm::vec3 radii) {
    BodyPrimitive p;
    p.kind = BodyPrimitiveKind::kEllipsoid;
    p.group = kFirstLoneGroup + static_cast<int>(list.size());
    p.a = p.b = centre;
    p.axes = frame;
    p.radii = glm::max(radii * scale_, glm::vec3(min_radius_));
    p.thickness = std::min({p.radii.x, p.radii.y, p.radii.z});
    glm::vec3 half(0.0f);
    for (int i = 0; i < 3; ++i) half += glm::abs(frame[i]) * p.radii[i];
    p.box_min = centre - half;
    p.box_max = centre + half;
    list.push_back(p);
  }

  std::vector<BodyPrimitive> list;

 private:
  float min_radius_;
  float scale_;
};

// Index of the elbow/knee in a limb chain: the interior point whose shorter bone is the
// longest, not counting the chain's first interior point when a later one exists (the
// clavicle or pelvis-to-hip bone before the shoulder or hip).
int LimbMiddle(const std::vector<glm::vec3>& p) {
  const int n = static_cast<int>(p.size());
  if (n < 3) return -1;
  int best = -1;
  float best_len = -1.0f;
  for (int k = n >= 4 ? 2 : 1; k + 1 < n; ++k) {
    const float shorter = std::min(glm::distance(p[static_cast<std::size_t>(k - 1)], p[static_cast<std::size_t>(k)]),
                                   glm::distance(p[static_cast<std::size_t>(k)], p[static_cast<std::size_t>(k + 1)]));
    if (shorter > best_len) best_len = shorter, best = k;
  }
  return best;
}

struct Limb {
  int chain = -1;
  int middle = -1;              // elbow/knee index in the chain
  std::vector<glm::vec3> p;     // chain point positions
  glm::vec3 root() const { return p[static_cast<std::size_t>(middle - 1)]; }  // hip/shoulder
  glm::vec3 mid() const { return p[static_cast<std::size_t>(middle)]; }       // knee/elbow
  glm::vec3 end() const { return p[static_cast<std::size_t>(middle + 1)]; }   // ankle/wrist
  float upper() const { return glm::distance(root(), mid()); }
  float lower() const { return glm::distance(mid(), end()); }
};

float ArcLength(const std::vector<glm::vec3>& p) {
  float total = 0.0f;
  for (std::size_t i = 1; i < p.size(); ++i) total += glm::distance(p[i - 1], p[i]);
  return total;
}

// The two limbs of `candidates` forming the most similar pair of lengths within 25 %,
// or none.
bool PickPair(const std::vector<Limb>& candidates, Limb& a, Limb& b) {
  float best = 0.25f;
  bool found = false;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    for (std::size_t j = i + 1; j < candidates.size(); ++j) {
      const float li = ArcLength(candidates[i].p), lj = ArcLength(candidates[j].p);
      const float diff = std::abs(li - lj) / std::max({li, lj, 1e-20f});
      if (diff < best) best = diff, a = candidates[i], b = candidates[j], found = true;
    }
  }
  return found;
}

}  // namespace

float SmoothMin(float a, float b, float k) {
  if (!(k > 0.0f)) return std::min(a, b);
  const float h = std::max(k - std::abs(a - b), 0.0f) / k;
  return std::min(a, b) - 0.25f * h * h * k;
}

float PrimitiveDistance(const BodyPrimitive& s, const glm::vec3& p) {
  if (s.kind == BodyPrimitiveKind::kEllipsoid) {
    // Distance bound of an ellipsoid: k0 (k0 - 1) / k1 with k0 = |q/r|, k1 = |q/r^2|,
    // q in the ellipsoid's frame; exact on the surface's axes, never far off near it.
    const glm::vec3 q = glm::transpose(s.axes) * (p - s.a);
    const float k0 = glm::length(q / s.radii);
    const float k1 = glm::length(q / (s.radii * s.radii));
    if (k1 < 1e-20f) return -std::min({s.radii.x, s.radii.y, s.radii.z});
    return k0 * (k0 - 1.0f) / k1;
  }
  // Round cone in its axial plane: y along a -> b, x radial. The straight side touches
  // both spheres where its outward normal is n = (cos t, sin t), sin t = (r0 - r1) / L;
  // along the side's direction u = (-sin t, cos t) the touching points sit at 0 and
  // L cos t, so the projection on u says which part (sphere a, side, sphere b) is nearest.
  const glm::vec3 ab = s.b - s.a;
  const float len = glm::length(ab);
  const glm::vec3 ap = p - s.a;
  if (len <= std::abs(s.r0 - s.r1)) {  // one sphere holds the other
    return s.r0 >= s.r1 ? glm::length(ap) - s.r0 : glm::length(p - s.b) - s.r1;
  }
  const glm::vec3 axis = ab / len;
  const float y = glm::dot(ap, axis);
  const float x = std::sqrt(std::max(glm::dot(ap, ap) - y * y, 0.0f));
  const float sin_t = (s.r0 - s.r1) / len;
  const float cos_t = std::sqrt(std::max(1.0f - sin_t * sin_t, 0.0f));
  const float along_side = -x * sin_t + y * cos_t;
  if (along_side < 0.0f) return glm::length(ap) - s.r0;
  if (along_side > len * cos_t) return glm::length(p - s.b) - s.r1;
  return x * cos_t + y * sin_t - s.r0;
}

float ImplicitBody::Distance(const glm::vec3& p) const {
  const glm::vec3 rel = (p - box_min_) / cell_size_;
  const glm::vec3 outside = glm::max(glm::max(box_min_ - p, p - box_max_), glm::vec3(0.0f));
  if (rel.x < 0.0f || rel.y < 0.0f || rel.z < 0.0f || rel.x >= static_cast<float>(cells_.x) ||
      rel.y >= static_cast<float>(cells_.y) || rel.z >= static_cast<float>(cells_.z)) {
    return std::max(margin_, glm::length(outside));
  }
  const glm::ivec3 c(rel);
  const int cell = (c.z * cells_.y + c.y) * cells_.x + c.x;
  constexpr float kFar = std::numeric_limits<float>::max();
  float d = kFar, thick = 0.0f;      // the union so far and its carried thickness
  float group_d = kFar, group_thick = 0.0f;
  int group = -1;
  const auto add_group = [&] {
    if (group_d == kFar) return;
    if (d == kFar) {
      d = group_d, thick = group_thick;
      return;
    }
    // The blend radius follows the thinner part; the thickness carried on moves
    // smoothly to the nearer part across the blend, so the field has no jumps.
    const float k = blend_ * std::min(thick, group_thick);
    const float nearer = k > 0.0f ? std::clamp(0.5f + 0.5f * (d - group_d) / k, 0.0f, 1.0f) : (group_d < d ? 1.0f : 0.0f);
    thick += nearer * (group_thick - thick);
    d = SmoothMin(d, group_d, k);
  };
  for (int i = cell_begin_[static_cast<std::size_t>(cell)]; i < cell_begin_[static_cast<std::size_t>(cell) + 1]; ++i) {
    const BodyPrimitive& s = primitives_[static_cast<std::size_t>(cell_items_[static_cast<std::size_t>(i)])];
    if (s.group != group) {  // groups are contiguous in the list
      add_group();
      group = s.group, group_d = kFar, group_thick = s.group_thickness;
    }
    group_d = std::min(group_d, PrimitiveDistance(s, p));
  }
  add_group();
  return std::min(d, margin_);
}

void ImplicitBody::BuildCells() {
  box_min_ = glm::vec3(std::numeric_limits<float>::max());
  box_max_ = glm::vec3(-std::numeric_limits<float>::max());
  max_blend_ = 0.0f;
  // Groups contiguous (stable: the order within a group is kept), each with the mean
  // thickness of its parts.
  std::stable_sort(primitives_.begin(), primitives_.end(),
                   [](const BodyPrimitive& x, const BodyPrimitive& y) { return x.group < y.group; });
  for (std::size_t first = 0; first < primitives_.size();) {
    std::size_t last = first;
    float sum = 0.0f;
    while (last < primitives_.size() && primitives_[last].group == primitives_[first].group) sum += primitives_[last++].thickness;
    for (std::size_t i = first; i < last; ++i) primitives_[i].group_thickness = sum / static_cast<float>(last - first);
    first = last;
  }
  for (const BodyPrimitive& s : primitives_) {
    box_min_ = glm::min(box_min_, s.box_min);
    box_max_ = glm::max(box_max_, s.box_max);
    max_blend_ = std::max(max_blend_, blend_ * s.group_thickness);
  }
  margin_ = 0.06f * size_;
  const glm::vec3 extent = box_max_ - box_min_;
  cell_size_ = std::max({extent.x, extent.y, extent.z, 1e-20f}) / static_cast<float>(kCellsPerAxis);
  cells_ = glm::clamp(glm::ivec3(glm::ceil(extent / cell_size_)), glm::ivec3(1), glm::ivec3(kCellsPerAxis));
  const std::size_t num_cells = static_cast<std::size_t>(cells_.x) * static_cast<std::size_t>(cells_.y) *
                                static_cast<std::size_t>(cells_.z);
  std::vector<std::vector<int>> lists(num_cells);
  for (std::size_t i = 0; i < primitives_.size(); ++i) {
    const BodyPrimitive& s = primitives_[i];
    const float grow = margin_ + blend_ * s.group_thickness;
    const glm::ivec3 lo = glm::clamp(glm::ivec3(glm::floor((s.box_min - grow - box_min_) / cell_size_)),
                                     glm::ivec3(0), cells_ - 1);
    const glm::ivec3 hi = glm::clamp(glm::ivec3(glm::floor((s.box_max + grow - box_min_) / cell_size_)),
                                     glm::ivec3(0), cells_ - 1);
    for (int z = lo.z; z <= hi.z; ++z) {
      for (int y = lo.y; y <= hi.y; ++y) {
        for (int x = lo.x; x <= hi.x; ++x) {
          lists[static_cast<std::size_t>((z * cells_.y + y) * cells_.x + x)].push_back(static_cast<int>(i));
        }
      }
    }
  }
  cell_begin_.assign(num_cells + 1, 0);
  cell_items_.clear();
  for (std::size_t c = 0; c < num_cells; ++c) {
    cell_items_.insert(cell_items_.end(), lists[c].begin(), lists[c].end());
    cell_begin_[c + 1] = static_cast<int>(cell_items_.size());
  }
}

base::Result<ImplicitBody> BuildImplicitBody(const mocap::Skeleton& skeleton,
                                             std::span<const glm::mat4> rest_model_from_joint,
                                             const ImplicitBodyOptions& o) {
  if (!(o.min_branch_extent >= 0.0f && o.min_branch_extent <= 0.5f) || !(o.blend >= 0.0f && o.blend <= 2.0f) ||
      !(o.radius_scale >= 0.5f && o.radius_scale <= 2.0f)) {
    return base::InvalidArgument(
        "body options out of range (min_branch_extent 0..0.5, blend 0..2, "
        "radius_scale 0.5..2)");
  }
  base::Result<BodyChains> tree =
      BuildBodyChains(skeleton, rest_model_from_joint, o.min_branch_extent);
  if (!tree.ok()) {
    base::Error e = std::move(tree).error();
    if (skeleton.num_joints() == 1) {
      e.message += " (the skeleton's only joint is '" + skeleton.names[0] + "')";
    } else if (e.code == ErrorCode::kInvalidArgument && skeleton.num_joints() > 1 &&
               e.message.find("non-zero length") != std::string::npos) {
      e.message += " (every joint from '" + skeleton.names[0] + "' to '" + skeleton.names.back() +
                   "' at one point)";
    }
    return e;
  }
  const std::vector<BodyPoint>& pts = tree->points;
  const std::vector<BodyChain>& chains = tree->chains;
  const float size = tree->size;
  const auto pos_of = [&pts](int i) { return pts[static_cast<std::size_t>(i)].pos; };
  const auto positions = [&](const BodyChain& c) {
    std::vector<glm::vec3> p;
    for (int i : c.points) p.push_back(pos_of(i));
    return p;
  };

  ImplicitBody body;
  body.size_ = size;
  body.blend_ = o.blend;
  PrimitiveList prims(kMinRadius * size, o.radius_scale);

  // Bones for the weights: every chain bone, turning with its child point's bone joint.
  for (std::size_t c = 0; c < chains.size(); ++c) {
    const std::vector<int>& p = chains[c].points;
    for (std::size_t k = 0; k + 1 < p.size(); ++k) {
      body.bones_.push_back({pos_of(p[k]), pos_of(p[k + 1]), pts[static_cast<std::size_t>(p[k + 1])].bone_joint,
                             static_cast<int>(c), static_cast<int>(k)});
    }
  }

  // The last spine point where a big side chain attaches (the chest), per spine.
  std::vector<int> last_branch(chains.size(), -1);
  for (const BodyChain& c : chains) {
    if (c.parent_chain < 0 || chains[static_cast<std::size_t>(c.parent_chain)].kind != BodyChainKind::kSpine) continue;
    if (ArcLength(positions(c)) < 0.15f * size) continue;
    const std::vector<int>& sp = chains[static_cast<std::size_t>(c.parent_chain)].points;
    for (std::size_t i = 0; i < sp.size(); ++i) {
      if (sp[i] == c.points[0]) {
        int& lb = last_branch[static_cast<std::size_t>(c.parent_chain)];
        lb = std::max(lb, static_cast<int>(i));
      }
    }
  }

  // Body axes: up from the file; lateral across the first spine's widest pair of root
  // limbs; forward from the toes when the body is a humanoid (below).
  const glm::vec3 up = skeleton.info.up_axis == mocap::UpAxis::kZ ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);

  // Humanoid roles on the first spine: legs leave its first point, arms a later one.
  const BodyChain& spine = chains[0];
  std::vector<Limb> leg_candidates, arm_candidates;
  for (std::size_t c = 1; c < chains.size(); ++c) {
    if (chains[c].parent_chain != 0 || chains[c].kind != BodyChainKind::kLimb) continue;
    Limb l;
    l.chain = static_cast<int>(c);
    l.p = positions(chains[c]);
    l.middle = LimbMiddle(l.p);
    if (l.middle < 1 || ArcLength(l.p) < 0.2f * size) continue;
    (chains[c].points[0] == spine.points[0] ? leg_candidates : arm_candidates).push_back(l);
  }
  Limb leg[2], arm[2];
  bool humanoid = last_branch[0] >= 0 && PickPair(leg_candidates, leg[0], leg[1]) &&
                  PickPair(arm_candidates, arm[0], arm[1]);
  glm::vec3 pelvis(0.0f), chest(0.0f);
  if (humanoid) {
    pelvis = pos_of(spine.points[0]);
    chest = arm[0].p[0];
    const glm::vec3 rise = chest - pelvis;
    const bool upright = glm::dot(rise, up) > 0.7f * glm::length(rise) && glm::length(rise) > 0.1f * size;
    const bool legs_down = glm::dot(leg[0].end() - leg[0].root(), up) < -0.5f * glm::distance(leg[0].end(), leg[0].root()) &&
                           glm::dot(leg[1].end() - leg[1].root(), up) < -0.5f * glm::distance(leg[1].end(), leg[1].root());
    humanoid = upright && legs_down;
  }
  body.humanoid_ = humanoid;

  // Generic chain shapes (every body; a humanoid's limbs and trunk are replaced below).
  std::vector<bool> replaced(chains.size(), false);
  if (humanoid) {
    for (const Limb* l : {&leg[0], &leg[1], &arm[0], &arm[1]}) replaced[static_cast<std::size_t>(l->chain)] = true;
  }
  for (std::size_t c = 0; c < chains.size(); ++c) {
    const std::vector<glm::vec3> p = positions(chains[c]);
    const std::size_t n = p.size();
    const bool torso = chains[c].kind == BodyChainKind::kSpine && last_branch[c] >= 0;
    const float total = std::max(ArcLength(p), 1e-6f * size);
    if (torso) {
      // Trunk up to the last big branch, a neck after it, a head at the end.
      const auto lb = static_cast<std::size_t>(last_branch[c]);
      const bool head_bone = n >= 3 && glm::distance(p[n - 1], p[n - 2]) >= 0.05f * size && n - 1 > lb;
      const std::size_t neck_end = head_bone ? n - 2 : n - 1;
      for (std::size_t k = 0; k + 1 < n; ++k) {
        if (humanoid && c == 0 && k < lb) continue;  // the humanoid trunk is built from volumes
        if (k >= neck_end) continue;                 // inside the head
        const bool trunk = k < lb;
        const float r = trunk ? kTorsoRadius * size : (humanoid ? 0.04f : 0.035f) * size;
        prims.Cone(trunk ? 2 * static_cast<int>(c) : 2 * static_cast<int>(c) + 1, p[k], p[k + 1], r, r);
      }
      const glm::vec3 axis = glm::normalize(p[n - 1] - p[n - 2]);
      const glm::vec3 tip = p[n - 1];
      const float len = glm::distance(p[n - 1], p[n - 2]);
      const glm::vec3 centre = head_bone ? tip - 0.45f * len * axis : tip + 0.055f * size * axis;
      const float along = head_bone ? std::max(0.55f * len, 0.06f * size) : 0.065f * size;
      // Head: a little deeper front to back than wide; its side axis across the body.
      glm::vec3 side_hint = glm::cross(up, axis);
      if (glm::length(side_hint) < 1e-3f) side_hint = glm::vec3(1, 0, 0);
      prims.Ellipsoid(centre, Frame(axis, side_hint), {along, 0.05f * size, 0.058f * size});
      if (!head_bone) {  // the head turns with the last joint: give it a bone
        const BodyPoint& last = pts[static_cast<std::size_t>(chains[c].points[n - 1])];
        body.bones_.push_back({tip, tip + 0.06f * size * axis, last.joint >= 0 ? last.joint : last.bone_joint, -1, 0});
      }
      continue;
    }
    if (replaced[c]) continue;
    // A limb, tail or lone chain: tapering with its length.
    float at = 0.0f;
    for (std::size_t k = 0; k + 1 < n; ++k) {
      const float next = at + glm::distance(p[k], p[k + 1]);
      const auto radius = [&](float s) {
        return std::clamp(total * (0.12f - 0.07f * s / total), kMinRadius * size, 0.08f * size);
      };
      prims.Cone(2 * static_cast<int>(c), p[k], p[k + 1], radius(at), radius(next));
      at = next;
    }
  }

  if (humanoid) {
    // Front: where the toes point (both feet), else where the knees bend, else any.
    glm::vec3 lateral = leg[1].root() - leg[0].root();
    lateral -= glm::dot(lateral, up) * up;
    if (glm::length(lateral) < 1e-4f * size) lateral = Perpendicular(up, glm::vec3(1, 0, 0));
    lateral = glm::normalize(lateral);
    glm::vec3 forward = glm::cross(lateral, up);
    glm::vec3 cue(0.0f);
    for (const Limb& l : leg) {
      if (static_cast<std::size_t>(l.middle) + 2 < l.p.size()) cue += l.p.back() - l.end();
      cue += 0.5f * (l.mid() - 0.5f * (l.root() + l.end()));
    }
    if (glm::dot(cue, forward) < 0.0f) forward = -forward;
    const glm::vec3 spine_dir = glm::normalize(chest - pelvis);
    const float torso_len = glm::distance(chest, pelvis);

    // Legs: thigh, shin, calf, heel and foot.
    float thigh_r = 0.0f;
    for (const Limb& l : leg) {
      const float a = l.upper(), b = l.lower();
      const std::size_t m = static_cast<std::size_t>(l.middle);
      thigh_r = 0.25f * a;
      for (std::size_t k = 0; k + 1 < m; ++k) prims.Cone(2 * l.chain, l.p[k], l.p[k + 1], thigh_r, thigh_r);
      prims.Cone(2 * l.chain, l.root(), l.mid(), 0.25f * a, 0.14f * a);
      prims.Cone(2 * l.chain, l.mid(), l.end(), 0.14f * a, 0.085f * b);
      const glm::vec3 shin = glm::normalize(l.end() - l.mid());
      prims.Ellipsoid(l.mid() + 0.33f * b * shin - 0.04f * b * forward, Frame(shin, lateral),
                      {0.28f * b, 0.11f * b, 0.105f * b});  // calf
      prims.Ellipsoid(l.root() + 0.42f * a * glm::normalize(l.mid() - l.root()) + 0.02f * a * forward,
                      Frame(l.mid() - l.root(), lateral), {0.38f * a, 0.2f * a, 0.21f * a});  // thigh muscles
      // Foot: the chain's bones after the ankle, a sole and a heel.
      glm::vec3 toe = l.end() + 0.3f * b * forward - 0.2f * b * up;
      for (std::size_t k = m + 1; k + 1 < l.p.size(); ++k) {
        const float t0 = static_cast<float>(k - m - 1) / static_cast<float>(l.p.size() - m - 1);
        const float t1 = static_cast<float>(k - m) / static_cast<float>(l.p.size() - m - 1);
        prims.Cone(2 * l.chain, l.p[k], l.p[k + 1], (0.07f - 0.035f * t0) * b, (0.07f - 0.035f * t1) * b);
        toe = l.p[k + 1];
      }
      const glm::vec3 ankle = l.end();
      prims.Ellipsoid(ankle - 0.06f * b * up - 0.035f * b * forward, glm::mat3(lateral, up, forward),
                      glm::vec3(0.065f * b));  // heel
      const glm::vec3 heel_to_toe = toe - (ankle - 0.06f * b * forward);
      prims.Ellipsoid(0.5f * (ankle + toe) - 0.05f * b * up, Frame(heel_to_toe, lateral),
                      {0.5f * glm::length(heel_to_toe) + 0.02f * b, 0.085f * b, 0.045f * b});  // sole
    }
    // Arms: clavicle, upper arm, deltoid, biceps, forearm, hand.
    float shoulder_half_width = 0.0f;
    for (const Limb& l : arm) {
      const float a = l.upper(), b = l.lower();
      const std::size_t m = static_cast<std::size_t>(l.middle);
      for (std::size_t k = 0; k + 1 < m; ++k) prims.Cone(2 * l.chain, l.p[k], l.p[k + 1], 0.17f * a, 0.15f * a);
      const glm::vec3 upper = glm::normalize(l.mid() - l.root());
      const glm::vec3 lower = glm::normalize(l.end() - l.mid());
      prims.Cone(2 * l.chain, l.root(), l.mid(), 0.19f * a, 0.14f * a);
      prims.Cone(2 * l.chain, l.mid(), l.end(), 0.15f * b, 0.1f * b);
      glm::vec3 out = l.root() - chest;
      out -= glm::dot(out, spine_dir) * spine_dir;
      shoulder_half_width = std::max(shoulder_half_width, glm::length(out));
      out = glm::length(out) > 1e-6f * size ? glm::normalize(out) : lateral;
      prims.Ellipsoid(l.root() + 0.1f * a * upper + 0.03f * a * out, Frame(upper, forward),
                      {0.3f * a, 0.22f * a, 0.21f * a});  // deltoid
      prims.Ellipsoid(l.root() + 0.55f * a * upper + 0.03f * a * forward, Frame(upper, forward),
                      {0.3f * a, 0.15f * a, 0.16f * a});  // biceps and triceps
      prims.Ellipsoid(l.mid() + 0.3f * b * lower, Frame(lower, forward), {0.3f * b, 0.17f * b, 0.14f * b});
      // Hand: a mitten from the wrist to the chain's end (folded fingers included).
      glm::vec3 tip = l.p.back();
      if (glm::distance(tip, l.end()) < 0.3f * b) tip = l.end() + 0.75f * b * lower;
      const glm::vec3 hand = tip - l.end();
      const float hand_len = glm::length(hand);
      for (std::size_t k = m + 1; k + 1 < l.p.size(); ++k) prims.Cone(2 * l.chain, l.p[k], l.p[k + 1], 0.05f * b, 0.04f * b);
      glm::vec3 thin = glm::cross(hand, forward);
      if (glm::length(thin) < 1e-3f * hand_len) thin = Perpendicular(hand / hand_len, up);
      prims.Ellipsoid(l.end() + 0.5f * hand, Frame(hand, glm::cross(thin, hand)),
                      {0.52f * hand_len, 0.22f * hand_len, 0.1f * hand_len});
    }
    // Trunk: pelvis, buttocks, belly, chest, shoulders, and the spine inside them.
    const glm::vec3 hips_mid = 0.5f * (leg[0].root() + leg[1].root());
    const float hip_half = 0.5f * glm::distance(leg[0].root(), leg[1].root());
    const float pelvis_lat = hip_half + 1.0f * thigh_r;
    const glm::mat3 torso_frame(lateral, spine_dir, glm::normalize(glm::cross(lateral, spine_dir)));
    const glm::vec3 fwd = glm::dot(torso_frame[2], forward) >= 0.0f ? torso_frame[2] : -torso_frame[2];
    const glm::mat3 trunk(lateral, spine_dir, fwd);
    prims.Ellipsoid(hips_mid + 0.12f * torso_len * spine_dir, trunk,
                    {pelvis_lat, 0.32f * torso_len, 0.58f * pelvis_lat});
    for (const Limb& l : leg) {
      const glm::vec3 inward = glm::normalize(hips_mid - l.root() + 1e-12f * lateral);
      prims.Ellipsoid(l.root() - 0.5f * thigh_r * fwd + 0.2f * hip_half * inward + 0.05f * torso_len * spine_dir,
                      trunk, {0.95f * thigh_r, 1.05f * thigh_r, 0.85f * thigh_r});  // buttock
    }
    // The trunk reaches the shoulder joints, which usually sit above the
    // spine point the arms leave (the clavicles climb): its volumes are laid
    // out along the pelvis-to-shoulder-line height, not to that point.
    float shoulder_h = 0.0f, upper_arm = 0.0f;
    for (const Limb& l : arm) {
      shoulder_h += 0.5f * glm::dot(l.root() - pelvis, spine_dir);
      upper_arm += 0.5f * l.upper();
    }
    const float trunk_len = std::max(torso_len, shoulder_h);
    const float chest_lat = std::max(0.85f * shoulder_half_width, pelvis_lat * 0.95f);
    prims.Ellipsoid(pelvis + 0.34f * trunk_len * spine_dir + 0.1f * pelvis_lat * fwd, trunk,
                    {0.78f * pelvis_lat, 0.3f * trunk_len, 0.55f * pelvis_lat});  // belly
    prims.Ellipsoid(pelvis + 0.6f * trunk_len * spine_dir + 0.04f * chest_lat * fwd, trunk,
                    {0.92f * chest_lat, 0.3f * trunk_len, 0.65f * chest_lat});  // rib cage
    prims.Ellipsoid(pelvis + 0.91f * trunk_len * spine_dir, trunk,
                    {shoulder_half_width + 0.1f * upper_arm, 0.12f * trunk_len, 0.42f * chest_lat});  // shoulders
    const std::vector<glm::vec3> sp = positions(spine);
    for (std::size_t k = 0; k < static_cast<std::size_t>(last_branch[0]); ++k) {
      prims.Cone(0, sp[k], sp[k + 1], 0.5f * pelvis_lat, 0.5f * pelvis_lat);
    }
  }

  if (prims.list.size() > static_cast<std::size_t>(kMaxPrimitives)) {
    return MakeError(ErrorCode::kLimitExceeded, {},
                     "skeleton makes " + std::to_string(prims.list.size()) + " body parts, more than " +
                         std::to_string(kMaxPrimitives));
  }
  body.primitives_ = std::move(prims.list);
  body.BuildCells();
  return body;
}

}  // namespace deform
