#pragma once
// Small generated meshes for the patch tests and benchmark: a bumpy sheet, an
// open tube (part of a cylinder) and a sphere cap. Triangles are
// counter-clockwise seen from outside (+z for the sheet and cap, away from
// the axis for the tube).

#include <cmath>
#include <numbers>
#include <vector>

#include "deform/mesh.h"

namespace testsupport {

// Grid of nx x ny vertices (index i*ny + j) with two triangles per cell.
inline void GridTriangles(int nx, int ny, std::vector<glm::uvec3>& tris) {
  for (int i = 0; i + 1 < nx; ++i) {
    for (int j = 0; j + 1 < ny; ++j) {
      const unsigned a = static_cast<unsigned>(i * ny + j), b = static_cast<unsigned>((i + 1) * ny + j);
      tris.emplace_back(a, b, b + 1);
      tris.emplace_back(a, b + 1, a + 1);
    }
  }
}

// Sheet over [0,size] x [0,0.6 size] in x,y (not square, so the plane map's
// first axis is x) with z = amp sin(2 pi x/size) cos(pi y/size).
inline deform::Mesh MakeBumpySheet(int nx, int ny, float size, float amp) {
  deform::Mesh m;
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < ny; ++j) {
      const float x = size * static_cast<float>(i) / static_cast<float>(nx - 1);
      const float y = 0.6f * size * static_cast<float>(j) / static_cast<float>(ny - 1);
      const float z = amp * std::sin(2.0f * std::numbers::pi_v<float> * x / size) *
                      std::cos(std::numbers::pi_v<float> * y / size);
      m.positions.emplace_back(x, y, z);
    }
  }
  GridTriangles(nx, ny, m.triangles);
  return m;
}

// Part of a cylinder about the z axis: angles phi0 .. phi0 + span_deg, heights
// 0 .. height; n_around x n_along vertices.
inline deform::Mesh MakeTube(int n_around, int n_along, float radius, float span_deg,
                             float height, float phi0_deg = -90.0f) {
  deform::Mesh m;
  const float deg = std::numbers::pi_v<float> / 180.0f;
  for (int i = 0; i < n_around; ++i) {
    const float phi = (phi0_deg + span_deg * static_cast<float>(i) / static_cast<float>(n_around - 1)) * deg;
    for (int j = 0; j < n_along; ++j) {
      const float h = height * static_cast<float>(j) / static_cast<float>(n_along - 1);
      m.positions.emplace_back(radius * std::cos(phi), radius * std::sin(phi), h);
    }
  }
  GridTriangles(n_around, n_along, m.triangles);
  return m;
}

// Cap of a sphere of radius r about +z: a grid over [-a,a]^2 lifted onto it.
inline deform::Mesh MakeSphereCap(int n, float radius, float a) {
  deform::Mesh m;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const float x = -a + 2.0f * a * static_cast<float>(i) / static_cast<float>(n - 1);
      const float y = -a + 2.0f * a * static_cast<float>(j) / static_cast<float>(n - 1);
      m.positions.emplace_back(x, y, std::sqrt(radius * radius - x * x - y * y));
    }
  }
  GridTriangles(n, n, m.triangles);
  return m;
}

// 0 .. count-1: every vertex of a mesh as its region.
inline std::vector<int> AllVertices(const deform::Mesh& m) {
  std::vector<int> out(m.positions.size());
  for (size_t i = 0; i < out.size(); ++i) out[i] = static_cast<int>(i);
  return out;
}

}  // namespace testsupport
