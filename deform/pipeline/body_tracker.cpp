#include "deform/pipeline/body_tracker.h"

#include <algorithm>
#include <numeric>
#include <limits>
#include <string>

namespace deform {
namespace {

// Directions of the 5x5x5 grid around its centre, one per line through it
// (gcd of the coordinates 1): 98 directions, at most about 13 degrees from any
// other direction. Not normalised: only the argmax along each matters.
std::vector<glm::vec3> HullDirections() {
  std::vector<glm::vec3> d;
  for (int x = -2; x <= 2; ++x) {
    for (int y = -2; y <= 2; ++y) {
      for (int z = -2; z <= 2; ++z) {
        if (std::gcd(std::gcd(x, y), z) == 1) d.emplace_back(x, y, z);
      }
    }
  }
  return d;
}

// Per skin joint, the vertices it moves (weight >= kHullWeight) that lie
// furthest along each hull direction of its bind frame; sorted, unique. A
// vertex blended between two joints is in both their hulls, so bends are covered.
constexpr float kHullWeight = 0.25f;

std::vector<int> HullVertices(const SkinnedMesh& mesh) {
  const std::vector<glm::vec3> directions = HullDirections();
  const std::size_t nd = directions.size();
  const std::size_t ns = mesh.joint_from_bind.size();
  std::vector<float> best_along(ns * nd, -std::numeric_limits<float>::infinity());
  std::vector<int> best_vertex(ns * nd, -1);
  const SkinWeights& w = mesh.weights;
  const auto k = static_cast<std::size_t>(w.influences);
  const int nv = mesh.bind.num_vertices();
  for (int v = 0; v < nv; ++v) {
    for (std::size_t slot = static_cast<std::size_t>(v) * k;
         slot < (static_cast<std::size_t>(v) + 1) * k; ++slot) {
      const std::size_t s = w.joints[slot];
      if (!(w.weights[slot] >= kHullWeight) || s >= ns) continue;
      const glm::vec3 local =
          glm::vec3(mesh.joint_from_bind[s] *
                    glm::vec4(mesh.bind.positions[static_cast<std::size_t>(v)], 1.0f));
      for (std::size_t d = 0; d < nd; ++d) {
        const float along = glm::dot(local, directions[d]);
        if (along > best_along[s * nd + d]) {
          best_along[s * nd + d] = along;
          best_vertex[s * nd + d] = v;
        }
      }
    }
  }
  std::vector<int> hull;
  for (const int v : best_vertex) {
    if (v >= 0) hull.push_back(v);
  }
  std::sort(hull.begin(), hull.end());
  hull.erase(std::unique(hull.begin(), hull.end()), hull.end());
  return hull;
}

}  // namespace

base::Result<BodyTracker> BodyTracker::Create(const Character& character,
                                              std::span<const int> tracked) {
  const SkinnedMesh& mesh = character.mesh;
  const int nv = mesh.bind.num_vertices();
  for (const int v : tracked) {
    if (v < 0 || v >= nv) {
      return base::InvalidArgument({character.source, 0, 0, {}},
                                   "tracked vertex " + std::to_string(v) +
                                       " is not one of the mesh's " + std::to_string(nv) +
                                       " vertices");
    }
  }
  BodyTracker t(character);
  t.hull_vertices_ = HullVertices(mesh);
  t.num_tracked_ = static_cast<int>(tracked.size());
  std::vector<int> points = t.hull_vertices_;
  points.insert(points.end(), tracked.begin(), tracked.end());
  const auto k = static_cast<std::size_t>(mesh.weights.influences);
  t.weights_.influences = mesh.weights.influences;
  for (const int v : points) {
    const auto at = static_cast<std::size_t>(v);
    t.rest_.push_back(mesh.bind.positions[at]);
    const auto row = static_cast<std::ptrdiff_t>(at * k);
    t.weights_.joints.insert(t.weights_.joints.end(), mesh.weights.joints.begin() + row,
                             mesh.weights.joints.begin() + row + static_cast<std::ptrdiff_t>(k));
    t.weights_.weights.insert(t.weights_.weights.end(), mesh.weights.weights.begin() + row,
                              mesh.weights.weights.begin() + row + static_cast<std::ptrdiff_t>(k));
  }
  t.posed_.resize(points.size());
  return t;
}

base::Status BodyTracker::Sample(double time_s, TrackedBody& out) {
  const Character& c = *character_;
  if (base::Status s = pose_.Sample(c, time_s); !s.ok()) return s;
  base::JobStatus s = palettes_.Update(pose_.model_from_joint, c.mesh, /*dqs=*/false);
  if (!s) return StageError(c, s, "skinning palette");
  const int n = static_cast<int>(rest_.size());
  s = SkinPoints(palettes_.view(), weights_, rest_, {}, 0, n, posed_, {});
  if (!s) return StageError(c, s, "hull skinning");

  out.joint_positions.resize(pose_.model_from_joint.size());
  for (std::size_t j = 0; j < pose_.model_from_joint.size(); ++j) {
    out.joint_positions[j] = glm::vec3(pose_.model_from_joint[j][3]);
  }
  const std::size_t num_hull = hull_vertices_.size();
  out.hull_bounds = ComputeBounds(std::span<const glm::vec3>(posed_).first(num_hull));
  out.tracked.assign(posed_.begin() + static_cast<std::ptrdiff_t>(num_hull), posed_.end());
  return base::Status::Ok();
}

}  // namespace deform
