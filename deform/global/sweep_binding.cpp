// Binding of rest points to sweep chains (ALGORITHMS.md 2.3, "Binding"): root-finding on
// the rest centre curve, nearest-chain assignment, junction weights, section axes.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "deform/global/sweep.h"
#include "deform/internal/checks.h"

namespace deform {
namespace {

using base::ErrorCode;
using base::MakeError;

float Smoothstep(float x) {
  const float y = std::clamp(x, 0.0f, 1.0f);
  return y * y * (3.0f - 2.0f * y);
}

using internal::Finite;

double PointSegmentDistance(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b) {
  const glm::dvec3 ab = b - a;
  const double t = std::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0, 1.0);
  return glm::length(p - (a + t * ab));
}


// Bones [first, last] of a chain.
struct BoneRange {
  int first = 0;
  int last = std::numeric_limits<int>::max();
};

// Distance from p to the nearest rest bone segment of the chain (of `bones` only).
double NearestBoneDistance(const SweepChain& chain, const glm::dvec3& p, BoneRange bones = {}) {
  const BasicSweepPose<double>& rest = chain.rest_pose();
  double nearest = std::numeric_limits<double>::max();
  const int last = std::min(bones.last, chain.num_bones() - 1);
  for (int k = std::max(0, bones.first); k <= last; ++k) {
    const auto ks = static_cast<std::size_t>(k);
    nearest = std::min(nearest, PointSegmentDistance(p, rest.points[ks], rest.points[ks + 1]));
  }
  return nearest;
}

// Principal direction, within the plane orthogonal to unit `tangent`, of the symmetric
// second-moment matrix m; any in-plane unit vector when the section is round.
glm::dvec3 PrincipalInPlane(const glm::dmat3& m, const glm::dvec3& tangent) {
  const glm::dvec3 helper =
      std::abs(tangent.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  const glm::dvec3 e1 = glm::normalize(glm::cross(tangent, helper));
  const glm::dvec3 e2 = glm::cross(tangent, e1);
  const double a = glm::dot(e1, m * e1), b = glm::dot(e1, m * e2), c = glm::dot(e2, m * e2);
  const double angle = 0.5 * std::atan2(2.0 * b, a - c);  // major axis of [[a b][b c]]
  return std::cos(angle) * e1 + std::sin(angle) * e2;
}

// The joint region holding u (its interior joint index), or -1 between regions. Section
// axes are pooled per region rather than per ring: a nearly round ring has no stable
// principal direction, and the axis must vary continuously along u for the skin to.
int SectionBin(const SweepChain& chain, float u) {
  int joint = -1;
  float x = 0.0f;
  return SweepRegionAt(chain, u, &joint, &x) ? joint : -1;
}

void AssignSectionAxes(std::span<const SweepChain> chains,
                       std::vector<SweepVertexBinding>& bindings) {
  std::vector<std::vector<glm::dmat3>> moments(chains.size());
  for (std::size_t c = 0; c < chains.size(); ++c) {
    moments[c].assign(static_cast<std::size_t>(chains[c].num_bones() + 1), glm::dmat3(0.0));
  }
  auto accumulate = [&](const SweepBinding& b) {
    const glm::dvec3 o(b.offset);
    const int bin = SectionBin(chains[b.chain], b.u);
    if (bin >= 0) moments[b.chain][static_cast<std::size_t>(bin)] += glm::outerProduct(o, o);
  };
  for (const SweepVertexBinding& v : bindings) {
    accumulate(v.primary);
    if (v.weight < 1.0f) accumulate(v.secondary);
  }
  auto assign = [&](SweepBinding& b) {
    const SweepChain& chain = chains[b.chain];
    const int bin = SectionBin(chain, b.u);
    if (bin < 0) return;  // between regions: no elliptic scaling applies
    glm::dvec3 tangent;
    SweepCentre(chain, chain.rest_pose(), static_cast<double>(b.u), &tangent);
    const glm::dmat3& m = moments[b.chain][static_cast<std::size_t>(bin)];
    b.section_axis = glm::vec3(PrincipalInPlane(m, glm::normalize(tangent)));
  };
  for (SweepVertexBinding& v : bindings) {
    assign(v.primary);
    if (v.weight < 1.0f) assign(v.secondary);
  }
}


}  // namespace

SweepBinding BindToSweep(const SweepChain& chain, int chain_index, const glm::dvec3& rest_point,
                         double u_min, double u_max) {
  const BasicSweepPose<double>& rest = chain.rest_pose();
  const int num_bones = chain.num_bones();
  const double u_lo = std::clamp(u_min, 0.0, static_cast<double>(num_bones));
  const double u_hi = u_max < 0.0 ? static_cast<double>(num_bones)
                                  : std::clamp(u_max, u_lo, static_cast<double>(num_bones));
  constexpr int kSamplesPerBone = 64;
  constexpr double kRootTolerance = 1e-9;
  auto g = [&](double u) {
    glm::dvec3 tangent;
    const glm::dvec3 c = SweepCentre(chain, rest, u, &tangent);
    return glm::dot(rest_point - c, glm::normalize(tangent));
  };
  double best_u = 0.0;
  double best_distance = std::numeric_limits<double>::max();
  auto consider = [&](double u) {
    const double distance = glm::length(rest_point - SweepCentre<double>(chain, rest, u, nullptr));
    if (distance < best_distance) {
      best_distance = distance;
      best_u = u;
    }
  };
  const int num_samples = kSamplesPerBone * num_bones;
  double u_prev = u_lo;
  double g_prev = g(u_lo);
  if (g_prev == 0.0) consider(u_lo);
  for (int i = 1; i <= num_samples; ++i) {
    const double u = std::min(u_hi, static_cast<double>(i) / kSamplesPerBone);
    if (u <= u_prev) continue;  // before the range, or past its end
    const double g_u = g(u);
    if (g_u == 0.0) {
      consider(u);
    } else if (g_prev != 0.0 && (g_prev < 0.0) != (g_u < 0.0)) {
      double lo = u_prev, hi = u, g_lo = g_prev;
      while (hi - lo > kRootTolerance) {
        const double mid = 0.5 * (lo + hi);
        const double g_mid = g(mid);
        if ((g_mid < 0.0) == (g_lo < 0.0)) {
          lo = mid;
          g_lo = g_mid;
        } else {
          hi = mid;
        }
      }
      consider(0.5 * (lo + hi));
    }
    u_prev = u;
    g_prev = g_u;
  }
  // The chain's ends compete with the roots, not only when there is no root: a point
  // beyond an end (a toe or finger tip, a cap) can also lie in the normal plane of a
  // distant, bent part of the chain (the thigh, the upper arm). That root is a
  // critical point of the distance but not the nearest point of the curve; binding to it
  // gave offsets of half the body, swung by every turn of the limb (a torn foot or hand).
  consider(u_lo);
  consider(u_hi);
  SweepBinding binding;
  binding.u = static_cast<float>(best_u);
  // The offset is measured from c0 at the stored (float-rounded) u, so the rebuild at the
  // bind pose reproduces the point up to float rounding.
  const glm::dvec3 c = SweepCentre<double>(chain, rest, static_cast<double>(binding.u), nullptr);
  binding.offset = glm::vec3(rest_point - c);
  binding.chain = static_cast<std::uint16_t>(chain_index);
  return binding;
}

base::Result<std::vector<SweepVertexBinding>> BindToSweeps(
    std::span<const SweepChain> chains, std::span<const SweepJunction> junctions,
    std::span<const glm::vec3> rest_positions, std::span<const std::uint8_t> primary_ok,
    std::span<const SweepPlacement> placements) {
  if (chains.empty() || chains.size() > std::numeric_limits<std::uint16_t>::max()) {
    return base::InvalidArgument("expected 1..65535 sweep chains, found " +
                                 std::to_string(chains.size()));
  }
  if (!primary_ok.empty() &&
      (primary_ok.size() != chains.size() ||
       std::find(primary_ok.begin(), primary_ok.end(), std::uint8_t{1}) == primary_ok.end())) {
    return base::InvalidArgument("expected one primary flag per chain, at least one set");
  }
  const int num_chains = static_cast<int>(chains.size());
  if (!placements.empty() && placements.size() != rest_positions.size()) {
    return base::InvalidArgument("expected one placement per vertex (" +
                                 std::to_string(rest_positions.size()) + "), found " +
                                 std::to_string(placements.size()));
  }
  for (std::size_t v = 0; v < placements.size(); ++v) {
    if (placements[v].chain >= num_chains || !std::isfinite(placements[v].u)) {
      return base::InvalidArgument("placement of vertex " + std::to_string(v) +
                                   ": expected a chain below " + std::to_string(num_chains) +
                                   " and a finite u, found chain " +
                                   std::to_string(placements[v].chain));
    }
  }
  std::vector<const SweepJunction*> junction_of(chains.size(), nullptr);
  for (std::size_t j = 0; j < junctions.size(); ++j) {
    const SweepJunction& junction = junctions[j];
    const std::string where = "junction " + std::to_string(j);
    if (junction.branch < 0 || junction.branch >= num_chains || junction.trunk < 0 ||
        junction.trunk >= num_chains || junction.branch == junction.trunk) {
      return base::InvalidArgument(where + ": expected two different chain indices below " +
                                   std::to_string(num_chains));
    }
    const auto branch_bones = static_cast<float>(chains[static_cast<std::size_t>(junction.branch)]
                                                     .num_bones());
    if (!(junction.u_start >= 0.0f && junction.u_start < junction.u_end &&
          junction.u_end <= branch_bones)) {
      return base::InvalidArgument(where + ": expected 0 <= u_start < u_end <= branch bone count");
    }
    if (!(junction.seam_band >= 0.0f && std::isfinite(junction.seam_band))) {
      return base::InvalidArgument(where + ": expected a finite seam band >= 0");
    }
    if (junction_of[static_cast<std::size_t>(junction.branch)] != nullptr) {
      return base::InvalidArgument(where + ": chain " + std::to_string(junction.branch) +
                                   " is already the branch of another junction");
    }
    junction_of[static_cast<std::size_t>(junction.branch)] = &junction;
  }
  // Per branch: the two trunk bones meeting at the trunk point nearest the branch's
  // start (its branch point), which alone count for the seam fade.
  std::vector<BoneRange> trunk_bones(chains.size());
  for (const SweepJunction& junction : junctions) {
    const SweepChain& trunk = chains[static_cast<std::size_t>(junction.trunk)];
    const glm::dvec3 start = chains[static_cast<std::size_t>(junction.branch)].rest_pose().points[0];
    int at = 0;
    for (int k = 1; k <= trunk.num_bones(); ++k) {
      if (glm::distance(trunk.rest_pose().points[static_cast<std::size_t>(k)], start) <
          glm::distance(trunk.rest_pose().points[static_cast<std::size_t>(at)], start)) {
        at = k;
      }
    }
    trunk_bones[static_cast<std::size_t>(junction.branch)] = {at - 1, at};
  }
  std::vector<SweepVertexBinding> bindings(rest_positions.size());
  for (std::size_t v = 0; v < rest_positions.size(); ++v) {
    if (!Finite(rest_positions[v])) {
      return base::InvalidArgument("rest vertex " + std::to_string(v) + " is not finite");
    }
    const glm::dvec3 p(rest_positions[v]);
    SweepVertexBinding& binding = bindings[v];
    int nearest = 0;
    double nearest_distance = std::numeric_limits<double>::max();
    if (!placements.empty() && placements[v].chain >= 0) {
      nearest = placements[v].chain;
      const SweepChain& chain = chains[static_cast<std::size_t>(nearest)];
      nearest_distance = NearestBoneDistance(chain, p);
      binding.primary.chain = static_cast<std::uint16_t>(nearest);
      binding.primary.u =
          std::clamp(placements[v].u, 0.0f, static_cast<float>(chain.num_bones()));
      binding.primary.offset = glm::vec3(
          p - SweepCentre<double>(chain, chain.rest_pose(), static_cast<double>(binding.primary.u), nullptr));
    } else {
      for (int c = 0; c < num_chains; ++c) {
        if (!primary_ok.empty() && primary_ok[static_cast<std::size_t>(c)] == 0) continue;
        const double d = NearestBoneDistance(chains[static_cast<std::size_t>(c)], p);
        if (d < nearest_distance) {
          nearest_distance = d;
          nearest = c;
        }
      }
      binding.primary = BindToSweep(chains[static_cast<std::size_t>(nearest)], nearest, p);
    }
    const SweepJunction* junction = junction_of[static_cast<std::size_t>(nearest)];
    if (junction != nullptr) {
      const float x = (binding.primary.u - junction->u_start) / (junction->u_end - junction->u_start);
      binding.weight = Smoothstep(x);
      if (junction->seam_band > 0.0f) {
        // Fade to the trunk where the trunk becomes the nearest chain, so the weight is
        // 0 on both sides of that boundary (ours; the spec's rule jumps there). Only the
        // trunk bones at the branch point count: a branch lying against a far part of
        // the trunk in the bind pose (a forearm raised beside the head, a foot kicked up
        // to it) must not blend with it; that tore the body apart when they separated.
        const double trunk_distance =
            NearestBoneDistance(chains[static_cast<std::size_t>(junction->trunk)], p,
                                trunk_bones[static_cast<std::size_t>(nearest)]);
        binding.weight *= Smoothstep(
            static_cast<float>((trunk_distance - nearest_distance) / junction->seam_band));
      }
      if (binding.weight < 1.0f) {
        // On the trunk near the branch point only: the nearest point of the whole trunk
        // can be a far part lying against the branch in the bind pose (the head beside
        // a raised arm, a hanging hand beside the hip).
        const BoneRange near = trunk_bones[static_cast<std::size_t>(nearest)];
        binding.secondary =
            BindToSweep(chains[static_cast<std::size_t>(junction->trunk)], junction->trunk, p,
                        std::max(0, near.first), near.last + 1.0);
      }
    }
  }
  AssignSectionAxes(chains, bindings);
  return bindings;
}

}  // namespace deform
