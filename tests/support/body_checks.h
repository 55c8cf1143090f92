#pragma once
// Checks every generated body must pass (tests/deform/body/, tests/app/generated_body_swd_test.cpp): closed, manifold
// and consistently oriented, no degenerate triangles, one connected piece, no
// self-intersection, and weights that sum to 1, are non-negative and sit on a bone near
// the vertex.

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <tuple>
#include <cstdint>
#include <numeric>
#include <span>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "deform/mesh.h"

namespace testsupport {

// The largest growth of a triangle edge from `rest` to `pos` (deformed minus
// rest length) over the body's size: a tear (a part following the wrong bone)
// opens gaps of a limb's radius, several percent.
inline float MaxEdgeGrowthFraction(const deform::Mesh& rest, std::span<const glm::vec3> pos) {
  float worst = 0.0f;
  for (const glm::uvec3& t : rest.triangles) {
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = t[e], b = t[(e + 1) % 3];
      worst = std::max(worst, glm::distance(pos[a], pos[b]) -
                                  glm::distance(rest.positions[a], rest.positions[b]));
    }
  }
  const glm::vec3 e = deform::ComputeBounds(rest.positions).size();
  return worst / std::max({e.x, e.y, e.z});
}

// Directed edges that are not matched by exactly one opposite edge (0: closed, manifold
// and consistently oriented).
inline int BadEdges(const deform::Mesh& mesh) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
  for (const glm::uvec3& t : mesh.triangles) {
    edges.emplace_back(t.x, t.y);
    edges.emplace_back(t.y, t.z);
    edges.emplace_back(t.z, t.x);
  }
  std::sort(edges.begin(), edges.end());
  int bad = 0;
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const bool duplicate = (i > 0 && edges[i - 1] == edges[i]) || (i + 1 < edges.size() && edges[i + 1] == edges[i]);
    const bool matched = std::binary_search(edges.begin(), edges.end(), std::make_pair(edges[i].second, edges[i].first));
    if (duplicate || !matched) ++bad;
  }
  return bad;
}

