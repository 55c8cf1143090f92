#include "deform/body/internal/tube_mesh.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace deform::internal {

float Smoothstep(float x) {
  x = std::clamp(x, 0.0f, 1.0f);
  return x * x * (3.0f - 2.0f * x);
}

glm::vec3 AnyPerpendicular(const glm::vec3& t, const glm::vec3& hint) {
  glm::vec3 p = hint - glm::dot(hint, t) * t;
  if (glm::length(p) < 1e-3f) {
    const glm::vec3 axis = std::abs(t.x) < 0.8f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
    p = axis - glm::dot(axis, t) * t;
  }
  return glm::normalize(p);
}

// Centripetal Catmull-Rom point between p1 and p2 (Barry-Goldman pyramid).
glm::vec3 CatmullRom(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2,
                     const glm::vec3& p3, float t) {
  const auto knot = [](const glm::vec3& a, const glm::vec3& b) {
    return std::max(std::sqrt(glm::length(b - a)), 1e-6f);
  };
  const float t0 = 0.0f;
  const float t1 = t0 + knot(p0, p1);
  const float t2 = t1 + knot(p1, p2);
  const float t3 = t2 + knot(p2, p3);
  const float u = t1 + t * (t2 - t1);
  const glm::vec3 a1 = ((t1 - u) * p0 + (u - t0) * p1) / (t1 - t0);
  const glm::vec3 a2 = ((t2 - u) * p1 + (u - t1) * p2) / (t2 - t1);
  const glm::vec3 a3 = ((t3 - u) * p2 + (u - t2) * p3) / (t3 - t2);
  const glm::vec3 b1 = ((t2 - u) * a1 + (u - t0) * a2) / (t2 - t0);
  const glm::vec3 b2 = ((t3 - u) * a2 + (u - t1) * a3) / (t3 - t1);
  return ((t2 - u) * b1 + (u - t1) * b2) / (t2 - t1);
}

std::uint32_t MeshBuilder::AddVertex(const glm::vec3& p, const Ring& r) {
  positions.push_back(p);
  joints.insert(joints.end(), {r.joint[0], r.joint[1]});
  weights.insert(weights.end(), {r.weight[0], r.weight[1]});
  chains.push_back(r.chain);
  chain_u.push_back(r.chain_u);
  return static_cast<std::uint32_t>(positions.size() - 1);
}


// Rings in order along their tangents, closed by a pole before the first
// and after the last. Triangles wind counter-clockwise seen from outside:
// ring vertices turn from n toward b, i.e. counter-clockwise about the tangent.
void MeshBuilder::AddClosedTube(const std::vector<Ring>& rings, const glm::vec3& start_pole,
                   const glm::vec3& end_pole, int ring_vertices) {
  const std::uint32_t rv = static_cast<std::uint32_t>(ring_vertices);
  const std::uint32_t first_pole = AddVertex(start_pole, rings.front());
  const std::uint32_t first_ring = static_cast<std::uint32_t>(positions.size());
  for (const Ring& r : rings) {
    glm::vec3 minor = r.minor - glm::dot(r.minor, r.tangent) * r.tangent;
    const float minor_len = glm::length(minor);
    // Where the preferred short axis runs along the tube, fall back to a circle.
    const float f = 1.0f + (r.flatten - 1.0f) * Smoothstep((minor_len - 0.2f) / 0.3f);
    minor = minor_len > 1e-6f ? minor / minor_len : r.n;
    for (std::uint32_t k = 0; k < rv; ++k) {
      const float theta = 2.0f * std::numbers::pi_v<float> * static_cast<float>(k) /
                          static_cast<float>(rv);
      glm::vec3 d = std::cos(theta) * r.n + std::sin(theta) * r.b;
      d -= (1.0f - f) * glm::dot(d, minor) * minor;  // squash along the short axis
      AddVertex(r.center + r.radius * d, r);
    }
  }
  const std::uint32_t last_pole = AddVertex(end_pole, rings.back());
  const std::uint32_t num_rings = static_cast<std::uint32_t>(rings.size());
  for (std::uint32_t k = 0; k < rv; ++k) {
    const std::uint32_t k1 = (k + 1) % rv;
    triangles.push_back({first_pole, first_ring + k1, first_ring + k});
    const std::uint32_t last = first_ring + (num_rings - 1) * rv;
    triangles.push_back({last_pole, last + k, last + k1});
    for (std::uint32_t i = 0; i + 1 < num_rings; ++i) {
      const std::uint32_t a = first_ring + i * rv;
      const std::uint32_t b = a + rv;
      triangles.push_back({a + k, a + k1, b + k1});
      triangles.push_back({a + k, b + k1, b + k});
    }
  }
}

// Adds domed caps: returns the rings with cap rings before and after, and the poles.
std::vector<Ring> WithCaps(const std::vector<Ring>& rings, float depth, glm::vec3& start_pole,
                           glm::vec3& end_pole) {
  std::vector<Ring> out;
  const Ring& s = rings.front();
  for (int j = kCapRings; j >= 1; --j) {
    const float phi = static_cast<float>(j) * std::numbers::pi_v<float> /
                      (2.0f * static_cast<float>(kCapRings + 1));
    Ring r = s;
    r.center = s.center - s.tangent * (depth * s.radius * std::sin(phi));
    r.radius = s.radius * std::cos(phi);
    out.push_back(r);
  }
  start_pole = s.center - s.tangent * (depth * s.radius);
  out.insert(out.end(), rings.begin(), rings.end());
  const Ring& e = rings.back();
  for (int j = 1; j <= kCapRings; ++j) {
    const float phi = static_cast<float>(j) * std::numbers::pi_v<float> /
                      (2.0f * static_cast<float>(kCapRings + 1));
    Ring r = e;
    r.center = e.center + e.tangent * (depth * e.radius * std::sin(phi));
    r.radius = e.radius * std::cos(phi);
    out.push_back(r);
  }
  end_pole = e.center + e.tangent * (depth * e.radius);
  return out;
}

}  // namespace deform::internal
