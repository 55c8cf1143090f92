#include "render/raster/region_select.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "deform/mesh.h"
#include "render/renderer.h"

namespace render {
namespace {

}  // namespace

base::Result<std::vector<int>> SelectScreenRegion(const Camera& camera,
                                                  std::span<const glm::vec3> positions,
                                                  std::span<const glm::vec3> normals,
                                                  std::span<const glm::uvec3> triangles,
                                                  const ScreenRegionQuery& q) {
  const glm::vec4 r = q.rect;
  if (!(r.x >= 0.0f && r.z <= 1.0f && r.y >= 0.0f && r.w <= 1.0f && r.x < r.z && r.y < r.w)) {
    return base::InvalidArgument(
        "screen region: expected a rectangle x0 < x1, y0 < y1 within [0,1]");
  }
  if (q.width < 16 || q.height < 16 || q.width > 4096 || q.height > 4096) {
    return base::InvalidArgument("screen region: depth image size must be 16..4096");
  }
  if (!normals.empty() && normals.size() != positions.size()) {
    return base::InvalidArgument("screen region: normals are not #V");
  }
  for (const glm::uvec3& t : triangles) {
    if (t.x >= positions.size() || t.y >= positions.size() || t.z >= positions.size()) {
      return base::InvalidArgument("screen region: a triangle index is past #V");
    }
  }
  std::vector<glm::vec3> own_normals;
  if (normals.empty()) {
    own_normals.resize(positions.size());
    deform::ComputeVertexNormals(positions, triangles, own_normals);
    normals = own_normals;
  }
  // The z-buffer of the mesh alone, one sample per pixel.
  RenderSettings settings;
  settings.width = q.width;
  settings.height = q.height;
  settings.supersample = 1;
  settings.threads = 1;
  settings.ground = false;
  settings.write_depth = true;
  const SceneMesh mesh{.positions = positions, .normals = normals, .triangles = triangles};
  const Image depth = Render(camera, {&mesh, 1}, {}, settings);
  if (depth.depth.empty())
    return base::InvalidArgument("screen region: the camera or mesh was refused");

  const glm::mat4 clip_from_world = camera.ClipFromWorld();
  const glm::vec3 forward = camera.Forward();
  const float w = static_cast<float>(q.width), h = static_cast<float>(q.height);
  std::vector<char> chosen(positions.size(), 0);
  std::vector<glm::vec2> pixel(positions.size());
  for (std::size_t v = 0; v < positions.size(); ++v) {
    const glm::vec3 p = positions[v];
    const glm::vec4 c = clip_from_world * glm::vec4(p, 1.0f);
    if (!(c.w > 0.0f)) continue;
    const glm::vec2 px((c.x / c.w * 0.5f + 0.5f) * w, (0.5f - c.y / c.w * 0.5f) * h);
    pixel[v] = px;
    if (px.x < r.x * w || px.x > r.z * w || px.y < r.y * h || px.y > r.w * h) continue;
    if (glm::dot(normals[v], camera.eye - p) <= 0.0f) continue;  // back-facing
    // Nearest z-buffer depth around the pixel: a vertex sits on triangle
    // edges, so its own pixel may belong to a neighbour.
    const int cx = static_cast<int>(px.x), cy = static_cast<int>(px.y);
    float nearest = std::numeric_limits<float>::infinity();
    for (int y = std::max(0, cy - 1); y <= std::min(q.height - 1, cy + 1); ++y) {
      for (int x = std::max(0, cx - 1); x <= std::min(q.width - 1, cx + 1); ++x) {
        nearest = std::min(nearest, depth.depth[depth.index(x, y)]);
      }
    }
    const float view_depth = glm::dot(p - camera.eye, forward);
    if (view_depth <= nearest * (1.0f + q.depth_tol_rel)) chosen[v] = 1;
  }
  // Connected component under the rectangle centre.
  const glm::vec2 centre(0.5f * (r.x + r.z) * w, 0.5f * (r.y + r.w) * h);
  int seed = -1;
  float best = std::numeric_limits<float>::infinity();
  for (std::size_t v = 0; v < positions.size(); ++v) {
    if (!chosen[v]) continue;
    const float d = glm::length(pixel[v] - centre);
    if (d < best) best = d, seed = static_cast<int>(v);
  }
  if (seed < 0) {
    return base::MakeError(base::ErrorCode::kNotFound, {},
                           "screen region: no visible front-facing vertex inside the rectangle");
  }
  // Union-find over edges of triangles between chosen vertices.
  std::vector<int> parent(positions.size());
  for (std::size_t v = 0; v < parent.size(); ++v) parent[v] = static_cast<int>(v);
  auto find = [&](int a) {
    while (parent[static_cast<std::size_t>(a)] != a) {
      parent[static_cast<std::size_t>(a)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(a)])];
      a = parent[static_cast<std::size_t>(a)];
    }
    return a;
  };
  for (const glm::uvec3& t : triangles) {
    for (int e = 0; e < 3; ++e) {
      const auto a = t[e], b = t[(e + 1) % 3];
      if (chosen[a] && chosen[b]) {
        const int ra = find(static_cast<int>(a)), rb = find(static_cast<int>(b));
        if (ra != rb) parent[static_cast<std::size_t>(std::max(ra, rb))] = std::min(ra, rb);
      }
    }
  }
  const int root = find(seed);
  std::vector<int> out;
  for (std::size_t v = 0; v < positions.size(); ++v) {
    if (chosen[v] && find(static_cast<int>(v)) == root) out.push_back(static_cast<int>(v));
  }
  return out;
}

}  // namespace render
