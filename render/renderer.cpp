#include "render/renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "render/internal/parallel.h"

namespace render {
namespace {

constexpr int kMaxSamplesPerAxis = 16384;

mocap::JobStatus Fail(mocap::JobStatus::Code code, const char* what) { return {code, what}; }

mocap::JobStatus ValidateInputs(std::span<const SceneMesh> meshes, const RenderSettings& s) {
  using Code = mocap::JobStatus::Code;
  if (s.supersample != 1 && s.supersample != 2 && s.supersample != 4)
    return Fail(Code::kOutOfRange, "supersample must be 1, 2 or 4");
  if (s.width < 1 || s.height < 1 || s.width * s.supersample > kMaxSamplesPerAxis ||
      s.height * s.supersample > kMaxSamplesPerAxis)
    return Fail(Code::kOutOfRange, "image size out of range");
  if (s.threads < 0) return Fail(Code::kOutOfRange, "threads must be >= 0");
  for (const SceneMesh& mesh : meshes) {
    const std::size_t nv = mesh.positions.size();
    if (!mesh.normals.empty() && mesh.normals.size() != nv)
      return Fail(Code::kSizeMismatch, "normals must be empty or #V");
    if (!mesh.vertex_colors.empty() && mesh.vertex_colors.size() != nv)
      return Fail(Code::kSizeMismatch, "vertex_colors must be empty or #V");
    if (!mesh.triangle_colors.empty() && mesh.triangle_colors.size() != mesh.triangles.size())
      return Fail(Code::kSizeMismatch, "triangle_colors must be empty or #T");
  }
  return mocap::kJobOk;
}

}  // namespace

mocap::JobStatus Renderer::Render(const Camera& camera, std::span<const SceneMesh> meshes,
                                  const Overlays& overlays, const RenderSettings& settings,
                                  Image& image) {
  const mocap::JobStatus status = ValidateInputs(meshes, settings);
  if (!status.ok()) return status;
  const int threads = internal::ResolveThreads(settings.threads);
  const int ss = settings.supersample;
  const glm::mat4 view_from_world = camera.ViewFromWorld();
  const glm::mat4 clip_from_world = camera.ClipFromView() * view_from_world;
  context_ = MakeShadingContext(settings.lights, settings.lighting, view_from_world);

  // Scene bounds place the ground and its contact shadows.
  deform::Bounds scene;
  shadows_.clear();
  for (const SceneMesh& mesh : meshes) {
    const deform::Bounds b = deform::ComputeBounds(mesh.positions);
    if (b.empty()) continue;
    scene.Extend(b.min);
    scene.Extend(b.max);
  }
  const float ground_y = settings.ground_at_scene_min && !scene.empty() ? scene.min.y
                                                                         : settings.ground_y;
  ground_positions_.clear();
  ground_triangles_.clear();
  if (settings.ground) {
    for (const SceneMesh& mesh : meshes) {
      if (!mesh.casts_contact_shadow) continue;
      shadows_.push_back(ShadowUnder(deform::ComputeBounds(mesh.positions), ground_y,
                                     settings.ground_style.shadow_strength));
    }
    const glm::vec3 c = scene.empty() ? glm::vec3(0.0f) : scene.center();
    const float radius = scene.empty() ? 1.0f : std::max(glm::length(scene.size()), 1e-3f);
    const float half = 25.0f * radius;
    ground_positions_ = {{c.x - half, ground_y, c.z + half}, {c.x + half, ground_y, c.z + half},
                         {c.x + half, ground_y, c.z - half}, {c.x - half, ground_y, c.z - half}};
    ground_triangles_ = {{0u, 1u, 2u}, {0u, 2u, 3u}};
    grid_spacing_ = settings.ground_style.grid_spacing > 0.0f
                        ? settings.ground_style.grid_spacing
                        : (scene.empty() ? 1.0f : std::max(scene.size().y, 1e-3f) * 0.25f);
  }

  // World -> clip, threaded over fixed vertex ranges.
  const std::size_t num_meshes = meshes.size() + 1;  // + ground
  clip_positions_.resize(num_meshes);
  std::vector<ClipMesh> clip_meshes(num_meshes);
  for (std::size_t m = 0; m < num_meshes; ++m) {
    const std::span<const glm::vec3> p =
        m < meshes.size() ? meshes[m].positions : std::span<const glm::vec3>(ground_positions_);
    clip_positions_[m].resize(p.size());
    internal::RunOnThreads(p.size() > 8192 ? threads : 1, [&](int t) {
      const int n = p.size() > 8192 ? threads : 1;
      const std::size_t begin = p.size() * static_cast<std::size_t>(t) / static_cast<std::size_t>(n);
      const std::size_t end = p.size() * static_cast<std::size_t>(t + 1) / static_cast<std::size_t>(n);
      for (std::size_t i = begin; i < end; ++i)
        clip_positions_[m][i] = clip_from_world * glm::vec4(p[i], 1.0f);
    });
    clip_meshes[m].clip_positions = clip_positions_[m];
    clip_meshes[m].triangles = m < meshes.size() ? meshes[m].triangles
                                                 : std::span<const glm::uvec3>(ground_triangles_);
  }

  RasterSettings raster;
  raster.width = settings.width * ss;
  raster.height = settings.height * ss;
  raster.cull_back_faces = settings.cull_back_faces;
  raster.threads = threads;
  if (!rasterizer_.Setup(clip_meshes, raster))
    return Fail(mocap::JobStatus::kOutOfRange, "raster size out of range");

  background_rows_.resize(static_cast<std::size_t>(raster.height));
  for (int y = 0; y < raster.height; ++y)
    background_rows_[static_cast<std::size_t>(y)] = BackgroundColor(
        settings.background, (static_cast<float>(y) + 0.5f) / static_cast<float>(raster.height));

  image.width = settings.width;
  image.height = settings.height;
  const std::size_t pixels = static_cast<std::size_t>(settings.width) * static_cast<std::size_t>(settings.height);
  image.rgba.resize(pixels);
  if (settings.write_depth || !overlays.lines.empty() || !overlays.points.empty() || overlays.wireframe)
    image.depth.resize(pixels);
  else
    image.depth.clear();

  scratch_.resize(static_cast<std::size_t>(threads));
  for (TileScratch& s : scratch_) {
    s.depth.resize(kTileSize * kTileSize);
    s.ids.resize(kTileSize * kTileSize);
    s.accum.resize(kTileSize * kTileSize);
    s.nearest.resize(kTileSize * kTileSize);
  }
  internal::ParallelForDynamic(rasterizer_.num_tiles(), threads, [&](int tile, int thread) {
    TileScratch& s = scratch_[static_cast<std::size_t>(thread)];
    rasterizer_.RasterizeTile(tile, s.depth, s.ids);
    ShadeTile(tile, settings, meshes, s, image);
  });

  // Overlays, in a fixed order, on the resolved image.
  if (overlays.wireframe) {
    for (const SceneMesh& mesh : meshes)
      DrawWireframe(clip_from_world, mesh.positions, mesh.triangles, overlays.wireframe_color,
                    overlays.wireframe_width_px, overlays.wireframe_depth_test, image);
  }
  for (const LineOverlay& lines : overlays.lines) DrawLines(clip_from_world, lines, image);
  for (const PointOverlay& points : overlays.points) DrawPoints(clip_from_world, points, image);
  for (const TextOverlay& text : overlays.text) DrawText(text, image);
  if (!settings.write_depth) image.depth.clear();
  return mocap::kJobOk;
}

void Renderer::ShadeTile(int tile, const RenderSettings& settings,
                         std::span<const SceneMesh> meshes, TileScratch& s, Image& image) const {
  const int ss = settings.supersample;
  const int x0 = (tile % rasterizer_.tiles_x()) * kTileSize;
  const int y0 = (tile / rasterizer_.tiles_x()) * kTileSize;
  const int x1 = std::min(x0 + kTileSize, rasterizer_.width());
  const int y1 = std::min(y0 + kTileSize, rasterizer_.height());
  const bool transparent = settings.background.transparent;
  const bool write_depth = !image.depth.empty();
  const float inf = std::numeric_limits<float>::infinity();
  const auto ground_mesh = static_cast<std::uint32_t>(meshes.size());
  const ShadingContext& ctx = context_;

  // Colour of one visible sample.
  auto shade = [&](std::uint32_t id, int sx, int sy) -> glm::vec3 {
    const RasterTriangle& tri = rasterizer_.triangle(id);
    const glm::vec3 b = rasterizer_.Barycentrics(id, sx, sy);
    if (tri.mesh == ground_mesh) {
      const glm::uvec3 t = ground_triangles_[tri.triangle];
      const glm::vec3 p = b.x * ground_positions_[t.x] + b.y * ground_positions_[t.y] +
                          b.z * ground_positions_[t.z];
      const glm::vec3 albedo = GroundAlbedo(settings.ground_style, grid_spacing_, p);
      const float n_dot_l = std::max(ctx.key_dir.y, 0.0f);
      const glm::vec3 lit = albedo * (ctx.ambient + ctx.key_radiance * n_dot_l +
                                      ctx.fill_radiance * std::max(ctx.fill_dir.y, 0.0f));
      return ctx.model == LightingModel::kUnlit ? albedo * ContactShadowFactor(shadows_, p)
                                                : lit * ContactShadowFactor(shadows_, p);
    }
    const SceneMesh& mesh = meshes[tri.mesh];
    const glm::uvec3 t = mesh.triangles[tri.triangle];
    const glm::vec3& p0 = mesh.positions[t.x];
    const glm::vec3& p1 = mesh.positions[t.y];
    const glm::vec3& p2 = mesh.positions[t.z];
    glm::vec3 albedo = mesh.base_color;
    if (!mesh.triangle_colors.empty()) {
      albedo = mesh.triangle_colors[tri.triangle];
    } else if (!mesh.vertex_colors.empty()) {
      albedo = b.x * mesh.vertex_colors[t.x] + b.y * mesh.vertex_colors[t.y] +
               b.z * mesh.vertex_colors[t.z];
    }
    if (ctx.model == LightingModel::kUnlit) return albedo;
    glm::vec3 n;
    if (settings.shading == ShadingMode::kSmooth && !mesh.normals.empty()) {
      n = b.x * mesh.normals[t.x] + b.y * mesh.normals[t.y] + b.z * mesh.normals[t.z];
    } else {
      n = glm::cross(p1 - p0, p2 - p0);
    }
    const float len2 = glm::dot(n, n);
    n = len2 > 0.0f ? n * (1.0f / std::sqrt(len2)) : glm::vec3(0.0f, 0.0f, 1.0f);
    if (tri.back_facing) n = -n;
    const glm::vec3 p = b.x * p0 + b.y * p1 + b.z * p2;
    return ShadeSurface(ctx, albedo, n, p);
  };

  if (ss == 1) {
    for (int sy = y0; sy < y1; ++sy) {
      const glm::vec3 bg = background_rows_[static_cast<std::size_t>(sy)];
      const std::size_t row = static_cast<std::size_t>(sy - y0) * kTileSize;
      for (int sx = x0; sx < x1; ++sx) {
        const std::size_t at = row + static_cast<std::size_t>(sx - x0);
        const std::uint32_t id = s.ids[at];
        const std::size_t out = image.index(sx, sy);
        if (id == kNoTriangle) {
          image.rgba[out] = transparent ? glm::vec4(0.0f) : glm::vec4(bg, 1.0f);
          if (write_depth) image.depth[out] = inf;
        } else {
          image.rgba[out] = glm::vec4(shade(id, sx, sy), 1.0f);
          if (write_depth) image.depth[out] = 1.0f / s.depth[at];
        }
      }
    }
    return;
  }

  // Supersampled: accumulate each output pixel's samples in row-major sample order.
  const int ox0 = x0 / ss, oy0 = y0 / ss, ox1 = x1 / ss, oy1 = y1 / ss;
  const int out_stride = kTileSize / ss;
  std::fill(s.accum.begin(), s.accum.end(), glm::vec4(0.0f));
  std::fill(s.nearest.begin(), s.nearest.end(), inf);
  for (int sy = y0; sy < y1; ++sy) {
    const glm::vec3 bg = background_rows_[static_cast<std::size_t>(sy)];
    const std::size_t row = static_cast<std::size_t>(sy - y0) * kTileSize;
    const std::size_t out_row = static_cast<std::size_t>((sy - y0) / ss) * static_cast<std::size_t>(out_stride);
    for (int sx = x0; sx < x1; ++sx) {
      const std::size_t at = row + static_cast<std::size_t>(sx - x0);
      const std::uint32_t id = s.ids[at];
      glm::vec4& acc = s.accum[out_row + static_cast<std::size_t>((sx - x0) / ss)];
      if (id == kNoTriangle) {
        if (!transparent) acc += glm::vec4(bg, 0.0f);
      } else {
        acc += glm::vec4(shade(id, sx, sy), 1.0f);
        float& nearest = s.nearest[out_row + static_cast<std::size_t>((sx - x0) / ss)];
        nearest = std::min(nearest, 1.0f / s.depth[at]);
      }
    }
  }
  const float inv_n = 1.0f / static_cast<float>(ss * ss);
  for (int oy = oy0; oy < oy1; ++oy) {
    for (int ox = ox0; ox < ox1; ++ox) {
      const std::size_t local = static_cast<std::size_t>(oy - oy0) * static_cast<std::size_t>(out_stride) +
                                static_cast<std::size_t>(ox - ox0);
      const glm::vec4 acc = s.accum[local];
      const std::size_t out = image.index(ox, oy);
      if (transparent) {
        // Straight (not premultiplied) colour of the covered samples; alpha = coverage.
        image.rgba[out] = acc.w > 0.0f ? glm::vec4(glm::vec3(acc) / acc.w, acc.w * inv_n)
                                       : glm::vec4(0.0f);
      } else {
        image.rgba[out] = glm::vec4(glm::vec3(acc) * inv_n, 1.0f);
      }
      if (write_depth) image.depth[out] = s.nearest[local];
    }
  }
}

Image Render(const Camera& camera, std::span<const SceneMesh> meshes, const Overlays& overlays,
             const RenderSettings& settings) {
  Renderer renderer;
  Image image;
  if (!renderer.Render(camera, meshes, overlays, settings, image).ok()) return Image();
  return image;
}

}  // namespace render
