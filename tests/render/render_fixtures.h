#pragma once
// Small scenes and independent reference computations for the render tests.

#include <cmath>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "render/camera.h"

namespace rendertest {

struct TriMesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::uvec3> triangles;
};

// A closed UV sphere (one vertex per pole), outward-facing counter-clockwise
// triangles and analytic unit normals.
inline TriMesh MakeSphere(glm::vec3 centre, float radius, int rings, int segments) {
  TriMesh m;
  const double pi = 3.14159265358979323846;
  auto add = [&](double theta, double phi) {
    const glm::vec3 n(static_cast<float>(std::sin(theta) * std::cos(phi)),
                      static_cast<float>(std::cos(theta)),
                      static_cast<float>(std::sin(theta) * std::sin(phi)));
    m.positions.push_back(centre + radius * n);
    m.normals.push_back(n);
  };
  add(0.0, 0.0);
  for (int i = 1; i < rings; ++i)
    for (int j = 0; j < segments; ++j) add(pi * i / rings, 2.0 * pi * j / segments);
  add(pi, 0.0);
  const auto ring = [&](int i, int j) {
    return static_cast<unsigned>(1 + (i - 1) * segments + (j % segments));
  };
  const auto bottom = static_cast<unsigned>(m.positions.size() - 1);
  for (int j = 0; j < segments; ++j) {
    m.triangles.push_back({0u, ring(1, j), ring(1, j + 1)});
    for (int i = 1; i + 1 < rings; ++i) {
      m.triangles.push_back({ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
      m.triangles.push_back({ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
    }
    m.triangles.push_back({ring(rings - 1, j), bottom, ring(rings - 1, j + 1)});
  }
  // Make every triangle counter-clockwise seen from outside.
  for (glm::uvec3& t : m.triangles) {
    const glm::vec3 a = m.positions[t.x], b = m.positions[t.y], c = m.positions[t.z];
    if (glm::dot(glm::cross(b - a, c - a), (a + b + c) / 3.0f - centre) < 0.0f) std::swap(t.y, t.z);
  }
  return m;
}

// World-space ray through the centre of pixel (x, y) of a width x height
// image, built from the camera's basis (independent of GLM's matrices).
struct Ray {
  glm::dvec3 origin;
  glm::dvec3 dir;  // not normalized; t = 1 lies on the image plane at view depth 1
};
inline Ray PixelRay(const render::Camera& cam, int width, int height, double x, double y) {
  const glm::dvec3 f = glm::normalize(glm::dvec3(cam.target) - glm::dvec3(cam.eye));
  const glm::dvec3 r = glm::normalize(glm::cross(f, glm::dvec3(cam.up)));
  const glm::dvec3 u = glm::cross(r, f);
  const double t = std::tan(0.5 * static_cast<double>(cam.fov_y_deg) * 3.14159265358979323846 / 180.0);
  const double ndc_x = (x + 0.5) / width * 2.0 - 1.0;
  const double ndc_y = 1.0 - (y + 0.5) / height * 2.0;
  return {glm::dvec3(cam.eye), f + r * (ndc_x * t * static_cast<double>(cam.aspect)) + u * (ndc_y * t)};
}

// Ray parameter of the nearest hit with a sphere, if any.
inline std::optional<double> HitSphere(const Ray& ray, glm::dvec3 centre, double radius) {
  const glm::dvec3 oc = ray.origin - centre;
  const double a = glm::dot(ray.dir, ray.dir), b = glm::dot(oc, ray.dir);
  const double c = glm::dot(oc, oc) - radius * radius;
  const double disc = b * b - a * c;
  if (disc < 0.0) return std::nullopt;
  return (-b - std::sqrt(disc)) / a;
}

// Ray-triangle hit: t and barycentrics (of b and c), Moller-Trumbore in double.
struct TriangleHit {
  double t, u, v;
};
inline std::optional<TriangleHit> HitTriangle(const Ray& ray, glm::dvec3 a, glm::dvec3 b,
                                              glm::dvec3 c) {
  const glm::dvec3 e1 = b - a, e2 = c - a;
  const glm::dvec3 p = glm::cross(ray.dir, e2);
  const double det = glm::dot(e1, p);
  if (std::abs(det) < 1e-14) return std::nullopt;
  const glm::dvec3 s = ray.origin - a;
  const double u = glm::dot(s, p) / det;
  const glm::dvec3 q = glm::cross(s, e1);
  const double v = glm::dot(ray.dir, q) / det;
  const double t = glm::dot(e2, q) / det;
  return TriangleHit{t, u, v};
}

}  // namespace rendertest
