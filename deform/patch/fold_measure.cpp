#include "deform/patch/fold_measure.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <tuple>

namespace deform {

std::vector<int> RegionTriangles(std::span<const glm::uvec3> triangles, std::span<const int> region,
                                 int num_vertices) {
  std::vector<std::uint8_t> in(static_cast<std::size_t>(std::max(num_vertices, 0)), 0);
  for (int v : region) {
    if (v >= 0 && v < num_vertices) in[static_cast<std::size_t>(v)] = 1;
  }
  std::vector<int> out;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const glm::uvec3& tri = triangles[t];
    bool all = true;
    for (int k = 0; k < 3; ++k) all = all && tri[k] < in.size() && in[tri[k]] != 0;
    if (all) out.push_back(static_cast<int>(t));
  }
  return out;
}

double MaxFoldAngleDeg(std::span<const glm::vec3> positions, std::span<const glm::uvec3> triangles,
                       std::span<const int> subset) {
  // (edge low vertex, edge high vertex, triangle) for every edge of a usable triangle.
  std::vector<std::tuple<unsigned, unsigned, int>> edges;
  std::vector<glm::dvec3> normal(triangles.size(), glm::dvec3(0.0));
  for (int t : subset) {
    if (t < 0 || static_cast<std::size_t>(t) >= triangles.size()) continue;
    const glm::uvec3& tri = triangles[static_cast<std::size_t>(t)];
    if (tri.x >= positions.size() || tri.y >= positions.size() || tri.z >= positions.size()) continue;
    const glm::dvec3 p0(positions[tri.x]), p1(positions[tri.y]), p2(positions[tri.z]);
    const glm::dvec3 n = glm::cross(p1 - p0, p2 - p0);
    const double len = glm::length(n);
    if (!(len > 0.0)) continue;                      // degenerate: no normal
    normal[static_cast<std::size_t>(t)] = n / len;
    for (int k = 0; k < 3; ++k) {
      const unsigned a = tri[k], b = tri[(k + 1) % 3];
      edges.emplace_back(std::min(a, b), std::max(a, b), t);
    }
  }
  std::sort(edges.begin(), edges.end());
  double worst = 0.0;
  for (std::size_t e = 0; e + 1 < edges.size(); ++e) {
    const auto& [a0, b0, t0] = edges[e];
    // Every pair of triangles on the same edge (a non-manifold edge has more than two).
    for (std::size_t f = e + 1; f < edges.size(); ++f) {
      const auto& [a1, b1, t1] = edges[f];
      if (a1 != a0 || b1 != b0) break;
      if (t1 == t0) continue;
      const double c = glm::dot(normal[static_cast<std::size_t>(t0)], normal[static_cast<std::size_t>(t1)]);
      worst = std::max(worst, std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / std::numbers::pi);
    }
  }
  return worst;
}

namespace {

// Unit normal of triangle t over `p`, or zero when degenerate.
glm::dvec3 UnitNormal(std::span<const glm::vec3> p, const glm::uvec3& tri) {
  const glm::dvec3 p0(p[tri.x]), p1(p[tri.y]), p2(p[tri.z]);
  const glm::dvec3 n = glm::cross(p1 - p0, p2 - p0);
  const double len = glm::length(n);
  return len > 0.0 ? n / len : glm::dvec3(0.0);
}

double AngleDeg(const glm::dvec3& a, const glm::dvec3& b) {
  return std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

}  // namespace

double MaxAddedFoldAngleDeg(std::span<const glm::vec3> before, std::span<const glm::vec3> after,
                            std::span<const glm::uvec3> triangles, std::span<const int> subset) {
  const std::size_t nv = std::min(before.size(), after.size());
  std::vector<std::tuple<unsigned, unsigned, int>> edges;
  for (int t : subset) {
    if (t < 0 || static_cast<std::size_t>(t) >= triangles.size()) continue;
    const glm::uvec3& tri = triangles[static_cast<std::size_t>(t)];
    if (tri.x >= nv || tri.y >= nv || tri.z >= nv) continue;
    for (int k = 0; k < 3; ++k) {
      const unsigned a = tri[k], b = tri[(k + 1) % 3];
      edges.emplace_back(std::min(a, b), std::max(a, b), t);
    }
  }
  std::sort(edges.begin(), edges.end());
  double worst = 0.0;
  bool any = false;
  for (std::size_t e = 0; e + 1 < edges.size(); ++e) {
    const auto& [a0, b0, t0] = edges[e];
    for (std::size_t f = e + 1; f < edges.size() && std::get<0>(edges[f]) == a0 && std::get<1>(edges[f]) == b0; ++f) {
      const int t1 = std::get<2>(edges[f]);
      if (t1 == t0) continue;
      const glm::uvec3 &u = triangles[static_cast<std::size_t>(t0)], &w = triangles[static_cast<std::size_t>(t1)];
      const glm::dvec3 nb0 = UnitNormal(before, u), nb1 = UnitNormal(before, w);
      const glm::dvec3 na0 = UnitNormal(after, u), na1 = UnitNormal(after, w);
      if (nb0 == glm::dvec3(0.0) || nb1 == glm::dvec3(0.0) || na0 == glm::dvec3(0.0) || na1 == glm::dvec3(0.0)) continue;
      const double added = AngleDeg(na0, na1) - AngleDeg(nb0, nb1);
      worst = any ? std::max(worst, added) : added;
      any = true;
    }
  }
  return worst;
}

}  // namespace deform
