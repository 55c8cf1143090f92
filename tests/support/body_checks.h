#pragma once
// Checks every generated body must pass (tests/deform/body/, tests/app/generated_body_swd_test.cpp): closed, manifold
// and consistently oriented, no degenerate triangles, one connected piece, and weights
// that sum to 1, are non-negative and sit on a bone near the vertex.

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <span>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "deform/mesh.h"

namespace testsupport {

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

}  // namespace testsupport
