#include "deform/body/bone_heat.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

namespace deform {
namespace {

using base::ErrorCode;
using base::MakeError;

constexpr int kSolveBlock = 32;        // right-hand sides solved together
constexpr int kVisibilitySamples = 12;  // tests along each vertex-to-bone segment
constexpr double kMaxCot = 1e3;        // cotangents of near-degenerate corners are capped

glm::vec3 NearestOnSegment(const BodyBone& b, const glm::vec3& p) {
  const glm::vec3 ab = b.b - b.a;
  const float len2 = glm::dot(ab, ab);
  const float t = len2 > 0.0f ? std::clamp(glm::dot(p - b.a, ab) / len2, 0.0f, 1.0f) : 0.0f;
  return b.a + t * ab;
}

// The nearest bones of vertex p that see it: their indices (ties within 0.01 %) and the
// distance; none when no bone is visible.
struct Nearest {
  std::vector<int> bones;
  float distance = 0.0f;
};

Nearest NearestVisibleBones(const glm::vec3& p, std::span<const BodyBone> bones,
                            const std::function<float(const glm::vec3&)>& distance, float tolerance,
                            std::vector<std::pair<float, int>>& order) {
  order.clear();
  for (std::size_t b = 0; b < bones.size(); ++b) {
    order.emplace_back(glm::distance(p, NearestOnSegment(bones[b], p)), static_cast<int>(b));
  }
  std::sort(order.begin(), order.end());
  Nearest out;
  for (const auto& [d, b] : order) {
    if (!out.bones.empty()) {
      if (d > out.distance * 1.0001f) break;
      out.bones.push_back(b);  // tied with the first visible bone
      continue;
    }
    const glm::vec3 q = NearestOnSegment(bones[static_cast<std::size_t>(b)], p);
    bool visible = true;
    for (int s = 1; s <= kVisibilitySamples && visible; ++s) {
      const float t = static_cast<float>(s) / static_cast<float>(kVisibilitySamples);
      visible = distance(p + t * (q - p)) < tolerance;
    }
    if (visible) out.bones.push_back(b), out.distance = d;
  }
  return out;
}

double Cot(const glm::dvec3& a, const glm::dvec3& b) {  // cotangent of the angle between a and b
  const double s = glm::length(glm::cross(a, b));
  return std::clamp(glm::dot(a, b) / std::max(s, 1e-300), -kMaxCot, kMaxCot);
}

}  // namespace

base::Result<BoneHeatWeights> ComputeBoneHeatWeights(
    const Mesh& mesh, std::span<const BodyBone> bones,
    const std::function<float(const glm::vec3&)>& distance, float size, const BoneHeatOptions& o) {
  if (!(o.heat > 0.0f) || o.max_influences < 1 || o.max_influences > 4 || !(o.inside_tolerance >= 0.0f)) {
    return base::InvalidArgument("bone heat options out of range (heat > 0, max_influences 1..4)");
  }
  if (bones.empty()) return base::InvalidArgument("bone heat needs at least one bone");
  const std::size_t nv = mesh.positions.size();
  // Joints that own bones, ascending: the unknowns' columns.
  std::vector<int> joints;
  for (const BodyBone& b : bones) joints.push_back(b.joint);
  std::sort(joints.begin(), joints.end());
  joints.erase(std::unique(joints.begin(), joints.end()), joints.end());
  const auto column_of = [&joints](int joint) {
    return static_cast<int>(std::lower_bound(joints.begin(), joints.end(), joint) - joints.begin());
  };

  // Vertex areas and the cotangent Laplacian (double: the sums cancel).
  std::vector<double> area(nv, 0.0);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(mesh.triangles.size() * 9 + nv);
  for (const glm::uvec3& t : mesh.triangles) {
    const glm::dvec3 p[3] = {glm::dvec3(mesh.positions[t.x]), glm::dvec3(mesh.positions[t.y]),
                             glm::dvec3(mesh.positions[t.z])};
    const double a = 0.5 * glm::length(glm::cross(p[1] - p[0], p[2] - p[0]));
    for (int i = 0; i < 3; ++i) area[t[i]] += a / 3.0;
    for (int i = 0; i < 3; ++i) {  // the corner at i weighs the opposite edge (j, k)
      const int j = (i + 1) % 3, k = (i + 2) % 3;
      const double w = 0.5 * Cot(p[j] - p[i], p[k] - p[i]);
      entries.emplace_back(static_cast<int>(t[j]), static_cast<int>(t[k]), -w);
      entries.emplace_back(static_cast<int>(t[k]), static_cast<int>(t[j]), -w);
      entries.emplace_back(static_cast<int>(t[j]), static_cast<int>(t[j]), w);
      entries.emplace_back(static_cast<int>(t[k]), static_cast<int>(t[k]), w);
    }
  }

  // Heat sources: each vertex's nearest visible bones.
  const float tolerance = o.inside_tolerance * size;
  std::vector<double> heat(nv, 0.0);
  std::vector<std::vector<int>> source(nv);
  std::vector<std::pair<float, int>> order;
  bool any = false;
  for (std::size_t v = 0; v < nv; ++v) {
    Nearest n = NearestVisibleBones(mesh.positions[v], bones, distance, tolerance, order);
    if (n.bones.empty()) continue;
    const double d = std::max(static_cast<double>(n.distance), 1e-4 * static_cast<double>(size));
    heat[v] = static_cast<double>(o.heat) * static_cast<double>(n.bones.size()) / (d * d);
    source[v] = std::move(n.bones);
    any = true;
  }
  if (!any) {  // no vertex sees a bone (a body far from its skeleton): nearest ones heat
    for (std::size_t v = 0; v < nv; ++v) {
      Nearest n = NearestVisibleBones(mesh.positions[v], bones, [](const glm::vec3&) { return -1.0f; }, 0.0f, order);
      const double d = std::max(static_cast<double>(n.distance), 1e-4 * static_cast<double>(size));
      heat[v] = static_cast<double>(o.heat) * static_cast<double>(n.bones.size()) / (d * d);
      source[v] = std::move(n.bones);
    }
  }
  for (std::size_t v = 0; v < nv; ++v) {
    entries.emplace_back(static_cast<int>(v), static_cast<int>(v), area[v] * heat[v]);
  }
  Eigen::SparseMatrix<double> system(static_cast<Eigen::Index>(nv), static_cast<Eigen::Index>(nv));
  system.setFromTriplets(entries.begin(), entries.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(system);
  if (ldlt.info() != Eigen::Success) {
    return base::InvalidArgument(
        "bone heat: the surface's Laplacian could not be factorised (not one closed piece?)");
  }

  // Solve in blocks of joints, keeping each vertex's largest weights.
  const auto m = static_cast<std::size_t>(o.max_influences);
  BoneHeatWeights out;
  out.influences = o.max_influences;
  out.joints.assign(nv * m, -1);
  out.weights.assign(nv * m, 0.0f);
  for (std::size_t first = 0; first < joints.size(); first += kSolveBlock) {
    const std::size_t count = std::min<std::size_t>(kSolveBlock, joints.size() - first);
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(nv), static_cast<Eigen::Index>(count));
    for (std::size_t v = 0; v < nv; ++v) {
      for (const int b : source[v]) {
        const auto col = static_cast<std::size_t>(column_of(bones[static_cast<std::size_t>(b)].joint));
        if (col < first || col >= first + count) continue;
        rhs(static_cast<Eigen::Index>(v), static_cast<Eigen::Index>(col - first)) +=
            area[v] * heat[v] / static_cast<double>(source[v].size());
      }
    }
    const Eigen::MatrixXd w = ldlt.solve(rhs);
    for (std::size_t v = 0; v < nv; ++v) {
      for (std::size_t c = 0; c < count; ++c) {
        const auto value = static_cast<float>(w(static_cast<Eigen::Index>(v), static_cast<Eigen::Index>(c)));
        if (!(value > 0.0f)) continue;
        // Insert into the vertex's descending list (ties keep the lower joint first).
        float* ws = &out.weights[v * m];
        int* js = &out.joints[v * m];
        std::size_t at = m;
        while (at > 0 && (js[at - 1] < 0 || ws[at - 1] < value)) --at;
        if (at >= m) continue;
        for (std::size_t s = m - 1; s > at; --s) ws[s] = ws[s - 1], js[s] = js[s - 1];
        ws[at] = value;
        js[at] = joints[first + c];
      }
    }
  }
  for (std::size_t v = 0; v < nv; ++v) {
    float sum = 0.0f;
    for (std::size_t s = 0; s < m; ++s) sum += out.weights[v * m + s];
    if (sum > 1e-6f) {
      for (std::size_t s = 0; s < m; ++s) out.weights[v * m + s] /= sum;
      continue;
    }
    // All weights vanished (no heat reached it): its nearest bone, whatever it sees.
    const Nearest n = NearestVisibleBones(mesh.positions[v], bones, [](const glm::vec3&) { return -1.0f; }, 0.0f, order);
    std::fill(&out.joints[v * m], &out.joints[v * m] + m, -1);
    std::fill(&out.weights[v * m], &out.weights[v * m] + m, 0.0f);
    out.joints[v * m] = bones[static_cast<std::size_t>(n.bones[0])].joint;
    out.weights[v * m] = 1.0f;
  }
  return out;
}

}  // namespace deform
