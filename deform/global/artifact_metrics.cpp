#include "deform/global/artifact_metrics.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <utility>

namespace deform {
namespace {

using base::ErrorCode;
using base::MakeError;

// Two unit vectors spanning the plane orthogonal to unit n.
void PlaneBasis(const glm::dvec3& n, glm::dvec3* e1, glm::dvec3* e2) {
  const glm::dvec3 helper = std::abs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  *e1 = glm::normalize(glm::cross(n, helper));
  *e2 = glm::cross(n, *e1);
}

}  // namespace

RingPlane BisectorPlane(const glm::vec3& joint, const glm::vec3& axis_in,
                        const glm::vec3& axis_out) {
  return {glm::dvec3(joint), glm::normalize(glm::dvec3(axis_in) + glm::dvec3(axis_out))};
}

double ProjectedRingArea(std::span<const glm::vec3> positions,
                         std::span<const std::uint32_t> ring, const RingPlane& plane) {
  if (ring.size() < 3) return 0.0;
  const glm::dvec3 n = glm::normalize(plane.normal);
  glm::dvec3 e1, e2;
  PlaneBasis(n, &e1, &e2);
  std::vector<std::pair<double, glm::dvec2>> points;  // (angle, in-plane coordinates)
  points.reserve(ring.size());
  glm::dvec2 centroid(0.0);
  for (const std::uint32_t index : ring) {
    const glm::dvec3 d = glm::dvec3(positions[index]) - plane.point;
    points.emplace_back(0.0, glm::dvec2(glm::dot(d, e1), glm::dot(d, e2)));
    centroid += points.back().second;
  }
  // Order around the ring's own centroid: the joint itself can lie near or outside the
  // section of a strongly bent sweep, whose centre moves inside the bend.
  centroid /= static_cast<double>(points.size());
  for (auto& [angle, q] : points) angle = std::atan2(q.y - centroid.y, q.x - centroid.x);
  std::sort(points.begin(), points.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  double twice_area = 0.0;  // shoelace formula
  for (std::size_t i = 0; i < points.size(); ++i) {
    const glm::dvec2& a = points[i].second;
    const glm::dvec2& b = points[(i + 1) % points.size()].second;
    twice_area += a.x * b.y - a.y * b.x;
  }
  return 0.5 * std::abs(twice_area);
}

base::Result<double> RingAreaRatio(std::span<const glm::vec3> rest_positions,
                                   std::span<const glm::vec3> positions, const ArtifactRing& ring) {
  if (rest_positions.size() != positions.size()) {
    return base::InvalidArgument("expected as many deformed as rest positions (" +
                                 std::to_string(rest_positions.size()) + "), found " +
                                 std::to_string(positions.size()));
  }
  if (ring.vertices.size() < 3) {
    return base::InvalidArgument("expected a ring of at least 3 vertices, found " +
                                 std::to_string(ring.vertices.size()));
  }
  for (const std::uint32_t index : ring.vertices) {
    if (index >= positions.size()) {
      return base::InvalidArgument("ring vertex " + std::to_string(index) + " is past the " +
                                   std::to_string(positions.size()) + " positions");
    }
  }
  const double rest_area = ProjectedRingArea(rest_positions, ring.vertices, ring.rest_plane);
  if (!(rest_area > 1e-12)) {
    return base::InvalidArgument("ring has no area at rest in its plane");
  }
  return ProjectedRingArea(positions, ring.vertices, ring.plane) / rest_area;
}

base::Result<double> CollapseFigure(std::span<const glm::vec3> rest_positions,
                                    std::span<const glm::vec3> positions,
                                    const ArtifactRing& ring) {
  return RingAreaRatio(rest_positions, positions, ring);
}

base::Result<double> CandyWrapperFigure(std::span<const glm::vec3> rest_positions,
                                        std::span<const glm::vec3> positions,
                                        std::span<const ArtifactRing> rings) {
  if (rings.empty()) {
    return base::InvalidArgument("expected at least one ring, found none");
  }
  double minimum = 0.0;
  for (std::size_t r = 0; r < rings.size(); ++r) {
    base::Result<double> ratio = RingAreaRatio(rest_positions, positions, rings[r]);
    if (!ratio) {
      base::Error error = std::move(ratio).error();
      error.message = "ring " + std::to_string(r) + ": " + error.message;
      return error;
    }
    minimum = r == 0 ? *ratio : std::min(minimum, *ratio);
  }
  return minimum;
}

base::Result<double> CappedVolume(std::span<const glm::vec3> positions,
                                  std::span<const glm::uvec3> triangles,
                                  std::span<const std::vector<std::uint32_t>> caps) {
  if (triangles.empty()) {
    return base::InvalidArgument("expected triangles, found none");
  }
  // Directed edge -> use count; an edge whose reverse is absent is on the boundary.
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
  double six_volume = 0.0;  // sum of det(a, b, c) = 6 x signed tetrahedron volumes from 0
  auto add_triangle = [&](const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
    six_volume += glm::dot(a, glm::cross(b, c));
  };
  for (const glm::uvec3& t : triangles) {
    if (t.x >= positions.size() || t.y >= positions.size() || t.z >= positions.size()) {
      return base::InvalidArgument("triangle index past the " + std::to_string(positions.size()) +
                                   " positions");
    }
    add_triangle(glm::dvec3(positions[t.x]), glm::dvec3(positions[t.y]),
                 glm::dvec3(positions[t.z]));
    ++edges[{t.x, t.y}];
    ++edges[{t.y, t.z}];
    ++edges[{t.z, t.x}];
  }
  std::map<std::uint32_t, std::size_t> cap_of;  // vertex -> cap index
  std::vector<glm::dvec3> centroids(caps.size(), glm::dvec3(0.0));
  for (std::size_t c = 0; c < caps.size(); ++c) {
    for (const std::uint32_t v : caps[c]) {
      if (v >= positions.size()) {
        return base::InvalidArgument("cap " + std::to_string(c) + " vertex " + std::to_string(v) +
                                     " is past the positions");
      }
      cap_of[v] = c;
      centroids[c] += glm::dvec3(positions[v]);
    }
    if (!caps[c].empty()) centroids[c] /= static_cast<double>(caps[c].size());
  }
  for (const auto& [edge, count] : edges) {
    if (edges.count({edge.second, edge.first}) != 0) continue;  // interior edge
    const auto from = cap_of.find(edge.first), to = cap_of.find(edge.second);
    if (from == cap_of.end() || to == cap_of.end() || from->second != to->second) {
      return base::InvalidArgument("boundary edge " + std::to_string(edge.first) + "-" +
                                   std::to_string(edge.second) + " is not on a cap ring");
    }
    // The cap triangle uses the edge reversed, so the closed surface stays consistent.
    for (int i = 0; i < count; ++i) {
      add_triangle(centroids[from->second], glm::dvec3(positions[edge.second]),
                   glm::dvec3(positions[edge.first]));
    }
  }
  return std::abs(six_volume) / 6.0;
}

base::Result<double> VolumeFigure(std::span<const glm::vec3> rest_positions,
                                  std::span<const glm::vec3> positions,
                                  std::span<const glm::uvec3> triangles,
                                  std::span<const std::vector<std::uint32_t>> caps) {
  if (rest_positions.size() != positions.size()) {
    return base::InvalidArgument("expected as many deformed as rest positions (" +
                                 std::to_string(rest_positions.size()) + "), found " +
                                 std::to_string(positions.size()));
  }
  base::Result<double> rest = CappedVolume(rest_positions, triangles, caps);
  if (!rest) return rest;
  if (!(*rest > 1e-12)) {
    return base::InvalidArgument("the section encloses no volume at rest");
  }
  base::Result<double> current = CappedVolume(positions, triangles, caps);
  if (!current) return current;
  return *current / *rest;
}

std::vector<std::uint32_t> RingNearPlane(std::span<const glm::vec3> rest_positions,
                                         const RingPlane& plane, double half_thickness) {
  const glm::dvec3 n = glm::normalize(plane.normal);
  std::vector<std::uint32_t> ring;
  for (std::size_t v = 0; v < rest_positions.size(); ++v) {
    if (std::abs(glm::dot(glm::dvec3(rest_positions[v]) - plane.point, n)) <= half_thickness) {
      ring.push_back(static_cast<std::uint32_t>(v));
    }
  }
  return ring;
}

std::vector<std::uint32_t> RingNearParameter(std::span<const SweepVertexBinding> bindings,
                                             int chain, float u_centre, float half_width) {
  std::vector<std::uint32_t> ring;
  for (std::size_t v = 0; v < bindings.size(); ++v) {
    const SweepBinding& b = bindings[v].primary;
    if (static_cast<int>(b.chain) == chain && std::abs(b.u - u_centre) < half_width) {
      ring.push_back(static_cast<std::uint32_t>(v));
    }
  }
  return ring;
}

}  // namespace deform
