#include "deform/global/swd_rig.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>

#include "deform/body/body_chains.h"
#include "deform/global/swd_job.h"

namespace deform {
namespace {

using base::ErrorCode;
using base::JobStatus;
using base::MakeError;

// One sweep cut from a body chain: body-chain points [first, last].
struct Piece {
  int body_chain = 0;
  int first = 0;
  int last = 0;
};

// The elbow or knee of a limb chain with bone lengths `lengths` (#K >= 2): the interior
// joint whose shorter bone is the longest (upper arm and forearm, thigh and shin). Bone 0
// leaves the trunk (a clavicle, or pelvis to hip): it is the junction zone, not a limb
// segment, and a clavicle can be as long as the forearm (CMU: 3.58 against 3.48), so
// joint 1 (the shoulder) wins only when its pair is more than twice as long as the best
// pair further out: a limb without a clavicle (upper arm, forearm, then a short hand).
int LimbMiddleJoint(const std::vector<double>& lengths) {
  auto pair = [&](std::size_t k) { return std::min(lengths[k - 1], lengths[k]); };
  if (lengths.size() < 2) return 0;
  int best = 0;
  double best_pair = -1.0;
  for (std::size_t k = 2; k < lengths.size(); ++k) {
    if (pair(k) > best_pair) best_pair = pair(k), best = static_cast<int>(k);
  }
  if (best == 0 || pair(1) > 2.0 * best_pair) return 1;
  return best;
}

int FindRoot(std::vector<int>& parent, int i) {
  while (parent[static_cast<std::size_t>(i)] != i) {
    parent[static_cast<std::size_t>(i)] =
        parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    i = parent[static_cast<std::size_t>(i)];
  }
  return i;
}

// Union-find parents joining the vertices of every triangle: FindRoot(parent, v)
// names the connected part (by shared triangle vertices) of vertex v.
std::vector<int> PartParents(const Mesh& mesh) {
  const std::size_t nv = mesh.positions.size();
  std::vector<int> parent(nv);
  for (std::size_t v = 0; v < nv; ++v) parent[v] = static_cast<int>(v);
  for (const glm::uvec3& t : mesh.triangles) {
    if (t.x >= nv || t.y >= nv || t.z >= nv) continue;
    const int a = FindRoot(parent, static_cast<int>(t.x));
    parent[static_cast<std::size_t>(FindRoot(parent, static_cast<int>(t.y)))] = a;
    parent[static_cast<std::size_t>(FindRoot(parent, static_cast<int>(t.z)))] = a;
  }
  return parent;
}

// Number of connected parts (by shared triangle vertices) of the mesh.
int CountParts(const Mesh& mesh) {
  const std::size_t nv = mesh.positions.size();
  std::vector<int> parent = PartParents(mesh);
  int parts = 0;
  for (std::size_t v = 0; v < nv; ++v) parts += FindRoot(parent, static_cast<int>(v)) == static_cast<int>(v) ? 1 : 0;
  return parts;
}

// Squared distance from p to the segment [a, b].
float SegmentDistance2(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b) {
  const glm::vec3 ab = b - a;
  const float len2 = glm::dot(ab, ab);
  const float t = len2 > 0.0f ? std::clamp(glm::dot(p - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
  const glm::vec3 d = p - (a + t * ab);
  return glm::dot(d, d);
}

// Binds the vertices part by part. A connected part of the mesh (a mannequin tube) of a
// mesh made of several parts, or one that lies mostly (kFamilyShare of its vertices)
// nearest the sweeps of one body chain and that chain's trunk, is bound to the sweeps of
// the body chain nearest most of its vertices (plus its trunk) only: without this, the inner side of a
// thigh tube, as near the other leg's bone as its own, would follow the other leg.
// Other parts (a welded skin) are bound to all sweeps.
// Vertices marked in `skip` (#V, or empty) are left unbound (default bindings) and do
// not vote.
base::Result<std::vector<SweepVertexBinding>> BindByComponent(
    std::span<const SweepChain> chains, std::span<const SweepJunction> junctions,
    std::span<const int> piece_chain, const Mesh& mesh, std::span<const std::uint8_t> skip) {
  constexpr float kFamilyShare = 0.75f;
  const std::size_t nv = mesh.positions.size();
  const auto nc = static_cast<int>(chains.size());
  std::vector<int> parent = PartParents(mesh);
  // Nearest sweep of every vertex, counted per part.
  std::vector<int> trunk_of(chains.size(), -1);
  for (const SweepJunction& j : junctions) trunk_of[static_cast<std::size_t>(j.branch)] = j.trunk;
  std::vector<std::vector<int>> counts(nv);
  for (std::size_t v = 0; v < nv; ++v) {
    if (!skip.empty() && skip[v] != 0) continue;
    int best = 0;
    float best_d = 1e38f;
    for (int c = 0; c < nc; ++c) {
      const BasicSweepPose<double>& rest = chains[static_cast<std::size_t>(c)].rest_pose();
      for (int k = 0; k < rest.num_bones; ++k) {
        const float d = SegmentDistance2(mesh.positions[v], glm::vec3(rest.points[static_cast<std::size_t>(k)]),
                                         glm::vec3(rest.points[static_cast<std::size_t>(k + 1)]));
        if (d < best_d) best_d = d, best = c;
      }
    }
    std::vector<int>& count = counts[static_cast<std::size_t>(FindRoot(parent, static_cast<int>(v)))];
    if (count.empty()) count.assign(chains.size() + 1, 0);
    ++count[static_cast<std::size_t>(best)];
    ++count[chains.size()];  // part size
  }
  // The chain set of every part: a family (one body chain's sweeps plus its trunk) or all.
  // A mesh made of several parts (the mannequin's tubes) binds every part to a family.
  int num_parts = 0;
  for (std::size_t v = 0; v < nv; ++v) num_parts += FindRoot(parent, static_cast<int>(v)) == static_cast<int>(v) ? 1 : 0;
  const bool several_parts = num_parts > 1;
  std::vector<int> group_of(nv, -1);
  std::vector<std::vector<int>> groups;  // sweep indices of each group
  std::vector<int> all(chains.size());
  for (int c = 0; c < nc; ++c) all[static_cast<std::size_t>(c)] = c;
  for (std::size_t v = 0; v < nv; ++v) {
    const int root = FindRoot(parent, static_cast<int>(v));
    if (static_cast<std::size_t>(root) != v || counts[v].empty()) continue;  // skipped parts
    const std::vector<int>& count = counts[v];
    const int top = static_cast<int>(std::max_element(count.begin(), count.end() - 1) - count.begin());
    std::vector<int> family;
    for (int c = 0; c < nc; ++c) {
      if (piece_chain[static_cast<std::size_t>(c)] == piece_chain[static_cast<std::size_t>(top)]) {
        family.push_back(c);
      }
    }
    const int trunk = trunk_of[static_cast<std::size_t>(family.front())];
    if (trunk >= 0) family.push_back(-1 - trunk);  // the trunk: junction blends only
    int inside = 0;
    for (int c : family) inside += count[static_cast<std::size_t>(c < 0 ? -1 - c : c)];
    const bool restrict = several_parts ||
                          static_cast<float>(inside) >= kFamilyShare * static_cast<float>(count.back());
    // Chains as indices; a negative entry -1 - c is chain c taken for junctions only.
    const std::vector<int>& set = restrict ? family : all;
    std::size_t g = 0;
    while (g < groups.size() && groups[g] != set) ++g;
    if (g == groups.size()) groups.push_back(set);
    group_of[v] = static_cast<int>(g);
  }
  std::vector<SweepVertexBinding> out(nv);
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const std::vector<int>& set = groups[g];
    std::vector<SweepChain> sub;
    std::vector<std::uint8_t> primary_ok;
    std::vector<int> local(chains.size(), -1);
    std::vector<int> global;  // sub index -> rig chain
    for (int entry : set) {
      const int c = entry < 0 ? -1 - entry : entry;
      local[static_cast<std::size_t>(c)] = static_cast<int>(sub.size());
      sub.push_back(chains[static_cast<std::size_t>(c)]);
      primary_ok.push_back(entry < 0 ? 0 : 1);
      global.push_back(c);
    }
    std::vector<SweepJunction> sub_junctions;
    for (SweepJunction j : junctions) {
      if (local[static_cast<std::size_t>(j.branch)] < 0 || local[static_cast<std::size_t>(j.trunk)] < 0) continue;
      j.branch = local[static_cast<std::size_t>(j.branch)];
      j.trunk = local[static_cast<std::size_t>(j.trunk)];
      sub_junctions.push_back(j);
    }
    std::vector<std::uint32_t> members;
    std::vector<glm::vec3> positions;
    for (std::size_t v = 0; v < nv; ++v) {
      if (!skip.empty() && skip[v] != 0) continue;
      if (group_of[static_cast<std::size_t>(FindRoot(parent, static_cast<int>(v)))] != static_cast<int>(g)) continue;
      members.push_back(static_cast<std::uint32_t>(v));
      positions.push_back(mesh.positions[v]);
    }
    base::Result<std::vector<SweepVertexBinding>> b =
        BindToSweeps(sub, sub_junctions, positions, primary_ok);
    if (!b.ok()) return std::move(b).error();
    for (std::size_t i = 0; i < members.size(); ++i) {
      SweepVertexBinding vb = (*b)[i];
      vb.primary.chain = static_cast<std::uint16_t>(global[vb.primary.chain]);
      vb.secondary.chain = static_cast<std::uint16_t>(global[vb.secondary.chain]);
      out[members[i]] = vb;
    }
  }
  return out;
}

}  // namespace

base::Result<SwdRig> BuildSwdRig(const mocap::Skeleton& skeleton,
                                 std::span<const glm::mat4> bind_model_from_joint,
                                 const Mesh& bind_mesh, const SwdRigOptions& options) {
  if (bind_mesh.positions.empty()) {
    return base::InvalidArgument("SWD rig: the mesh has no vertices");
  }
  if (!bind_mesh.normals.empty() && bind_mesh.normals.size() != bind_mesh.positions.size()) {
    return base::InvalidArgument("SWD rig: expected one normal per vertex (" +
                                 std::to_string(bind_mesh.positions.size()) + "), found " +
                                 std::to_string(bind_mesh.normals.size()));
  }
  if (!(options.max_bend_rad > 0.0 && options.max_bend_rad <= 3.2)) {
    return base::InvalidArgument("SWD rig: max_bend_rad must be in (0, 3.2]");
  }
  base::Result<BodyChains> tree =
      BuildBodyChains(skeleton, bind_model_from_joint, options.min_branch_extent);
  if (!tree.ok()) return std::move(tree).error();
  const std::vector<BodyPoint>& pts = tree->points;
  const std::vector<BodyChain>& body = tree->chains;

  // Cut every chain into pieces of at most kMaxSweepBones bones sharing one bone.
  std::vector<Piece> pieces;
  std::vector<int> first_piece(body.size(), 0);
  for (std::size_t c = 0; c < body.size(); ++c) {
    first_piece[c] = static_cast<int>(pieces.size());
    const int num_bones = static_cast<int>(body[c].points.size()) - 1;
    int start = 0;
    while (true) {
      const int end = std::min(num_bones, start + kMaxSweepBones);
      pieces.push_back({static_cast<int>(c), start, end});
      if (end == num_bones) break;
      start = end - 1;
    }
  }
  if (pieces.size() > static_cast<std::size_t>(kMaxSwdChains)) {
    return MakeError(ErrorCode::kLimitExceeded, {skeleton.info.source_file, 0, 0, {}},
                     "SWD: the skeleton splits into " + std::to_string(pieces.size()) +
                         " sweeps, more than the " + std::to_string(kMaxSwdChains) +
                         " one body can use (use --global ssd or dqs)");
  }

  SwdRig rig;
  const auto nj = static_cast<std::size_t>(skeleton.num_joints());
  rig.joint_from_bind_.resize(nj);
  for (std::size_t j = 0; j < nj; ++j) {
    rig.joint_from_bind_[j] = glm::inverse(bind_model_from_joint[j]);
  }
  for (std::size_t p = 0; p < pieces.size(); ++p) {
    const Piece& piece = pieces[p];
    const BodyChain& chain = body[static_cast<std::size_t>(piece.body_chain)];
    SweepChainSpec spec;
    std::vector<double> lengths;
    for (int i = piece.first; i <= piece.last; ++i) {
      const BodyPoint& pt = pts[static_cast<std::size_t>(chain.points[static_cast<std::size_t>(i)])];
      spec.rest_points.push_back(pt.pos);
      if (i > piece.first) {
        spec.joints.push_back(pt.bone_joint);
        lengths.push_back(glm::distance(spec.rest_points[spec.rest_points.size() - 2], pt.pos));
      }
    }
    const int k_bones = static_cast<int>(spec.joints.size());
    // Limbs: the longest pair of bones meets at the elbow or knee; the joint after it
    // (wrist, ankle) spreads its twist upstream.
    spec.twist_spread.assign(static_cast<std::size_t>(k_bones + 1), TwistSpread::kDownstream);
    const bool limb = chain.kind == BodyChainKind::kLimb && piece.first == 0;
    if (limb && k_bones >= 2) {
      SwdLimb l;
      l.chain = static_cast<int>(p);
      l.middle = LimbMiddleJoint(lengths);
      l.has_end = l.middle + 1 < k_bones;
      if (l.has_end) spec.twist_spread[static_cast<std::size_t>(l.middle + 1)] = TwistSpread::kUpstream;
      const BodyChain& parent = body[static_cast<std::size_t>(chain.parent_chain)];
      l.arm = !(parent.kind == BodyChainKind::kSpine && parent.points[0] == chain.points[0]);
      rig.limbs_.push_back(l);
    }
    // Region half-widths from the skin radius near each interior joint.
    spec.half_widths.assign(static_cast<std::size_t>(k_bones + 1), 0.0f);
    for (int k = 1; k < k_bones; ++k) {
      const double r = SkinRadiusNearJoint(spec, k, bind_mesh.positions);
      const double lin = lengths[static_cast<std::size_t>(k - 1)];
      const double lout = lengths[static_cast<std::size_t>(k)];
      const double radius = r > 0.0 ? r : 0.1 * std::min(lin, lout);
      spec.half_widths[static_cast<std::size_t>(k)] =
          static_cast<float>(DefaultHalfWidth(radius, options.max_bend_rad, lin, lout));
    }
    base::Result<SweepChain> sweep = BuildSweepChain(spec);
    if (!sweep.ok()) {
      base::Error e = std::move(sweep).error();
      e.message = "SWD: body chain " + std::to_string(piece.body_chain) +
                  " cannot carry a sweep: " + e.message;
      return e;
    }
    rig.chains_.push_back(std::move(*sweep));
    // Junction with the trunk: the previous piece of the same chain, else the parent
    // chain's piece holding the branch point.
    int trunk = -1;
    float seam = 0.0f;
    if (piece.first > 0) {
      trunk = static_cast<int>(p) - 1;
    } else if (chain.parent_chain >= 0) {
      const BodyChain& parent = body[static_cast<std::size_t>(chain.parent_chain)];
      const auto at = std::find(parent.points.begin(), parent.points.end(), chain.points[0]);
      const int index = static_cast<int>(at - parent.points.begin());
      trunk = first_piece[static_cast<std::size_t>(chain.parent_chain)];
      while (trunk + 1 < static_cast<int>(pieces.size()) &&
             pieces[static_cast<std::size_t>(trunk + 1)].body_chain == chain.parent_chain &&
             pieces[static_cast<std::size_t>(trunk)].last <= index) {
        ++trunk;
      }
      seam = static_cast<float>(lengths[0]);
    }
    if (trunk >= 0) {
      SweepJunction junction;
      junction.branch = static_cast<int>(p);
      junction.trunk = trunk;
      junction.u_start = 0.0f;
      junction.u_end = 1.0f;
      junction.seam_band = seam;
      rig.junctions_.push_back(junction);
    }
  }
  // The seam fade keeps the junction weight continuous where the primary sweep switches
  // between trunk and branch inside one surface. A mesh of several parts binds each part
  // to one family whose primary is always the branch, so there is no such switch; there
  // the fade only pulled a limb lying against the trunk bones at its branch point in the
  // bind pose (LAFAN's upper arm raised beside the neck, mocapbank's forearm hanging
  // beside the belly) halfway onto the trunk, and tore it off when they separated.
  if (CountParts(bind_mesh) > 1) {
    for (SweepJunction& junction : rig.junctions_) junction.seam_band = 0.0f;
  }
  // Vertices placed by their generator: the last piece of their chain starting at or
  // before u (in a piece's first bone the junction blends it with the piece before).
  const std::size_t nv = bind_mesh.positions.size();
  std::vector<SweepPlacement> placements;
  std::vector<std::uint8_t> placed;
  if (!options.vertex_chains.empty()) {
    if (options.vertex_chains.size() != nv) {
      return base::InvalidArgument("SWD rig: expected one body chain coordinate per vertex (" +
                                   std::to_string(nv) + "), found " +
                                   std::to_string(options.vertex_chains.size()));
    }
    placements.resize(nv);
    placed.assign(nv, 0);
    for (std::size_t v = 0; v < nv; ++v) {
      const BodyChainCoord& coord = options.vertex_chains[v];
      if (coord.chain < 0) continue;
      if (coord.chain >= static_cast<int>(body.size()) || !std::isfinite(coord.u) ||
          coord.u < 0.0f ||
          coord.u > static_cast<float>(body[static_cast<std::size_t>(coord.chain)].points.size() - 1)) {
        return base::InvalidArgument(
            "SWD rig: vertex " + std::to_string(v) + " lies on body chain " +
            std::to_string(coord.chain) + " at u = " + std::to_string(coord.u) +
            ", which the skeleton's " + std::to_string(body.size()) +
            " chains do not have (a mesh made for another skeleton or pose?)");
      }
      int p = first_piece[static_cast<std::size_t>(coord.chain)];
      while (p + 1 < static_cast<int>(pieces.size()) &&
             pieces[static_cast<std::size_t>(p + 1)].body_chain == coord.chain &&
             static_cast<float>(pieces[static_cast<std::size_t>(p + 1)].first) <= coord.u) {
        ++p;
      }
      placements[v] = {p, coord.u - static_cast<float>(pieces[static_cast<std::size_t>(p)].first)};
      placed[v] = 1;
    }
  }
  // Bind each connected part of the mesh to its own chains (see BindByComponent).
  std::vector<int> piece_chain(pieces.size());
  for (std::size_t p = 0; p < pieces.size(); ++p) piece_chain[p] = pieces[p].body_chain;
  const bool all_placed =
      !placed.empty() && std::find(placed.begin(), placed.end(), std::uint8_t{0}) == placed.end();
  std::vector<SweepVertexBinding> by_distance(nv);
  if (!all_placed) {
    base::Result<std::vector<SweepVertexBinding>> bindings =
        BindByComponent(rig.chains_, rig.junctions_, piece_chain, bind_mesh, placed);
    if (!bindings.ok()) return std::move(bindings).error();
    by_distance = std::move(*bindings);
  }
  rig.bindings_ = std::move(by_distance);
  if (!placed.empty()) {
    std::vector<glm::vec3> positions;
    std::vector<SweepPlacement> where;
    for (std::size_t v = 0; v < nv; ++v) {
      if (placed[v] == 0) continue;
      positions.push_back(bind_mesh.positions[v]);
      where.push_back(placements[v]);
    }
    base::Result<std::vector<SweepVertexBinding>> bound =
        BindToSweeps(rig.chains_, rig.junctions_, positions, {}, where);
    if (!bound.ok()) return std::move(bound).error();
    std::size_t i = 0;
    for (std::size_t v = 0; v < nv; ++v) {
      if (placed[v] != 0) rig.bindings_[v] = (*bound)[i++];
    }
  }
  rig.rest_normals_ = bind_mesh.normals;
  return rig;
}

base::Result<std::vector<SweepVertexBinding>> BindPointsLikeVertices(
    const SwdRig& rig, std::span<const glm::vec3> points, std::span<const int> guides) {
  if (points.size() != guides.size()) {
    return base::InvalidArgument("SWD: expected one guide vertex per point (" +
                                 std::to_string(points.size()) + "), found " +
                                 std::to_string(guides.size()));
  }
  std::vector<int> trunk_of(rig.chains().size(), -1);
  for (const SweepJunction& j : rig.junctions()) {
    trunk_of[static_cast<std::size_t>(j.branch)] = j.trunk;
  }
  std::vector<SweepVertexBinding> out(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const int g = guides[i];
    if (g < 0 || g >= rig.num_vertices()) {
      return base::InvalidArgument("SWD: point " + std::to_string(i) + " has guide vertex " +
                                   std::to_string(g) + ", expected 0.." +
                                   std::to_string(rig.num_vertices() - 1));
    }
    // The guide's sweeps: its own, its junction's trunk, and its second sweep.
    const SweepVertexBinding& guide = rig.bindings()[static_cast<std::size_t>(g)];
    std::vector<int> set{guide.primary.chain};
    const int trunk = trunk_of[guide.primary.chain];
    if (trunk >= 0) set.push_back(trunk);
    if (guide.weight < 1.0f && std::find(set.begin(), set.end(), guide.secondary.chain) == set.end()) {
      set.push_back(guide.secondary.chain);
    }
    std::vector<SweepChain> sub;
    for (int c : set) sub.push_back(rig.chains()[static_cast<std::size_t>(c)]);
    std::vector<std::uint8_t> primary_ok(set.size(), 0);
    primary_ok[0] = 1;  // the guide's own sweep; the others through its junction only
    std::vector<SweepJunction> sub_junctions;
    for (SweepJunction j : rig.junctions()) {
      const auto b = std::find(set.begin(), set.end(), j.branch);
      const auto t = std::find(set.begin(), set.end(), j.trunk);
      if (b == set.end() || t == set.end()) continue;
      j.branch = static_cast<int>(b - set.begin());
      j.trunk = static_cast<int>(t - set.begin());
      sub_junctions.push_back(j);
    }
    base::Result<std::vector<SweepVertexBinding>> b =
        BindToSweeps(sub, sub_junctions, points.subspan(i, 1), primary_ok);
    if (!b.ok()) {
      base::Error e = std::move(b).error();
      e.message = "SWD: point " + std::to_string(i) + ": " + e.message;
      return e;
    }
    SweepVertexBinding vb = (*b)[0];
    vb.primary.chain = static_cast<std::uint16_t>(set[vb.primary.chain]);
    vb.secondary.chain = static_cast<std::uint16_t>(set[vb.secondary.chain]);
    out[i] = vb;
  }
  return out;
}

JobStatus ComputeSwdJointState(const SwdRig& rig, std::span<const glm::mat4> model_from_joint,
                               std::span<glm::quat> joint_rotations,
                               std::span<glm::vec3> joint_positions) {
  const auto nj = static_cast<std::size_t>(rig.num_joints());
  if (model_from_joint.size() != nj || joint_rotations.size() != nj ||
      joint_positions.size() != nj) {
    return {JobStatus::kSizeMismatch, "SWD joint state: spans are not one entry per rig joint"};
  }
  for (std::size_t j = 0; j < nj; ++j) {
    const glm::mat4 delta = model_from_joint[j] * rig.joint_from_bind()[j];
    glm::mat3 r(delta);
    for (int c = 0; c < 3; ++c) {  // drop any scale: dQ is a rotation
      const float len = glm::length(r[c]);
      if (len > 0.0f) r[c] /= len;
    }
    joint_rotations[j] = glm::normalize(glm::quat_cast(r));
    joint_positions[j] = glm::vec3(model_from_joint[j][3]);
  }
  return {};
}

JobStatus SwdRigJob::Run() const {
  if (rig == nullptr) return {JobStatus::kMissingInput, "SwdRigJob without a rig"};
  const auto nj = static_cast<std::size_t>(rig->num_joints());
  if (model_from_joint.size() != nj) {
    return {JobStatus::kSizeMismatch, "model_from_joint is not one matrix per rig joint"};
  }
  if (joint_rotations.size() != nj || joint_positions.size() != nj) {
    return {JobStatus::kSizeMismatch, "joint scratch is not one entry per rig joint"};
  }
  if (vertex_begin < 0 ||
      static_cast<std::size_t>(vertex_begin) + positions.size() >
          static_cast<std::size_t>(rig->num_vertices())) {
    return {JobStatus::kOutOfRange, "vertex range past the rig's vertices"};
  }
  if (!normals.empty() && normals.size() != positions.size()) {
    return {JobStatus::kSizeMismatch, "normals and positions differ in size"};
  }
  if (!normals.empty() && rig->rest_normals().empty()) {
    return {JobStatus::kMissingInput, "normal output but the rig's mesh has no normals"};
  }
  const JobStatus state =
      ComputeSwdJointState(*rig, model_from_joint, joint_rotations, joint_positions);
  if (!state) return state;
  const auto begin = static_cast<std::size_t>(vertex_begin);
  return SwdJob{.chains = rig->chains(),
                .joint_rotations = joint_rotations,
                .joint_positions = joint_positions,
                .bindings = rig->bindings().subspan(begin, positions.size()),
                .rest_normals = normals.empty()
                                    ? std::span<const glm::vec3>()
                                    : rig->rest_normals().subspan(begin, positions.size()),
                .keep_volume = keep_volume,
                .section_scales = {},
                .positions = positions,
                .normals = normals}
      .Run();
}

}  // namespace deform
