#pragma once
// Closed tubes of elliptic rings: the surface builder behind the mannequin.
// Private to the deform module.

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace deform::internal {

// One cross-section of a tube: an ellipse in the plane normal to `tangent`,
// with the two skeleton joints (and weights) its vertices follow.
struct Ring {
  glm::vec3 center{0.0f};
  glm::vec3 tangent{0.0f, 0.0f, 1.0f};  // unit, the direction the tube runs
  glm::vec3 n{1.0f, 0.0f, 0.0f};        // frame: n, b = tangent x n, both unit
  glm::vec3 b{0.0f, 1.0f, 0.0f};
  float radius = 1.0f;     // long radius, model units
  glm::vec3 minor{0.0f};   // preferred short axis of the ellipse (any length; projected)
  float flatten = 1.0f;    // short radius / long radius, 1 = circle
  int joint[2] = {0, 0};   // skeleton joints
  float weight[2] = {1.0f, 0.0f};
  int chain = -1;          // body chain the tube follows (-1: none), see BodyChainCoord
  float chain_u = 0.0f;    // chain coordinate of the ring (bone index + fraction)
};

// 3x^2 - 2x^3 on x clamped to [0, 1].
float Smoothstep(float x);

// Unit vector normal to unit `t`, as close to `hint` as possible (any
// normal when hint runs along t).
glm::vec3 AnyPerpendicular(const glm::vec3& t, const glm::vec3& hint);

// Centripetal Catmull-Rom point between p1 and p2 at t in [0, 1]
// (Barry-Goldman pyramid; no cusps or self-loops within a segment).
glm::vec3 CatmullRom(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2,
                     const glm::vec3& p3, float t);

// Collects mesh data; every tube or ellipsoid is emitted as one closed component.
struct MeshBuilder {
  std::vector<glm::vec3> positions;    // #V
  std::vector<glm::uvec3> triangles;   // #T, counter-clockwise seen from outside
  std::vector<int> joints;             // #V x 2 skeleton joints
  std::vector<float> weights;          // #V x 2
  std::vector<int> chains;             // #V body chain of the ring (Ring::chain)
  std::vector<float> chain_u;          // #V chain coordinate of the ring (Ring::chain_u)

  std::uint32_t AddVertex(const glm::vec3& p, const Ring& r);
  // Rings in order along their tangents (at least one), closed by a pole
  // before the first and after the last: ring_vertices x #rings + 2 vertices.
  void AddClosedTube(const std::vector<Ring>& rings, const glm::vec3& start_pole,
                     const glm::vec3& end_pole, int ring_vertices);
};

// Rings of domed caps (kCapRings each) before and after `rings`, `depth`
// radii deep; returns all rings in order and sets the two poles.
inline constexpr int kCapRings = 3;
std::vector<Ring> WithCaps(const std::vector<Ring>& rings, float depth, glm::vec3& start_pole,
                           glm::vec3& end_pole);

}  // namespace deform::internal
