#include "deform/body/mannequin.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

#include "deform/body/body_chains.h"
#include "deform/body/internal/tube_mesh.h"
#include "deform/global/skinning_job.h"

namespace deform {
namespace {

using base::ErrorCode;
using base::MakeError;
using internal::AnyPerpendicular;
using internal::CatmullRom;
using internal::kCapRings;
using internal::MeshBuilder;
using internal::Ring;
using internal::Smoothstep;
using internal::WithCaps;
using Point = BodyPoint;
using Chain = BodyChain;
using ChainKind = BodyChainKind;

constexpr int kMaxVertices = 40000;
constexpr int kCurveSamples = 24;     // dense Catmull-Rom samples per bone
constexpr float kTorsoRadius = 0.09f;  // half the torso width, in body sizes S

// Per-chain shape: radius, flattening and short axis at each chain point.
struct ChainShape {
  std::vector<float> radius;
  std::vector<float> flatten;
  std::vector<glm::vec3> minor;
  int geometry_begin = 0;  // first chain point the tube covers
  int geometry_end = 0;    // last chain point the tube covers
};

}  // namespace

base::Result<SkinnedMesh> BuildMannequin(const mocap::Skeleton& skeleton,
                                         std::span<const glm::mat4> rest_model_from_joint,
                                         const MannequinOptions& o) {
  const int nj = skeleton.num_joints();
  if (o.ring_vertices < 8 || o.ring_vertices > 64 || o.target_vertices < 10000 ||
      o.target_vertices > kMaxVertices || !(o.radius_scale >= 0.25f && o.radius_scale <= 4.0f) ||
      !(o.min_branch_extent >= 0.0f && o.min_branch_extent <= 0.5f) ||
      !(o.blend_width > 0.0f && o.blend_width <= 4.0f)) {
    return base::InvalidArgument(
        "mannequin options out of range (ring_vertices 8..64, target_vertices "
        "10000..40000, radius_scale 0.25..4, min_branch_extent 0..0.5, "
        "blend_width in (0, 4])");
  }
  base::Result<BodyChains> tree =
      BuildBodyChains(skeleton, rest_model_from_joint, o.min_branch_extent);
  if (!tree.ok()) return std::move(tree).error();
  const std::vector<Point>& pts = tree->points;
  const std::vector<Chain>& chains = tree->chains;
  const float size = tree->size;
  const auto pos_of = [&pts](int i) { return pts[static_cast<std::size_t>(i)].pos; };

  // Per-chain arc lengths at the points (straight bones) and total lengths.
  std::vector<std::vector<float>> arcs(chains.size());
  for (std::size_t c = 0; c < chains.size(); ++c) {
    const std::vector<int>& p = chains[c].points;
    arcs[c].assign(p.size(), 0.0f);
    for (std::size_t i = 1; i < p.size(); ++i) {
      arcs[c][i] = arcs[c][i - 1] + glm::distance(pos_of(p[i - 1]), pos_of(p[i]));
    }
  }
  // Which spines carry a torso (big side chains), and the last point where one attaches.
  std::vector<int> last_branch(chains.size(), -1);
  for (std::size_t c = 0; c < chains.size(); ++c) {
    const int pc = chains[c].parent_chain;
    if (pc < 0 || chains[static_cast<std::size_t>(pc)].kind != ChainKind::kSpine) continue;
    if (arcs[c].back() < 0.15f * size) continue;
    const std::vector<int>& sp = chains[static_cast<std::size_t>(pc)].points;
    for (std::size_t i = 0; i < sp.size(); ++i) {
      if (sp[i] == chains[c].points[0]) {
        last_branch[static_cast<std::size_t>(pc)] =
            std::max(last_branch[static_cast<std::size_t>(pc)], static_cast<int>(i));
      }
    }
  }

  // Body axes: up from the skeleton info, lateral from the first two root limbs.
  const glm::vec3 up = skeleton.info.up_axis == mocap::UpAxis::kZ ? glm::vec3(0, 0, 1)
                                                                   : glm::vec3(0, 1, 0);
  glm::vec3 lateral(0.0f);
  {
    std::vector<glm::vec3> roots_limbs;
    for (const Chain& c : chains) {
      if (c.parent_chain >= 0 && c.points.size() >= 2 &&
          c.points[0] == chains[static_cast<std::size_t>(c.parent_chain)].points[0]) {
        roots_limbs.push_back(pos_of(c.points[1]));
      }
    }
    // The pair of root limbs (hips) farthest apart across the spine's direction.
    glm::vec3 along = pos_of(chains[0].points.back()) - pos_of(chains[0].points[0]);
    along -= glm::dot(along, up) * up;
    along = glm::length(along) > 1e-6f * size ? glm::normalize(along) : glm::vec3(0.0f);
    float widest = 0.0f;
    for (std::size_t a = 0; a < roots_limbs.size(); ++a) {
      for (std::size_t b = a + 1; b < roots_limbs.size(); ++b) {
        glm::vec3 d = roots_limbs[b] - roots_limbs[a];
        d -= glm::dot(d, up) * up + glm::dot(d, along) * along;
        if (glm::length(d) > widest) widest = glm::length(d), lateral = d;
      }
    }
    if (glm::length(lateral) < 1e-6f * size) {
      const glm::vec3 spine = pos_of(chains[0].points.back()) - pos_of(chains[0].points[0]);
      lateral = glm::cross(up, spine);
    }
    lateral = AnyPerpendicular(up, lateral);
  }
  const glm::vec3 forward = glm::normalize(glm::cross(lateral, up));

  // 3. Radii, flattening and covered range of every chain.
  std::vector<ChainShape> shapes(chains.size());
  std::vector<glm::vec3> chain_minor(chains.size(), up);
  for (std::size_t c = 0; c < chains.size(); ++c) {
    const Chain& ch = chains[c];
    ChainShape& sh = shapes[c];
    const int n = static_cast<int>(ch.points.size());
    const float total = std::max(arcs[c].back(), 1e-6f * size);
    sh.radius.assign(static_cast<std::size_t>(n), 0.0f);
    sh.flatten.assign(static_cast<std::size_t>(n), 1.0f);
    sh.geometry_end = n - 1;
    const bool torso = ch.kind == ChainKind::kSpine && last_branch[c] >= 0;
    const int pc = ch.parent_chain;
    const bool on_torso = pc >= 0 && last_branch[static_cast<std::size_t>(pc)] >= 0;
    const bool root_limb = pc >= 0 && ch.points[0] == chains[static_cast<std::size_t>(pc)].points[0];
    if (torso) {
      chain_minor[c] = forward;
      for (int i = 0; i < n; ++i) {
        const bool trunk = i <= last_branch[c];
        sh.radius[static_cast<std::size_t>(i)] = (trunk ? kTorsoRadius : 0.035f) * size;
        sh.flatten[static_cast<std::size_t>(i)] = trunk ? 0.65f : 1.0f;
      }
      if (n >= 3 && arcs[c][static_cast<std::size_t>(n - 1)] - arcs[c][static_cast<std::size_t>(n - 2)] >= 0.05f * size) {
        sh.geometry_end = n - 2;  // the head bone lies inside the head ellipsoid
      }
    } else {
      const float factor = root_limb ? 1.05f : 1.0f;  // thighs a little thicker than arms
      for (int i = 0; i < n; ++i) {
        const float r = factor * total * (0.12f - 0.06f * arcs[c][static_cast<std::size_t>(i)] / total);
        sh.radius[static_cast<std::size_t>(i)] = std::clamp(r, 0.004f * size, 0.08f * size);
      }
      int flat_from = -1;  // feet after the ankle, hands after the wrist
      if (root_limb && on_torso) {
        for (int i = std::max(2, n / 2); i + 1 < n && flat_from < 0; ++i) {
          const glm::vec3 a = glm::normalize(pos_of(ch.points[static_cast<std::size_t>(i)]) - pos_of(ch.points[static_cast<std::size_t>(i - 1)]));
          const glm::vec3 b = glm::normalize(pos_of(ch.points[static_cast<std::size_t>(i + 1)]) - pos_of(ch.points[static_cast<std::size_t>(i)]));
          if (glm::dot(a, b) < std::cos(0.61f)) flat_from = i;  // a turn of more than 35 degrees
        }
      } else if (on_torso) {
        flat_from = ch.folded_branches ? ch.first_folded : (n >= 5 ? n - 2 : -1);
      }
      if (flat_from > 0) {
        for (int i = flat_from + 1; i < n; ++i) sh.flatten[static_cast<std::size_t>(i)] = 0.5f;
      }
      // A branch bone shorter than the torso radius (pelvis to hip, chest to
      // clavicle) lies inside the torso; a longer one (CMU's clavicle) is kept
      // so the limb stays attached.
      if (on_torso && n >= 3 && arcs[c][1] < kTorsoRadius * size * o.radius_scale) {
        sh.geometry_begin = 1;
      }
    }
    for (float& r : sh.radius) r *= o.radius_scale;
  }

  // Head: an ellipsoid at the end of every torso spine.
  struct Head {
    glm::vec3 center, axis;
    float a;
    int joint;
  };
  std::vector<Head> heads;
  for (std::size_t c = 0; c < chains.size(); ++c) {
    if (chains[c].kind != ChainKind::kSpine || last_branch[c] < 0) continue;
    const std::vector<int>& p = chains[c].points;
    const std::size_t n = p.size();
    const glm::vec3 tip = pos_of(p[n - 1]);
    const glm::vec3 axis = glm::normalize(tip - pos_of(p[n - 2]));
    if (shapes[c].geometry_end == static_cast<int>(n) - 2) {
      const float len = glm::distance(tip, pos_of(p[n - 2]));
      heads.push_back({tip - 0.5f * len * axis, axis, std::max(0.5f * len, 0.06f * size),
                       pts[static_cast<std::size_t>(p[n - 1])].bone_joint});
    } else {
      const Point& last = pts[static_cast<std::size_t>(p[n - 1])];
      heads.push_back({tip + 0.06f * size * axis, axis, 0.065f * size,
                       last.joint >= 0 ? last.joint : last.bone_joint});
    }
  }

  // 4. Ring spacing from the vertex budget, then the tubes.
  const int rv = o.ring_vertices;
  constexpr int kHeadRings = 23;
  struct Sample {
    glm::vec3 pos;
    float s;    // chain coordinate (arc length along the straight bones)
    float arc;  // arc length along the curve
  };
  std::vector<std::vector<Sample>> curves(chains.size());
  float total_curve = 0.0f;
  for (std::size_t c = 0; c < chains.size(); ++c) {
    const std::vector<int>& p = chains[c].points;
    const int gb = shapes[c].geometry_begin;
    const int ge = shapes[c].geometry_end;
    const auto at = [&](int i) {  // chain point, mirrored past the covered range
      if (i < gb) return 2.0f * pos_of(p[static_cast<std::size_t>(gb)]) - pos_of(p[static_cast<std::size_t>(gb + 1)]);
      if (i > ge) return 2.0f * pos_of(p[static_cast<std::size_t>(ge)]) - pos_of(p[static_cast<std::size_t>(ge - 1)]);
      return pos_of(p[static_cast<std::size_t>(i)]);
    };
    std::vector<Sample>& curve = curves[c];
    for (int k = gb; k < ge; ++k) {
      const float len = arcs[c][static_cast<std::size_t>(k + 1)] - arcs[c][static_cast<std::size_t>(k)];
      const int last = k + 1 == ge ? kCurveSamples : kCurveSamples - 1;
      for (int q = 0; q <= last; ++q) {
        const float t = static_cast<float>(q) / static_cast<float>(kCurveSamples);
        Sample smp;
        smp.pos = CatmullRom(at(k - 1), at(k), at(k + 1), at(k + 2), t);
        smp.s = arcs[c][static_cast<std::size_t>(k)] + t * len;
        smp.arc = curve.empty() ? 0.0f : curve.back().arc + glm::distance(curve.back().pos, smp.pos);
        curve.push_back(smp);
      }
    }
    total_curve += curve.back().arc;
  }
  const int num_tubes = static_cast<int>(chains.size());
  const int fixed = static_cast<int>(heads.size()) * (kHeadRings * rv + 2) +
                    num_tubes * (2 * kCapRings * rv + 2);
  const int ring_budget = std::max((o.target_vertices - fixed) / rv - num_tubes, num_tubes);
  const float spacing = std::max(total_curve / static_cast<float>(ring_budget), 1e-6f * size);
  const int min_vertices = fixed + num_tubes * 3 * rv;
  if (min_vertices > kMaxVertices) {
    return MakeError(ErrorCode::kLimitExceeded, {},
                     "skeleton splits into " + std::to_string(num_tubes) +
                         " chains; the mannequin would exceed " + std::to_string(kMaxVertices) +
                         " vertices");
  }

  MeshBuilder mesh;
  for (std::size_t c = 0; c < chains.size(); ++c) {
    const Chain& ch = chains[c];
    const ChainShape& sh = shapes[c];
    const std::vector<Sample>& curve = curves[c];
    const std::vector<float>& arc = arcs[c];
    const int n = static_cast<int>(ch.points.size());
    const auto bone_joint = [&](int k) {  // joint moving bone k (points k -> k+1)
      return pts[static_cast<std::size_t>(ch.points[static_cast<std::size_t>(k + 1)])].bone_joint;
    };
    const auto blend_half = [&](int i) {  // half-width of the blend around chain point i
      float h = o.blend_width * sh.radius[static_cast<std::size_t>(i)];
      if (i > 0) h = std::min(h, 0.45f * (arc[static_cast<std::size_t>(i)] - arc[static_cast<std::size_t>(i - 1)]));
      if (i + 1 < n) h = std::min(h, 0.45f * (arc[static_cast<std::size_t>(i + 1)] - arc[static_cast<std::size_t>(i)]));
      return std::max(h, 1e-9f);
    };
    // The joint before the chain's first point, blended into its first rings;
    // never one that only positions the body (it would pin them where the
    // body was bound: Bandai's 4 m tail to the origin).
    int incoming = pts[static_cast<std::size_t>(ch.points[0])].parent >= 0 || ch.parent_chain >= 0
                       ? pts[static_cast<std::size_t>(ch.points[0])].bone_joint
                       : -1;
    if (incoming >= 0 && tree->body_part_joints[static_cast<std::size_t>(incoming)] == 0) {
      incoming = -1;
    }
    const float length = curve.back().arc;
    const int count = std::max(3, static_cast<int>(std::lround(length / spacing)) + 1);
    std::vector<Ring> rings;
    const auto point_at = [&curve](float target) {  // curve point at an arc length
      const auto it = std::lower_bound(curve.begin() + 1, curve.end() - 1, target,
                                       [](const Sample& smp, float t) { return smp.arc < t; });
      const Sample& hi = *it;
      const Sample& lo = *(it - 1);
      const float x = std::clamp((target - lo.arc) / std::max(hi.arc - lo.arc, 1e-12f), 0.0f, 1.0f);
      return lo.pos + x * (hi.pos - lo.pos);
    };
    std::size_t q = 0;
    for (int i = 0; i < count; ++i) {
      const float target = length * static_cast<float>(i) / static_cast<float>(count - 1);
      while (q + 2 < curve.size() && curve[q + 1].arc < target) ++q;
      const Sample& a = curve[q];
      const Sample& b = curve[q + 1];
      const float x = std::clamp((target - a.arc) / std::max(b.arc - a.arc, 1e-12f), 0.0f, 1.0f);
      Ring r;
      r.center = a.pos + x * (b.pos - a.pos);
      const float s = a.s + x * (b.s - a.s);
      r.tangent = glm::length(b.pos - a.pos) > 0.0f ? glm::normalize(b.pos - a.pos) : up;
      int k = 0;  // bone holding s
      while (k + 2 < n && s > arc[static_cast<std::size_t>(k + 1)]) ++k;
      const float len = std::max(arc[static_cast<std::size_t>(k + 1)] - arc[static_cast<std::size_t>(k)], 1e-12f);
      const float w = Smoothstep((s - arc[static_cast<std::size_t>(k)]) / len);
      r.chain = static_cast<int>(c);
      r.chain_u = static_cast<float>(k) + std::clamp((s - arc[static_cast<std::size_t>(k)]) / len, 0.0f, 1.0f);
      r.radius = sh.radius[static_cast<std::size_t>(k)] + w * (sh.radius[static_cast<std::size_t>(k + 1)] - sh.radius[static_cast<std::size_t>(k)]);
      r.flatten = sh.flatten[static_cast<std::size_t>(k)] + w * (sh.flatten[static_cast<std::size_t>(k + 1)] - sh.flatten[static_cast<std::size_t>(k)]);
      // Ring planes follow the curve's chord over +-0.75 radius rather than its
      // local tangent: at a sharp turn (ankle) neighbouring rings fan out
      // instead of cutting through each other on the inner side.
      const float h = 0.75f * r.radius;
      const glm::vec3 chord = point_at(std::min(target + h, length)) - point_at(std::max(target - h, 0.0f));
      if (glm::length(chord) > 1e-6f * size) r.tangent = glm::normalize(chord);
      r.n = AnyPerpendicular(r.tangent, rings.empty() ? forward : rings.back().n);  // transport
      r.b = glm::cross(r.tangent, r.n);
      r.minor = chain_minor[c];
      r.joint[0] = r.joint[1] = bone_joint(k);
      r.weight[0] = 1.0f;
      r.weight[1] = 0.0f;
      const float h0 = blend_half(k);
      const float h1 = blend_half(k + 1);
      const float from_start = s - arc[static_cast<std::size_t>(k)];
      const float to_end = arc[static_cast<std::size_t>(k + 1)] - s;
      if ((k > 0 || incoming >= 0) && from_start < h0) {  // blend with the bone before
        const float wk = Smoothstep((from_start + h0) / (2.0f * h0));
        r.joint[0] = k > 0 ? bone_joint(k - 1) : incoming;
        r.joint[1] = bone_joint(k);
        r.weight[0] = 1.0f - wk;
        r.weight[1] = wk;
      } else if (k + 2 < n && to_end < h1) {  // blend with the bone after
        const float wk = Smoothstep((h1 - to_end) / (2.0f * h1));
        r.joint[1] = bone_joint(k + 1);
        r.weight[0] = 1.0f - wk;
        r.weight[1] = wk;
      }
      rings.push_back(r);
    }
    glm::vec3 start_pole, end_pole;
    const std::vector<Ring> closed = WithCaps(rings, 0.8f, start_pole, end_pole);  // domes 0.8 radii deep
    mesh.AddClosedTube(closed, start_pole, end_pole, rv);
  }
  for (const Head& h : heads) {
    const glm::vec3 n = AnyPerpendicular(h.axis, lateral);
    std::vector<Ring> rings;
    for (int k = 1; k <= kHeadRings; ++k) {
      const float phi = std::numbers::pi_v<float> * static_cast<float>(k) / static_cast<float>(kHeadRings + 1);
      Ring r;
      r.tangent = h.axis;
      r.n = n;
      r.b = glm::cross(h.axis, n);
      r.center = h.center - h.a * std::cos(phi) * h.axis;
      r.radius = 0.05f * size * o.radius_scale * std::sin(phi);
      r.minor = forward;
      r.flatten = 1.1f;  // a little deeper front to back than wide
      r.joint[0] = r.joint[1] = h.joint;
      rings.push_back(r);
    }
    mesh.AddClosedTube(rings, h.center - h.a * h.axis, h.center + h.a * h.axis, rv);
  }

  if (mesh.positions.size() > static_cast<std::size_t>(kMaxVertices)) {
    return MakeError(ErrorCode::kLimitExceeded, {},
                     "mannequin has " + std::to_string(mesh.positions.size()) +
                         " vertices, more than " + std::to_string(kMaxVertices));
  }

  // 5. Skin joints, weights and normals.
  SkinnedMesh out;
  std::vector<int> skin_of(static_cast<std::size_t>(nj), -1);
  for (int j : mesh.joints) skin_of[static_cast<std::size_t>(j)] = 0;
  for (int j = 0; j < nj; ++j) {
    if (skin_of[static_cast<std::size_t>(j)] < 0) continue;
    skin_of[static_cast<std::size_t>(j)] = static_cast<int>(out.skin_joints.size());
    out.skin_joints.push_back(j);
    out.joint_from_bind.push_back(glm::inverse(rest_model_from_joint[static_cast<std::size_t>(j)]));
  }
  const std::size_t nv = mesh.positions.size();
  out.weights.influences = 4;
  out.weights.joints.assign(nv * 4, 0);
  out.weights.weights.assign(nv * 4, 0.0f);
  for (std::size_t v = 0; v < nv; ++v) {
    const int j0 = mesh.joints[2 * v];
    const int j1 = mesh.joints[2 * v + 1];
    float w0 = mesh.weights[2 * v];
    float w1 = mesh.weights[2 * v + 1];
    if (j0 == j1) w0 += w1, w1 = 0.0f;
    const auto s0 = static_cast<std::uint16_t>(skin_of[static_cast<std::size_t>(j0)]);
    const auto s1 = static_cast<std::uint16_t>(skin_of[static_cast<std::size_t>(j1)]);
    for (std::size_t i = 0; i < 4; ++i) out.weights.joints[4 * v + i] = s0;
    out.weights.weights[4 * v] = w0;
    if (w1 > 0.0f) {
      out.weights.joints[4 * v + 1] = s1;
      out.weights.weights[4 * v + 1] = w1;
    }
  }
  NormalizeSkinWeights(out.weights);
  out.body_chain_coords.resize(nv);
  for (std::size_t v = 0; v < nv; ++v) out.body_chain_coords[v] = {mesh.chains[v], mesh.chain_u[v]};
  out.bind.positions = std::move(mesh.positions);
  out.bind.triangles = std::move(mesh.triangles);
  out.bind.normals.resize(nv);
  ComputeVertexNormals(out.bind.positions, out.bind.triangles, out.bind.normals);
  return out;
}

}  // namespace deform
