#include "render/renderer.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "render/internal/parallel.h"

namespace render {
namespace {

constexpr int kMaxSamplesPerAxis = 16384;

// The image is written once per frame and not read back by this thread:
// non-temporal stores skip the read-for-ownership of every output cache line.
inline void StreamStore(glm::vec4* dst, const glm::vec4& v) {
#if defined(__SSE2__)
  if ((reinterpret_cast<std::uintptr_t>(dst) & 15u) == 0) {
    _mm_stream_ps(reinterpret_cast<float*>(dst), _mm_set_ps(v.w, v.z, v.y, v.x));
    return;
  }
#endif
  *dst = v;
}
inline void StreamStore(float* dst, float v) {
#if defined(__SSE2__)
  int bits;
  std::memcpy(&bits, &v, sizeof bits);
  _mm_stream_si32(reinterpret_cast<int*>(dst), bits);
#else
  *dst = v;
#endif
}
inline void StreamFence() {
#if defined(__SSE2__)
  _mm_sfence();
#endif
}

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
    s.depth.resize(kTileBufferSize);
    s.ids.resize(kTileBufferSize);
    s.accum.resize(kTileSize * kTileSize);
    s.nearest.resize(kTileSize * kTileSize);
  }
  internal::ParallelForDynamic(rasterizer_.num_tiles(), threads, [&](int tile, int thread) {
    TileScratch& s = scratch_[static_cast<std::size_t>(thread)];
    if (rasterizer_.tile_triangle_count(tile) == 0) {
      FillBackgroundTile(tile, settings, image);
      return;
    }
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

// Shades visible samples. Neighbouring samples usually hit the same few
// triangles, so each triangle's vertex attributes (mapped to the setup
// triangle's vertex order) and edge-function coefficients are kept in a small
// direct-mapped cache. Every cached value is a pure function of the id, so
// results do not depend on the order samples are visited in.
class Renderer::SampleShader {
 public:
  SampleShader(const Rasterizer& raster, std::span<const SceneMesh> meshes,
               const RenderSettings& settings, const Renderer& renderer)
      : raster_(raster), meshes_(meshes), settings_(settings), r_(renderer) {}

  [[gnu::always_inline]] glm::vec3 Shade(std::uint32_t id, int sx, int sy) {
    Entry& t = cache_[id & (kCacheSize - 1)];
    if (t.id != id) Load(id, t);
    // Perspective-correct weights up to a common scale: edge function times
    // 1/w, as planes in sample space around the triangle's reference sample.
    const auto fx = static_cast<float>(sx - t.ref_x), fy = static_cast<float>(sy - t.ref_y);
    const float w0 = t.wc[0] + t.wa[0] * fx + t.wb[0] * fy;
    const float w1 = t.wc[1] + t.wa[1] * fx + t.wb[1] * fy;
    const float w2 = t.wc[2] + t.wa[2] * fx + t.wb[2] * fy;
    const ShadingContext& ctx = r_.context_;
    const LightingModel model = ctx.model;
    if (t.ground) {
      const float inv = 1.0f / (w0 + w1 + w2);
      const glm::vec3 p = (w0 * inv) * t.p[0] + (w1 * inv) * t.p[1] + (w2 * inv) * t.p[2];
      const glm::vec3 albedo = GroundAlbedo(settings_.ground_style, r_.grid_spacing_, p, ctx.eye);
      const float shadow = ContactShadowFactor(r_.shadows_, p);
      if (model == LightingModel::kUnlit) return albedo * shadow;
      return albedo * (ctx.ambient + ctx.key_radiance * std::max(ctx.key_dir.y, 0.0f) +
                       ctx.fill_radiance * std::max(ctx.fill_dir.y, 0.0f)) *
             shadow;
    }
    glm::vec3 albedo = t.albedo;
    const bool need_weights = t.interpolate_color || model == LightingModel::kBlinnPhong;
    float l0 = w0, l1 = w1, l2 = w2;
    if (need_weights) {
      const float inv = 1.0f / (w0 + w1 + w2);
      l0 = w0 * inv;
      l1 = w1 * inv;
      l2 = w2 * inv;
    }
    if (t.interpolate_color) albedo = l0 * t.col[0] + l1 * t.col[1] + l2 * t.col[2];
    if (model == LightingModel::kUnlit) return albedo;
    glm::vec3 n = t.face_normal;
    // Unnormalized weights suffice: the interpolated normal is renormalized.
    if (t.smooth) n = w0 * t.n[0] + w1 * t.n[1] + w2 * t.n[2];
    const float len2 = glm::dot(n, n);
    if (model == LightingModel::kLambert) {
      // N.L / |N|, with the square root only for lit samples.
      const float d = glm::dot(n, ctx.key_dir);
      const float n_dot_l = d > 0.0f && len2 > 0.0f ? d / std::sqrt(len2) : 0.0f;
      return albedo * (ctx.ambient + ctx.key_radiance * n_dot_l);
    }
    n = len2 > 0.0f ? n * (1.0f / std::sqrt(len2)) : t.face_normal;
    const glm::vec3 p = l0 * t.p[0] + l1 * t.p[1] + l2 * t.p[2];
    return ShadeSurface(ctx, albedo, n, p);
  }

 private:
  static constexpr std::uint32_t kCacheSize = 64;
  struct Entry {
    std::uint32_t id = kNoTriangle;
    bool ground = false, smooth = false, interpolate_color = false;
    int ref_x = 0, ref_y = 0;  // reference sample (the triangle's bounds corner)
    float wa[3] = {}, wb[3] = {}, wc[3] = {};  // weight_i = wc + wa * (x - ref_x) + wb * (y - ref_y)
    glm::vec3 n[3], col[3], p[3], face_normal{0.0f, 0.0f, 1.0f}, albedo{1.0f};
  };

  [[gnu::noinline]] void Load(std::uint32_t id, Entry& t) const {
    t.id = id;
    const RasterTriangle& tri = raster_.triangle(id);
    t.ref_x = tri.min_x;
    t.ref_y = tri.min_y;
    for (int i = 0; i < 3; ++i) {
      const int a = (i + 1) % 3, b = (i + 2) % 3;
      const std::int32_t dx = tri.x[b] - tri.x[a], dy = tri.y[b] - tri.y[a];
      const std::int64_t e = EdgeValue(tri.x[a], tri.y[a], tri.x[b], tri.y[b], t.ref_x, t.ref_y);
      t.wa[i] = static_cast<float>(-std::int64_t{dy} * kSubpixelScale) * tri.inv_w[i];
      t.wb[i] = static_cast<float>(std::int64_t{dx} * kSubpixelScale) * tri.inv_w[i];
      t.wc[i] = static_cast<float>(e) * tri.inv_w[i];
    }
    const glm::mat3* weights = raster_.corner_weights(id);
    // Attribute of setup vertex i from the three source-corner values.
    auto to_vertices = [&](const glm::vec3 (&corner)[3], glm::vec3 (&out)[3]) {
      for (int i = 0; i < 3; ++i) {
        out[i] = weights == nullptr ? corner[tri.order[i]]
                                    : (*weights)[i].x * corner[0] + (*weights)[i].y * corner[1] +
                                          (*weights)[i].z * corner[2];
      }
    };
    t.ground = tri.mesh == static_cast<std::uint32_t>(meshes_.size());
    glm::vec3 corner[3];
    if (t.ground) {
      const glm::uvec3 v = r_.ground_triangles_[tri.triangle];
      for (int k = 0; k < 3; ++k) corner[k] = r_.ground_positions_[v[k]];
      to_vertices(corner, t.p);
      return;
    }
    const SceneMesh& mesh = meshes_[tri.mesh];
    const glm::uvec3 v = mesh.triangles[tri.triangle];
    t.smooth = settings_.shading == ShadingMode::kSmooth && !mesh.normals.empty();
    const bool need_positions = r_.context_.model == LightingModel::kBlinnPhong;
    if (!t.smooth || need_positions) {
      for (int k = 0; k < 3; ++k) corner[k] = mesh.positions[v[k]];
      if (need_positions) to_vertices(corner, t.p);
    }
    // The geometric normal shades flat triangles. A smooth triangle whose
    // interpolated normal vanishes gets ambient light only (zero normal).
    t.face_normal = glm::vec3(0.0f);
    if (!t.smooth) {
      const glm::vec3 f = glm::cross(corner[1] - corner[0], corner[2] - corner[0]);
      const float len2 = glm::dot(f, f);
      t.face_normal = len2 > 0.0f ? f * (1.0f / std::sqrt(len2)) : glm::vec3(0.0f);
      if (tri.back_facing) t.face_normal = -t.face_normal;
    }
    if (t.smooth) {
      const float sign = tri.back_facing ? -1.0f : 1.0f;
      for (int k = 0; k < 3; ++k) corner[k] = sign * mesh.normals[v[k]];
      to_vertices(corner, t.n);
    }
    t.interpolate_color = false;
    t.albedo = mesh.base_color;
    if (!mesh.triangle_colors.empty()) {
      t.albedo = mesh.triangle_colors[tri.triangle];
    } else if (!mesh.vertex_colors.empty()) {
      t.interpolate_color = true;
      for (int k = 0; k < 3; ++k) corner[k] = mesh.vertex_colors[v[k]];
      to_vertices(corner, t.col);
    }
  }

  const Rasterizer& raster_;
  std::span<const SceneMesh> meshes_;
  const RenderSettings& settings_;
  const Renderer& r_;
  Entry cache_[kCacheSize];
};

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

  SampleShader shader(rasterizer_, meshes, settings, *this);

  if (ss == 1) {
    for (int sy = y0; sy < y1; ++sy) {
      const glm::vec4 bg = transparent ? glm::vec4(0.0f)
                                       : glm::vec4(background_rows_[static_cast<std::size_t>(sy)], 1.0f);
      const std::size_t row = static_cast<std::size_t>(sy - y0) * kTileSize;
      glm::vec4* rgba = image.rgba.data() + image.index(x0, sy);
      float* depth = write_depth ? image.depth.data() + image.index(x0, sy) : nullptr;
      for (int sx = x0; sx < x1; ++sx, ++rgba) {
        const std::size_t at = row + static_cast<std::size_t>(sx - x0);
        const std::uint32_t id = s.ids[at];
        const bool hit = id != kNoTriangle;
        StreamStore(rgba, hit ? glm::vec4(shader.Shade(id, sx, sy), 1.0f) : bg);
        if (depth != nullptr) StreamStore(depth++, hit ? 1.0f / s.depth[at] : inf);
      }
    }
    StreamFence();
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
        acc += glm::vec4(shader.Shade(id, sx, sy), 1.0f);
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

void Renderer::FillBackgroundTile(int tile, const RenderSettings& settings, Image& image) const {
  // Same values the shading path gives an empty pixel: the box average of the
  // background rows it covers (transparent: zero colour and alpha).
  const int ss = settings.supersample;
  const int ox0 = (tile % rasterizer_.tiles_x()) * kTileSize / ss;
  const int oy0 = (tile / rasterizer_.tiles_x()) * kTileSize / ss;
  const int ox1 = std::min(ox0 + kTileSize / ss, image.width);
  const int oy1 = std::min(oy0 + kTileSize / ss, image.height);
  const float inf = std::numeric_limits<float>::infinity();
  const float inv_n = 1.0f / static_cast<float>(ss * ss);
  for (int oy = oy0; oy < oy1; ++oy) {
    glm::vec4 color(0.0f);
    if (!settings.background.transparent) {
      // Sum in the order ShadeTile accumulates: sample rows, then columns.
      glm::vec4 acc(0.0f);
      for (int j = 0; j < ss; ++j)
        for (int i = 0; i < ss; ++i)
          acc += glm::vec4(background_rows_[static_cast<std::size_t>(oy * ss + j)], 0.0f);
      color = ss == 1 ? glm::vec4(background_rows_[static_cast<std::size_t>(oy)], 1.0f)
                      : glm::vec4(glm::vec3(acc) * inv_n, 1.0f);
    }
    glm::vec4* rgba = image.rgba.data() + image.index(ox0, oy);
    for (int ox = ox0; ox < ox1; ++ox) StreamStore(rgba++, color);
    if (!image.depth.empty()) {
      float* depth = image.depth.data() + image.index(ox0, oy);
      for (int ox = ox0; ox < ox1; ++ox) StreamStore(depth++, inf);
    }
  }
  StreamFence();
}

Image Render(const Camera& camera, std::span<const SceneMesh> meshes, const Overlays& overlays,
             const RenderSettings& settings) {
  Renderer renderer;
  Image image;
  if (!renderer.Render(camera, meshes, overlays, settings, image).ok()) return Image();
  return image;
}

}  // namespace render
