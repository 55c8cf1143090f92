#pragma once
// The body scene of the render benchmarks: a ~50k-triangle body-like mesh
// (eleven subdivided ellipsoids) and the camera that frames it at about a
// third of the screen. Shared by raster_bench (our renderer) and
// llvmpipe_bench (Mesa's software OpenGL) so both draw the same scene. Part of
// the bench harness (bench/harness/timing.h has its contract); render only.

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "render/camera.h"

namespace bench {

struct BodyMesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::uvec3> triangles;
};

// Appends an ellipsoid (UV sphere scaled by `radii`) centred at `centre`.
inline void AddEllipsoid(BodyMesh& mesh, glm::vec3 centre, glm::vec3 radii, int rings, int segments) {
  const auto base = static_cast<unsigned>(mesh.positions.size());
  const double pi = 3.14159265358979323846;
  for (int i = 0; i <= rings; ++i) {
    for (int j = 0; j <= segments; ++j) {
      const double theta = pi * i / rings, phi = 2.0 * pi * j / segments;
      const glm::vec3 unit(static_cast<float>(std::sin(theta) * std::cos(phi)),
                           static_cast<float>(std::cos(theta)),
                           static_cast<float>(-std::sin(theta) * std::sin(phi)));
      mesh.positions.push_back(centre + radii * unit);
      mesh.normals.push_back(glm::normalize(unit / radii));
    }
  }
  const auto at = [&](int i, int j) {
    return base + static_cast<unsigned>(i * (segments + 1) + j);
  };
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      if (i > 0) mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i, j + 1)});
      if (i + 1 < rings) mesh.triangles.push_back({at(i, j + 1), at(i + 1, j), at(i + 1, j + 1)});
    }
  }
}

inline BodyMesh MakeBody() {
  BodyMesh body;
  const int r = 32, s = 72;  // 2 * 72 * 31 = 4464 triangles per part, 11 parts
  AddEllipsoid(body, {0.0f, 1.32f, 0.0f}, {0.30f, 0.32f, 0.17f}, r, s);    // chest
  AddEllipsoid(body, {0.0f, 0.95f, 0.0f}, {0.27f, 0.18f, 0.16f}, r, s);    // pelvis
  AddEllipsoid(body, {0.0f, 1.76f, 0.02f}, {0.13f, 0.15f, 0.14f}, r, s);   // head
  for (float side : {-1.0f, 1.0f}) {
    AddEllipsoid(body, {side * 0.50f, 1.45f, 0.0f}, {0.22f, 0.085f, 0.085f}, r, s);  // upper arm
    AddEllipsoid(body, {side * 0.90f, 1.45f, 0.0f}, {0.20f, 0.07f, 0.07f}, r, s);    // forearm
    AddEllipsoid(body, {side * 0.15f, 0.62f, 0.0f}, {0.12f, 0.25f, 0.12f}, r, s);    // thigh
    AddEllipsoid(body, {side * 0.15f, 0.22f, 0.0f}, {0.09f, 0.22f, 0.09f}, r, s);    // shin
  }
  return body;
}

// The camera of BM_RenderBody: fov, near and far are the render::Camera defaults.
inline render::Camera BodyCamera(int width, int height) {
  render::Camera camera;
  camera.eye = glm::vec3(0.3f, 1.2f, 1.55f);
  camera.target = glm::vec3(0.0f, 1.05f, 0.0f);
  camera.aspect = static_cast<float>(width) / static_cast<float>(height);
  return camera;
}

// Sanity snapshots: when the environment variable PATCHSKIN_BENCH_SNAPSHOT_DIR
// is set, the benchmarks write one frame per row there as a binary PPM
// (8-bit linear RGB, top row first; convert with `oiiotool x.ppm -o x.png`).
// Not timed. Returns the path written, or "" when the variable is unset.
inline std::string SnapshotPath(const std::string& name) {
  const char* dir = std::getenv("PATCHSKIN_BENCH_SNAPSHOT_DIR");
  if (dir == nullptr || *dir == '\0') return {};
  return std::string(dir) + "/" + name + ".ppm";
}

// `rgb` is width * height * 3 bytes, top row first.
inline bool WritePpm(const std::string& path, int width, int height,
                     const std::vector<std::uint8_t>& rgb) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) return false;
  std::fprintf(file, "P6\n%d %d\n255\n", width, height);
  const bool ok = std::fwrite(rgb.data(), 1, rgb.size(), file) == rgb.size();
  return std::fclose(file) == 0 && ok;
}

}  // namespace bench