// Number of connected pieces (vertices joined by triangles; unreferenced vertices count).
inline int ConnectedPieces(const deform::Mesh& mesh) {
  std::vector<std::uint32_t> parent(mesh.positions.size());
  std::iota(parent.begin(), parent.end(), 0u);
  const auto find = [&parent](std::uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (const glm::uvec3& t : mesh.triangles) {
    parent[find(t.y)] = find(t.x);
    parent[find(t.z)] = find(t.x);
  }
  int pieces = 0;
  for (std::uint32_t i = 0; i < parent.size(); ++i) pieces += find(i) == i ? 1 : 0;
  return pieces;
}

// Smallest triangle area over the square of the mean edge length (0 for a degenerate one).
inline double SmallestRelativeArea(const deform::Mesh& mesh) {
  double edge_sum = 0.0;
  for (const glm::uvec3& t : mesh.triangles) edge_sum += glm::distance(mesh.positions[t.x], mesh.positions[t.y]);
  const double mean = edge_sum / static_cast<double>(std::max<std::size_t>(mesh.triangles.size(), 1));
  double smallest = 1e30;
  for (const glm::uvec3& t : mesh.triangles) {
    const glm::dvec3 a(mesh.positions[t.x]), b(mesh.positions[t.y]), c(mesh.positions[t.z]);
    smallest = std::min(smallest, 0.5 * glm::length(glm::cross(b - a, c - a)) / (mean * mean));
  }
  return smallest;
}

// Enclosed volume (divergence theorem; positive for outward-facing triangles).
inline double EnclosedVolume(std::span<const glm::vec3> positions, std::span<const glm::uvec3> triangles) {
  const glm::dvec3 o = positions.empty() ? glm::dvec3(0.0) : glm::dvec3(positions[0]);
  double v = 0.0;
  for (const glm::uvec3& t : triangles) {
    v += glm::dot(glm::dvec3(positions[t.x]) - o,
                  glm::cross(glm::dvec3(positions[t.y]) - o, glm::dvec3(positions[t.z]) - o));
  }
  return v / 6.0;
}

// True when segment p-q crosses triangle abc at a point inside both (Moller-Trumbore, in
// double; touching within a relative 1e-9 does not count, so shared edges and vertices of
// a closed mesh never do).
inline bool SegmentCrossesTriangle(const glm::dvec3& p, const glm::dvec3& q, const glm::dvec3& a,
                                   const glm::dvec3& b, const glm::dvec3& c) {
  constexpr double kEps = 1e-9;
  const glm::dvec3 d = q - p, e1 = b - a, e2 = c - a;
  const glm::dvec3 h = glm::cross(d, e2);
  const double det = glm::dot(e1, h);
  if (std::abs(det) <= kEps * glm::length(d) * glm::length(e1) * glm::length(e2)) return false;  // parallel
  const glm::dvec3 s = p - a;
  const double u = glm::dot(s, h) / det;
  const glm::dvec3 qv = glm::cross(s, e1);
  const double v = glm::dot(d, qv) / det;
  const double t = glm::dot(e2, qv) / det;
  return u > kEps && v > kEps && u + v < 1.0 - kEps && t > kEps && t < 1.0 - kEps;
}

// Pairs of triangles that share no vertex and cross each other (one's edge passes through
// the other's interior). Triangles are binned by their bounding boxes into a uniform grid
// of cells about two mean edges wide, so the cost is about linear in the triangle count.
inline int SelfIntersectingPairs(const deform::Mesh& mesh) {
  const auto& pos = mesh.positions;
  const auto& tri = mesh.triangles;
  if (tri.empty()) return 0;
  double edge_sum = 0.0;
  glm::dvec3 lo(1e300), hi(-1e300);
  for (const glm::uvec3& t : tri) edge_sum += glm::distance(glm::dvec3(pos[t.x]), glm::dvec3(pos[t.y]));
  for (const glm::vec3& p : pos) lo = glm::min(lo, glm::dvec3(p)), hi = glm::max(hi, glm::dvec3(p));
  const double cell = std::max(2.0 * edge_sum / static_cast<double>(tri.size()), 1e-12);
  const auto cell_of = [&](const glm::dvec3& p) {
    return glm::ivec3(glm::floor((p - lo) / cell));
  };
  std::map<std::tuple<int, int, int>, std::vector<std::uint32_t>> grid;
  for (std::uint32_t i = 0; i < tri.size(); ++i) {
    const glm::uvec3& t = tri[i];
    const glm::dvec3 a(pos[t.x]), b(pos[t.y]), c(pos[t.z]);
    const glm::ivec3 c0 = cell_of(glm::min(a, glm::min(b, c))), c1 = cell_of(glm::max(a, glm::max(b, c)));
    for (int x = c0.x; x <= c1.x; ++x)
      for (int y = c0.y; y <= c1.y; ++y)
        for (int z = c0.z; z <= c1.z; ++z) grid[{x, y, z}].push_back(i);
  }
  const auto crosses = [&](const glm::uvec3& s, const glm::uvec3& t) {
    const std::array<glm::dvec3, 3> p{glm::dvec3(pos[s.x]), glm::dvec3(pos[s.y]), glm::dvec3(pos[s.z])};
    const std::array<glm::dvec3, 3> q{glm::dvec3(pos[t.x]), glm::dvec3(pos[t.y]), glm::dvec3(pos[t.z])};
    for (int k = 0; k < 3; ++k) {
      if (SegmentCrossesTriangle(p[k], p[(k + 1) % 3], q[0], q[1], q[2])) return true;
      if (SegmentCrossesTriangle(q[k], q[(k + 1) % 3], p[0], p[1], p[2])) return true;
    }
    return false;
  };
  std::vector<std::pair<std::uint32_t, std::uint32_t>> found;
  for (const auto& [key, members] : grid) {
    for (std::size_t i = 0; i < members.size(); ++i) {
      for (std::size_t j = i + 1; j < members.size(); ++j) {
        const glm::uvec3 &s = tri[members[i]], &t = tri[members[j]];
        bool shared = false;
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b) shared = shared || s[a] == t[b];
        if (!shared && crosses(s, t)) found.emplace_back(members[i], members[j]);
      }
    }
  }
  std::sort(found.begin(), found.end());  // a pair met in several cells counts once
  return static_cast<int>(std::unique(found.begin(), found.end()) - found.begin());
}

}  // namespace testsupport
