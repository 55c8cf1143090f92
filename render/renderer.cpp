#include "render/renderer.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "base/parallel.h"
#include "render/raster/internal/simd.h"
#include "render/raster/shading4.h"

namespace render {
namespace {

constexpr int kMaxSamplesPerAxis = 16384;
constexpr float kInf = std::numeric_limits<float>::infinity();

// The image is written once per frame and not read back by this thread:
// non-temporal stores skip the read-for-ownership of every output cache line.
inline void StreamStore(glm::vec4* dst, const glm::vec4& v) {
#if defined(__SSE2__)
  if ((reinterpret_cast<std::uintptr_t>(dst) & 15u) == 0) {
    _mm_stream_ps(reinterpret_cast<float*>(dst), simd::Set(v));
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

// View depth (1 / stored 1/w, +inf where empty) of `n` samples of one tile row.
void WriteDepthRow(const float* inv_w, const std::uint32_t* ids, int n, float* out) {
  int i = 0;
#if defined(__SSE2__)
  const __m128 one = _mm_set1_ps(1.0f);
  const __m128 inf = _mm_set1_ps(std::numeric_limits<float>::infinity());
  const __m128i empty = _mm_set1_epi32(static_cast<int>(kNoTriangle));
  const bool aligned = (reinterpret_cast<std::uintptr_t>(out) & 15u) == 0;
  for (; i + 4 <= n; i += 4) {
    const __m128 miss = _mm_castsi128_ps(_mm_cmpeq_epi32(simd::LoadU(ids + i), empty));
    // Empty samples hold 1/w = 0: divide 1 by 1 there instead, then select inf.
    const __m128 d = _mm_div_ps(one, simd::Select(miss, one, _mm_loadu_ps(inv_w + i)));
    const __m128 v = simd::Select(miss, inf, d);
    if (aligned) {
      _mm_stream_ps(out + i, v);
    } else {
      _mm_storeu_ps(out + i, v);
    }
  }
#endif
  for (; i < n; ++i) StreamStore(out + i, ids[i] != kNoTriangle ? 1.0f / inv_w[i] : kInf);
}

// Multisampling: whether all ss x ss samples of the pixel starting at column
// c0 of `ids` (the pixel row's first sample row, stride kTileSize) saw `id`.
bool PixelAllOf(const std::uint32_t* ids, int c0, int ss, std::uint32_t id) {
  for (int r = 0; r < ss; ++r) {
    const std::uint32_t* row = ids + static_cast<std::size_t>(r) * kTileSize + c0;
    for (int c = 0; c < ss; ++c)
      if (row[c] != id) return false;
  }
  return true;
}

// One sample's share of its pixel, as every resolve path adds it: a covered
// sample adds (colour, 1) and raises the pixel's nearest 1/w; an empty one
// adds the background with coverage 0, or nothing when transparent. Returns
// the sample as the tent resolve stores it.
inline glm::vec4 AddSample(bool covered, const glm::vec3& color, const glm::vec3& background,
                           float inv_w, bool transparent, glm::vec4& acc, float& nearest) {
  glm::vec4 sample(0.0f);
  if (!covered) {
    if (!transparent) sample = glm::vec4(background, 0.0f);
  } else {
    sample = glm::vec4(color, 1.0f);
    // The largest 1/w; its reciprocal is the smallest of the samples'
    // reciprocals (rounded division is monotone), one divide per pixel.
    nearest = std::max(nearest, inv_w);
  }
  if (covered || !transparent) acc += sample;
  return sample;
}

}  // namespace

// Multisampling: the whole pixels of a pixel row (`whole`, n sample columns)
// into the tile's accumulators at out_row, each of its ss x ss samples added
// in the order the per-sample loop adds them, so a pixel gets the bytes
// supersampling gives a pixel of one colour: a covered pixel's colour is
// color[first sample] and its nearest depth the largest 1/w of its samples
// (`depth`: the pixel row's first sample row, stride kTileSize); an empty
// pixel's samples are its sample rows' background[r] (none when transparent).
// For the tent resolve, the samples also go to `samples`.
void Renderer::AccumulateWholePixels(int n, int ss_shift, const Whole* whole,
                                     const glm::vec3* color, const float* depth,
                                     const glm::vec3* background, bool transparent,
                                     std::size_t out_row, TileScratch& s, glm::vec4* samples,
                                     std::size_t sample_stride) const {
  const int ss = 1 << ss_shift;
  for (int c0 = 0; c0 < n; c0 += ss) {
    const Whole kind = whole[c0 >> ss_shift];
    if (kind == Whole::kNo) continue;
    const std::size_t pixel = out_row + static_cast<std::size_t>(c0 >> ss_shift);
    glm::vec4 acc = s.accum[pixel];
    float nearest = s.nearest[pixel];
    for (int r = 0; r < ss; ++r) {
      const float* row = depth + static_cast<std::size_t>(r) * kTileSize + c0;
      for (int c = 0; c < ss; ++c) {
        const glm::vec4 sample = AddSample(kind != Whole::kEmpty, color[c0], background[r], row[c],
                                           transparent, acc, nearest);
        if (samples != nullptr)
          samples[static_cast<std::size_t>(r) * sample_stride + static_cast<std::size_t>(c0 + c)] =
              sample;
      }
    }
    s.accum[pixel] = acc;
    s.nearest[pixel] = nearest;
  }
}

// Multisampling: what each pixel of a pixel row (n sample columns, the
// pixel row's first sample row at `ids`, stride kTileSize) saw in all its
// samples: one triangle, the ground (one or more of its triangles), nothing,
// or a mix.
void Renderer::ClassifyPixels(const std::uint32_t* ids, int n, int ss_shift,
                              std::uint32_t ground_mesh, Whole* whole) const {
  const int ss = 1 << ss_shift;
  // Neighbouring pixels mostly see the same triangle: remember the last answer.
  std::uint32_t last_id = kNoTriangle;
  bool last_ground = false;
  auto ground = [&](std::uint32_t id) {
    if (id == kNoTriangle) return false;
    if (id != last_id) {
      last_id = id;
      last_ground = rasterizer_.triangle(id).mesh == ground_mesh;
    }
    return last_ground;
  };
  for (int c0 = 0; c0 < n; c0 += ss) {
    const std::uint32_t first = ids[c0];
    Whole kind = Whole::kNo;
    if (PixelAllOf(ids, c0, ss, first)) {
      kind = first == kNoTriangle ? Whole::kEmpty
             : ground(first)      ? Whole::kGround
                                  : Whole::kTriangle;
    } else if (ground(first)) {
      kind = Whole::kGround;
      for (int r = 0; r < ss && kind == Whole::kGround; ++r)
        for (int c = 0; c < ss; ++c)
          if (!ground(ids[static_cast<std::size_t>(r) * kTileSize +
                          static_cast<std::size_t>(c0 + c)])) {
            kind = Whole::kNo;
            break;
          }
    }
    whole[c0 >> ss_shift] = kind;
  }
}

namespace {

base::JobStatus Fail(base::JobStatus::Code code, const char* what) { return {code, what}; }

base::JobStatus ValidateInputs(std::span<const SceneMesh> meshes, const RenderSettings& s) {
  using Code = base::JobStatus::Code;
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
    if (!mesh.textures.empty() && mesh.uvs.size() != nv)
      return Fail(Code::kSizeMismatch, "uvs must be #V when textures are given");
    if (!mesh.triangle_textures.empty() && mesh.triangle_textures.size() != mesh.triangles.size())
      return Fail(Code::kSizeMismatch, "triangle_textures must be empty or #T");
  }
  return base::kJobOk;
}

}  // namespace

base::JobStatus Renderer::Render(const Camera& camera, std::span<const SceneMesh> meshes,
                                 const Overlays& overlays, const RenderSettings& settings,
                                 Image& image) {
  const base::JobStatus status = ValidateInputs(meshes, settings);
  if (!status.ok()) return status;
  const int threads = base::ResolveThreads(settings.threads);
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
    base::RunOnThreads(p.size() > 8192 ? threads : 1, [&](int t) {
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
  raster.clip_far = settings.clip_far;
  raster.threads = threads;
  if (!rasterizer_.Setup(clip_meshes, raster))
    return Fail(base::JobStatus::kOutOfRange, "raster size out of range");

  // The key light's shadow map, for the meshes and the ground.
  body_shadow_ = nullptr;
  if (settings.shadows && context_.model != LightingModel::kUnlit) {
    casters_.clear();
    for (const SceneMesh& mesh : meshes) casters_.push_back({mesh.positions, mesh.triangles, mesh.closed});
    ShadowMapSettings map_settings = settings.shadow_map;
    map_settings.threads = threads;
    shadow_map_.Build(context_.key_dir, casters_, map_settings);
    if (!shadow_map_.empty()) body_shadow_ = &shadow_map_;
  }

  if (settings.ground) {
    // The ground faces up: ambient plus the key and fill lights' diffuse terms.
    const ShadingContext& ctx = context_;
    const glm::vec3 light = ctx.model == LightingModel::kUnlit
                                ? glm::vec3(1.0f)
                                : ctx.ambient + ctx.key_radiance * std::max(ctx.key_dir.y, 0.0f) +
                                      ctx.fill_radiance * std::max(ctx.fill_dir.y, 0.0f);
    // The key light's cast shadow takes its diffuse term away where occluded.
    const bool cast = body_shadow_ != nullptr && ctx.key_dir.y > 0.0f;
    ground_shader_ = GroundShader::Create({.clip_from_world = clip_from_world,
                                           .eye = ctx.eye,
                                           .raster_width = raster.width,
                                           .raster_height = raster.height,
                                           .ground_y = ground_y,
                                           .grid_spacing = grid_spacing_,
                                           .style = settings.ground_style,
                                           .shadows = shadows_,
                                           .light = light,
                                           .shadow_map = cast ? &shadow_map_ : nullptr,
                                           .key_light = ctx.key_radiance * std::max(ctx.key_dir.y, 0.0f)});
  }

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

  const bool tent = settings.resolve == ResolveFilter::kTent && ss > 1;
  if (tent) {
    samples_.resize(static_cast<std::size_t>(raster.width) * static_cast<std::size_t>(raster.height));
  } else {
    samples_.clear();
  }
  scratch_.resize(static_cast<std::size_t>(threads));
  for (TileScratch& s : scratch_) {
    s.depth.resize(kTileBufferSize);
    s.ids.resize(kTileBufferSize);
    s.accum.resize(kTileSize * kTileSize);
    s.nearest.resize(kTileSize * kTileSize);
  }
  if (tent) {
    base::ParallelForDynamic(rasterizer_.num_tiles(), threads, [&](int tile, int thread) {
      TileScratch& s = scratch_[static_cast<std::size_t>(thread)];
      if (rasterizer_.tile_triangle_count(tile) == 0) {
        FillBackgroundTile(tile, settings, image);
        return;
      }
      rasterizer_.RasterizeTile(tile, s.depth, s.ids);
      ShadeTile(tile, settings, meshes, s, image);
    });
  } else {
    // Background tiles are written in long row runs (see background_fill.h),
    // their share after each shaded tile so that their stores drain while the
    // next tile computes; whatever is left at the end.
    shaded_tiles_.clear();
    for (int tile = 0; tile < rasterizer_.num_tiles(); ++tile)
      if (rasterizer_.tile_triangle_count(tile) != 0) shaded_tiles_.push_back(tile);
    std::atomic<std::size_t> fill_cursor{0};
    fill_.Plan(rasterizer_, ss, background_rows_, settings.background.transparent, settings.width,
               settings.height, fill_cursor);
    const int count = static_cast<int>(shaded_tiles_.size());
    std::atomic<int> next{0};
    base::RunOnThreads(std::min(threads, std::max(count, 1)), [&](int thread) {
      TileScratch& s = scratch_[static_cast<std::size_t>(thread)];
      std::size_t credit = 0;  // background units owed, times count
      for (int i = next.fetch_add(1); i < count; i = next.fetch_add(1)) {
        const int tile = shaded_tiles_[static_cast<std::size_t>(i)];
        rasterizer_.RasterizeTile(tile, s.depth, s.ids);
        ShadeTile(tile, settings, meshes, s, image);
        credit += fill_.units();
        const std::size_t due = credit / static_cast<std::size_t>(count);
        credit -= due * static_cast<std::size_t>(count);
        fill_.Drain(due, image);
      }
      fill_.Drain(fill_.units(), image);
    });
  }
  if (tent) {
    // Every sample is shaded before any pixel reads its neighbours' samples.
    base::RunOnThreads(threads, [&](int t) {
      const int row0 = settings.height * t / threads, row1 = settings.height * (t + 1) / threads;
      TentResolveRows(row0, row1, settings, image);
    });
  }

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
  return base::kJobOk;
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

  // What ShadeSample did with a sample.
  enum class Kind {
    kColor,     // `color` holds the sample's colour
    kGround,    // a ground sample: nothing written (GroundShader shades it)
    kDeferred,  // Blinn-Phong: ShadeSurface's inputs went to lane i % 4 of deferred[i / 4]
  };

  [[gnu::always_inline]] glm::vec3 Shade(std::uint32_t id, int sx, int sy) {
    glm::vec3 color;
    if (ShadeSample(id, static_cast<float>(sx), static_cast<float>(sy), color, nullptr, 0) ==
        Kind::kGround)
      return r_.ground_shader_.Shade(sx, sy);
    return color;
  }

  // The colour of triangle `id` at sample position (sx, sy) (integers: sample
  // centres; multisampling passes a centroid between them); with `deferred`
  // set, Blinn-Phong surfaces are left to ShadeSurface4 (four at a time).
  [[gnu::always_inline]] Kind ShadeSample(std::uint32_t id, float sx, float sy, glm::vec3& color,
                                          SurfacePoints4* deferred, int i) {
    Entry& t = cache_[id & (kCacheSize - 1)];
    if (t.id != id) Load(id, t);
    if (t.ground) return Kind::kGround;  // most samples: nothing else to compute
    // Perspective-correct weights up to a common scale: edge function times
    // 1/w, as planes in sample space around the triangle's reference sample.
    // (Exact for integer positions: both terms are below 2^24.)
    const float fx = sx - static_cast<float>(t.ref_x), fy = sy - static_cast<float>(t.ref_y);
    const float w0 = t.wc[0] + t.wa[0] * fx + t.wb[0] * fy;
    const float w1 = t.wc[1] + t.wa[1] * fx + t.wb[1] * fy;
    const float w2 = t.wc[2] + t.wa[2] * fx + t.wb[2] * fy;
    const ShadingContext& ctx = r_.context_;
    const LightingModel model = ctx.model;
    color = glm::vec3(0.0f);
    if (t.lambert_plane) {
      color = LambertPlane(t, fx, fy);
      return Kind::kColor;
    }
    glm::vec3 albedo = t.albedo;
    const bool need_weights =
        t.interpolate_color || model == LightingModel::kBlinnPhong || t.texture != nullptr;
    float l0 = w0, l1 = w1, l2 = w2;
    if (need_weights) {
      const float inv = 1.0f / (w0 + w1 + w2);
      l0 = w0 * inv;
      l1 = w1 * inv;
      l2 = w2 * inv;
    }
    if (t.interpolate_color) albedo = l0 * t.col[0] + l1 * t.col[1] + l2 * t.col[2];
    if (t.texture != nullptr) albedo *= SampleTexture(t, w0 + w1 + w2, fx, fy);
    if (model == LightingModel::kUnlit) {
      color = albedo;
      return Kind::kColor;
    }
    glm::vec3 n = t.face_normal;
    // Unnormalized weights suffice: the interpolated normal is renormalized.
    if (t.smooth) n = w0 * t.n[0] + w1 * t.n[1] + w2 * t.n[2];
    const float len2 = glm::dot(n, n);
    if (model == LightingModel::kLambert) {
      // N.L / |N|, with the square root only for lit samples.
      const float d = glm::dot(n, ctx.key_dir);
      const float n_dot_l = d > 0.0f && len2 > 0.0f ? d / std::sqrt(len2) : 0.0f;
      color = albedo * (ctx.ambient + ctx.key_radiance * n_dot_l);
      return Kind::kColor;
    }
    n = len2 > 0.0f ? n * (1.0f / std::sqrt(len2)) : t.face_normal;
    const glm::vec3 p = l0 * t.p[0] + l1 * t.p[1] + l2 * t.p[2];
    // Only samples the key light reaches can lose it to a shadow; the map is
    // read off the surface's outer side (a back face's normal was turned).
    const float side = r_.body_shadow_ != nullptr && glm::dot(n, ctx.key_dir) > 0.0f
                           ? (t.back_facing ? -1.0f : 1.0f)
                           : 0.0f;
    if (deferred != nullptr) {  // ShadeSurfaceRow reads the map four lanes at a time
      SurfacePoints4& d = deferred[i >> 2];
      const int lane = i & 3;
      for (int c = 0; c < 3; ++c) {
        d.albedo[c][lane] = albedo[c];
        d.normal[c][lane] = n[c];
        d.position[c][lane] = p[c];
      }
      d.shadow_side[lane] = side;
      return Kind::kDeferred;
    }
    const float key = side != 0.0f ? r_.body_shadow_->SurfaceVisibility(p, side * n) : 1.0f;
    color = ShadeSurface(ctx, albedo, n, p, key);
    return Kind::kColor;
  }

  // Shade() as RGBA (alpha 1) for the single-sample path, which stores it as is.
  [[gnu::always_inline]] glm::vec4 ShadeRgba(std::uint32_t id, int sx, int sy) {
    Entry& t = cache_[id & (kCacheSize - 1)];
    if (t.id != id) Load(id, t);
    if (t.lambert_plane) {
      return LambertPlane(t, static_cast<float>(sx - t.ref_x), static_cast<float>(sy - t.ref_y),
                          1.0f);
    }
    return glm::vec4(Shade(id, sx, sy), 1.0f);
  }

#if defined(__SSE2__)
  // The terms of a sample's colour, base + key * max(D, 0) / |N|: for a
  // plane-lit triangle its (N, D) and the entry's lit_base / lit_key; for any
  // other the shaded colour (alpha 1) in `base`, zero `key` and zero (N, D).
  // kGround and kDeferred as ShadeSample (nothing written to nd, base, key).
  [[gnu::always_inline]] Kind ShadeTerms(std::uint32_t id, int sx, int sy, float* nd, float* base,
                                         float* key, SurfacePoints4* deferred, int i) {
    Entry& t = cache_[id & (kCacheSize - 1)];
    if (t.id != id) Load(id, t);
    if (t.ground) return Kind::kGround;
    if (t.lambert_plane) {
      const float fx = static_cast<float>(sx - t.ref_x), fy = static_cast<float>(sy - t.ref_y);
      _mm_store_ps(nd, PlaneAt(t, fx, fy));
      _mm_store_ps(base, _mm_load_ps(t.lit_base));
      _mm_store_ps(key, _mm_load_ps(t.lit_key));
      return Kind::kColor;
    }
    glm::vec3 c;
    const Kind kind =
        ShadeSample(id, static_cast<float>(sx), static_cast<float>(sy), c, deferred, i);
    if (kind != Kind::kColor) return kind;
    _mm_store_ps(base, simd::Set(glm::vec4(c, 1.0f)));
    _mm_store_ps(key, _mm_setzero_ps());
    _mm_store_ps(nd, _mm_setzero_ps());
    return Kind::kColor;
  }
#endif

 private:
  static constexpr std::uint32_t kCacheSize = 64;
  struct Entry {
    std::uint32_t id = kNoTriangle;
    bool ground = false, smooth = false, interpolate_color = false, back_facing = false;
    // Lambert with one albedo per triangle: the unnormalized normal N and
    // D = N . key_dir are linear in the sample position, so they are stored
    // as planes and a sample costs two plane evaluations, |N| and one divide:
    //   (N, D) = plane_c + plane_a * (x - ref_x) + plane_b * (y - ref_y),
    //   colour = lit_base + lit_key * max(D, 0) / |N|   (= albedo * (ambient + key * N.L)).
    bool lambert_plane = false;
    alignas(16) float plane_a[4] = {}, plane_b[4] = {}, plane_c[4] = {};  // (Nx, Ny, Nz, D)
    alignas(16) float lit_base[4] = {}, lit_key[4] = {};  // (albedo * ambient, 1), (albedo * key, 0)
    int ref_x = 0, ref_y = 0;  // reference sample (the triangle's bounds corner)
    float wa[3] = {}, wb[3] = {}, wc[3] = {};  // weight_i = wc + wa * (x - ref_x) + wb * (y - ref_y)
    glm::vec3 n[3], col[3], p[3], face_normal{0.0f, 0.0f, 1.0f}, albedo{1.0f};
    // Textured: (u, v) times the unnormalized weights, as planes like wa/wb/wc
    // (uv_a = sum_i wa[i] * uv_i, ...), and the weights' sum's planes.
    const Texture* texture = nullptr;
    glm::vec2 uv_a{0.0f}, uv_b{0.0f}, uv_c{0.0f};
    float sum_a = 0.0f, sum_b = 0.0f;
  };

  // The texture at a sample: with S = w0 + w1 + w2 (planes in x, y), uv =
  // (uv_c + uv_a x + uv_b y) / S, so d(uv)/dx = (uv_a - uv * sum_a) / S and
  // likewise in y: the exact derivatives of the perspective-correct uv.
  static glm::vec3 SampleTexture(const Entry& t, float sum, float fx, float fy) {
    if (!(sum != 0.0f)) return t.texture->Sample(glm::vec2(0.0f), 0.0f);
    const float inv = 1.0f / sum;
    const glm::vec2 uv = (t.uv_c + t.uv_a * fx + t.uv_b * fy) * inv;
    const glm::vec2 du_dx = (t.uv_a - uv * t.sum_a) * inv;
    const glm::vec2 du_dy = (t.uv_b - uv * t.sum_b) * inv;
    return t.texture->Sample(uv, t.texture->Lod(du_dx, du_dy));
  }

#if defined(__SSE2__)
  // The entry's (N, D) planes at (fx, fy): c + a * fx + b * fy, in that order.
  [[gnu::always_inline]] static __m128 PlaneAt(const Entry& t, float fx, float fy) {
    return _mm_add_ps(
        _mm_add_ps(_mm_load_ps(t.plane_c), _mm_mul_ps(_mm_load_ps(t.plane_a), _mm_set1_ps(fx))),
        _mm_mul_ps(_mm_load_ps(t.plane_b), _mm_set1_ps(fy)));
  }
#endif

  // Lambert from the entry's planes; `alpha` is the w of the result.
  [[gnu::always_inline]] static glm::vec4 LambertPlane(const Entry& t, float fx, float fy,
                                                       float alpha) {
#if defined(__SSE2__)
    alignas(16) float nd[4];
    _mm_store_ps(nd, PlaneAt(t, fx, fy));
    const float len2 = nd[0] * nd[0] + nd[1] * nd[1] + nd[2] * nd[2];
    const float n_dot_l = nd[3] > 0.0f && len2 > 0.0f ? nd[3] / std::sqrt(len2) : 0.0f;
    alignas(16) float out[4];
    _mm_store_ps(out, _mm_add_ps(_mm_load_ps(t.lit_base),
                                 _mm_mul_ps(_mm_load_ps(t.lit_key), _mm_set1_ps(n_dot_l))));
    return {out[0], out[1], out[2], alpha};
#else
    float nd[4];
    for (int k = 0; k < 4; ++k) nd[k] = t.plane_c[k] + t.plane_a[k] * fx + t.plane_b[k] * fy;
    const float len2 = nd[0] * nd[0] + nd[1] * nd[1] + nd[2] * nd[2];
    const float n_dot_l = nd[3] > 0.0f && len2 > 0.0f ? nd[3] / std::sqrt(len2) : 0.0f;
    return {t.lit_base[0] + t.lit_key[0] * n_dot_l, t.lit_base[1] + t.lit_key[1] * n_dot_l,
            t.lit_base[2] + t.lit_key[2] * n_dot_l, alpha};
#endif
  }
  static glm::vec3 LambertPlane(const Entry& t, float fx, float fy) {
    return glm::vec3(LambertPlane(t, fx, fy, 1.0f));
  }

  [[gnu::noinline]] void Load(std::uint32_t id, Entry& t) const {
    t.id = id;
    t.lambert_plane = false;
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
    if (t.ground) return;  // shaded by GroundShader from the sample position alone
    glm::vec3 corner[3];
    const SceneMesh& mesh = meshes_[tri.mesh];
    const glm::uvec3 v = mesh.triangles[tri.triangle];
    t.smooth = settings_.shading == ShadingMode::kSmooth && !mesh.normals.empty();
    t.back_facing = tri.back_facing;
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
    t.texture = nullptr;
    if (!mesh.textures.empty()) LoadTexture(mesh, tri, v, weights, t);
    t.lambert_plane =
        r_.context_.model == LightingModel::kLambert && !t.interpolate_color && t.texture == nullptr;
    if (t.lambert_plane) {
      const ShadingContext& ctx = r_.context_;
      for (int k = 0; k < 3; ++k) {
        t.plane_a[k] = t.plane_b[k] = 0.0f;
        t.plane_c[k] = t.face_normal[k];
      }
      if (t.smooth) {
        for (int k = 0; k < 3; ++k) {
          t.plane_a[k] = t.wa[0] * t.n[0][k] + t.wa[1] * t.n[1][k] + t.wa[2] * t.n[2][k];
          t.plane_b[k] = t.wb[0] * t.n[0][k] + t.wb[1] * t.n[1][k] + t.wb[2] * t.n[2][k];
          t.plane_c[k] = t.wc[0] * t.n[0][k] + t.wc[1] * t.n[1][k] + t.wc[2] * t.n[2][k];
        }
      }
      const glm::vec3 a(t.plane_a[0], t.plane_a[1], t.plane_a[2]);
      const glm::vec3 b(t.plane_b[0], t.plane_b[1], t.plane_b[2]);
      const glm::vec3 c(t.plane_c[0], t.plane_c[1], t.plane_c[2]);
      t.plane_a[3] = glm::dot(a, ctx.key_dir);
      t.plane_b[3] = glm::dot(b, ctx.key_dir);
      t.plane_c[3] = glm::dot(c, ctx.key_dir);
      const glm::vec3 base = t.albedo * ctx.ambient, key = t.albedo * ctx.key_radiance;
      for (int k = 0; k < 3; ++k) {
        t.lit_base[k] = base[k];
        t.lit_key[k] = key[k];
      }
      t.lit_base[3] = 1.0f;
      t.lit_key[3] = 0.0f;
    }
  }

  // The texture of a mesh triangle and its uv planes (see SampleTexture).
  static void LoadTexture(const SceneMesh& mesh, const RasterTriangle& tri, const glm::uvec3& v,
                          const glm::mat3* weights, Entry& t) {
    const std::int32_t k = mesh.triangle_textures.empty() ? 0 : mesh.triangle_textures[tri.triangle];
    if (k < 0 || static_cast<std::size_t>(k) >= mesh.textures.size()) return;
    t.texture = &mesh.textures[static_cast<std::size_t>(k)];
    // Without colours the texture is the albedo (base_color is for untextured triangles).
    if (mesh.triangle_colors.empty() && mesh.vertex_colors.empty()) t.albedo = glm::vec3(1.0f);
    t.uv_a = t.uv_b = t.uv_c = glm::vec2(0.0f);
    t.sum_a = t.sum_b = 0.0f;
    for (int i = 0; i < 3; ++i) {
      const glm::vec2 uv = weights == nullptr ? mesh.uvs[v[tri.order[i]]]
                                              : (*weights)[i].x * mesh.uvs[v[0]] +
                                                    (*weights)[i].y * mesh.uvs[v[1]] +
                                                    (*weights)[i].z * mesh.uvs[v[2]];
      t.uv_a += t.wa[i] * uv;
      t.uv_b += t.wb[i] * uv;
      t.uv_c += t.wc[i] * uv;
      t.sum_a += t.wa[i];
      t.sum_b += t.wb[i];
    }
  }

  const Rasterizer& raster_;
  std::span<const SceneMesh> meshes_;
  const RenderSettings& settings_;
  const Renderer& r_;
  Entry cache_[kCacheSize];
};

template <class Store>
void Renderer::ShadeGroundRow(int x0, int sy, int n, const bool* ground, Store&& store) const {
  for (int i = 0; i < n; i += 4) {
    if (!(ground[i] || ground[i + 1] || ground[i + 2] || ground[i + 3])) continue;
    float r[4], g[4], b[4];
    ground_shader_.Shade4(x0 + i, sy, r, g, b);
    for (int k = 0; k < 4 && i + k < n; ++k)
      if (ground[i + k]) store(i + k, glm::vec3(r[k], g[k], b[k]));
  }
}

template <class Store>
void Renderer::ShadeGroundPixelRow(int x0, int sy, int n, int ss, const bool* whole,
                                   Store&& store) const {
  for (int p = 0; p < n; p += 4) {
    if (!(whole[p] || whole[p + 1] || whole[p + 2] || whole[p + 3])) continue;
    float r[4], g[4], b[4];
    ground_shader_.ShadePixels4(x0 + p * ss, sy, ss, r, g, b);
    for (int k = 0; k < 4 && p + k < n; ++k)
      if (whole[p + k]) store((p + k) * ss, glm::vec3(r[k], g[k], b[k]));
  }
}

template <class Store>
void Renderer::ShadeSurfaceRow(int n, const bool* surface, SurfacePoints4* deferred,
                               Store&& store) const {
  for (int i = 0; i < n; i += 4) {
    if (!(surface[i] || surface[i + 1] || surface[i + 2] || surface[i + 3])) continue;
    SurfacePoints4& group = deferred[i >> 2];
    for (int k = 0; k < 4; ++k) {
      if (surface[i + k]) continue;  // an unused lane: give it harmless finite inputs
      for (int c = 0; c < 3; ++c) {
        group.albedo[c][k] = 0.0f;
        group.normal[c][k] = c == 1 ? 1.0f : 0.0f;
        group.position[c][k] = context_.eye[c] + (c == 1 ? 1.0f : 0.0f);
      }
      group.shadow_side[k] = 0.0f;
    }
    int shadowed = 0;  // lanes that read the shadow map
    alignas(16) float outward[3][4];
    for (int k = 0; k < 4; ++k) {
      shadowed |= group.shadow_side[k] != 0.0f ? 1 << k : 0;
      for (int c = 0; c < 3; ++c) outward[c][k] = group.shadow_side[k] * group.normal[c][k];
    }
    if (shadowed != 0) {
      body_shadow_->SurfaceVisibility4(group.position, outward, shadowed, group.key_visibility);
    } else {
      for (float& v : group.key_visibility) v = 1.0f;
    }
    float out[3][4];
    ShadeSurface4(context_, group, out);
    for (int k = 0; k < 4 && i + k < n; ++k)
      if (surface[i + k]) store(i + k, glm::vec3(out[0][k], out[1][k], out[2][k]));
  }
}

void Renderer::ShadeTile(int tile, const RenderSettings& settings,
                         std::span<const SceneMesh> meshes, TileScratch& s, Image& image) {
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
#if defined(__SSE2__)
      // Two passes over the row so the square roots and divides of plane-lit
      // samples run four at a time: first each sample's (N, D) and colour
      // terms (other samples get their final colour in `base`, key 0), then
      // colour = base + key * max(D, 0) / |N| as in LambertPlane, same order
      // of operations, so the bytes equal the one-sample path's.
      alignas(16) float nd[kTileSize][4], base[kTileSize][4], key[kTileSize][4];
      bool ground[kTileSize + 3] = {};  // + 3: the last group of four may pass n
      bool surface[kTileSize + 3] = {};  // Blinn-Phong samples left to ShadeSurface4
      SurfacePoints4 deferred[kTileSize / 4];
      bool any_ground = false, any_surface = false;
      const int n = x1 - x0;
      for (int i = 0; i < n; ++i) {
        const std::uint32_t id = s.ids[row + static_cast<std::size_t>(i)];
        if (id == kNoTriangle) {
          _mm_store_ps(base[i], simd::Set(bg));
          _mm_store_ps(key[i], _mm_setzero_ps());
          _mm_store_ps(nd[i], _mm_setzero_ps());
        } else {
          const SampleShader::Kind kind =
              shader.ShadeTerms(id, x0 + i, sy, nd[i], base[i], key[i], deferred, i);
          if (kind == SampleShader::Kind::kColor) continue;
          (kind == SampleShader::Kind::kGround ? ground : surface)[i] = true;
          (kind == SampleShader::Kind::kGround ? any_ground : any_surface) = true;
          _mm_store_ps(key[i], _mm_setzero_ps());
          _mm_store_ps(nd[i], _mm_setzero_ps());
        }
      }
      auto store_base = [&](int i, const glm::vec3& c) {
        _mm_store_ps(base[i], simd::Set(glm::vec4(c, 1.0f)));
      };
      if (any_ground) ShadeGroundRow(x0, sy, n, ground, store_base);
      if (any_surface) ShadeSurfaceRow(n, surface, deferred, store_base);
      for (int i = n; i < ((n + 3) & ~3); ++i) _mm_store_ps(nd[i], _mm_setzero_ps());
      for (int i = 0; i < n; i += 4) {
        __m128 x = _mm_load_ps(nd[i]), y = _mm_load_ps(nd[i + 1]), z = _mm_load_ps(nd[i + 2]),
               d = _mm_load_ps(nd[i + 3]);
        _MM_TRANSPOSE4_PS(x, y, z, d);
        const __m128 len2 =
            _mm_add_ps(_mm_add_ps(_mm_mul_ps(x, x), _mm_mul_ps(y, y)), _mm_mul_ps(z, z));
        const __m128 zero = _mm_setzero_ps();
        const __m128 lit = _mm_and_ps(_mm_cmpgt_ps(d, zero), _mm_cmpgt_ps(len2, zero));
        alignas(16) float n_dot_l[4];
        _mm_store_ps(n_dot_l, _mm_and_ps(lit, _mm_div_ps(d, _mm_sqrt_ps(len2))));
        for (int j = 0; j < 4 && i + j < n; ++j) {
          const __m128 c = _mm_add_ps(_mm_load_ps(base[i + j]),
                                      _mm_mul_ps(_mm_load_ps(key[i + j]), _mm_set1_ps(n_dot_l[j])));
          if ((reinterpret_cast<std::uintptr_t>(rgba + i + j) & 15u) == 0) {
            _mm_stream_ps(reinterpret_cast<float*>(rgba + i + j), c);
          } else {
            _mm_storeu_ps(reinterpret_cast<float*>(rgba + i + j), c);
          }
        }
      }
#else
      for (int sx = x0; sx < x1; ++sx, ++rgba) {
        const std::size_t at = row + static_cast<std::size_t>(sx - x0);
        const std::uint32_t id = s.ids[at];
        const bool hit = id != kNoTriangle;
        StreamStore(rgba, hit ? shader.ShadeRgba(id, sx, sy) : bg);
      }
#endif
      if (depth != nullptr) WriteDepthRow(s.depth.data() + row, s.ids.data() + row, x1 - x0, depth);
    }
    StreamFence();
    return;
  }

  // Supersampled: accumulate each output pixel's samples in row-major sample order.
  const int ox0 = x0 / ss, oy0 = y0 / ss, ox1 = x1 / ss, oy1 = y1 / ss;
  const int out_stride = kTileSize / ss;
  // Only the tile's (kTileSize / ss)^2 output pixels are used.
  const auto used = static_cast<std::ptrdiff_t>(out_stride) * out_stride;
  std::fill(s.accum.begin(), s.accum.begin() + used, glm::vec4(0.0f));
  std::fill(s.nearest.begin(), s.nearest.begin() + used, 0.0f);
  const int ss_shift = ss == 4 ? 2 : 1;  // ss is 2 or 4 here
  const std::size_t sample_stride = static_cast<std::size_t>(rasterizer_.width());
  glm::vec4* samples = samples_.empty() ? nullptr : samples_.data() + static_cast<std::size_t>(y0) * sample_stride;
  const bool multisample = settings.antialias == AntiAlias::kMultisample;
  const auto ground_mesh = static_cast<std::uint32_t>(meshes.size());
  glm::vec3 color[kTileSize];  // the current sample row's colours
  Whole whole[kTileSize / 2];  // multisampling: the current pixel row's pixels
  for (int sy = y0; sy < y1; ++sy) {
    const glm::vec3 bg = background_rows_[static_cast<std::size_t>(sy)];
    const std::size_t row = static_cast<std::size_t>(sy - y0) * kTileSize;
    const std::size_t out_row = static_cast<std::size_t>((sy - y0) / ss) * static_cast<std::size_t>(out_stride);
    const int j = (sy - y0) % ss;  // sample row within the pixel
    const std::uint32_t* pixel_row_ids = s.ids.data() + row - static_cast<std::size_t>(j) * kTileSize;
    // The row's colours first, so the ground's samples are shaded four at a time.
    bool ground[kTileSize + 3] = {}, surface[kTileSize + 3] = {};
    SurfacePoints4 deferred[kTileSize / 4];
    bool any_ground = false, any_surface = false;
    bool ground_pixel[kTileSize / 2 + 3] = {};  // multisampling: whole ground pixels of the row
    bool any_ground_pixel = false;
    if (multisample && j == 0) ClassifyPixels(pixel_row_ids, x1 - x0, ss_shift, ground_mesh, whole);
    for (int sx = x0; sx < x1; ++sx) {
      const std::uint32_t id = s.ids[row + static_cast<std::size_t>(sx - x0)];
      const int i = sx - x0;
      glm::vec2 at(static_cast<float>(sx), static_cast<float>(sy));
      // A pixel inside one triangle is shaded once, at its centre (where the
      // mean of its samples' positions is), and that colour is all of its
      // samples'. Pixels on an edge are shaded per sample, so edges are
      // exactly supersampling's. A pixel all ground is shaded once too, with
      // its grid lines filtered over the pixel (GroundShader::ShadePixels4).
      if (multisample) {
        const Whole kind = whole[i >> ss_shift];
        if (kind != Whole::kNo) {
          // Only the first sample row shades, at the pixel's first sample;
          // the loop then goes on at the next pixel (ss divides x0).
          const bool shade = j == 0 && kind != Whole::kEmpty;
          sx |= ss - 1;
          if (!shade) continue;
          if (kind == Whole::kGround) {
            ground_pixel[i >> ss_shift] = any_ground_pixel = true;
            continue;
          }
          const float centre = 0.5f * static_cast<float>(ss - 1);
          at += glm::vec2(centre);
        }
      }
      if (id == kNoTriangle) continue;
      const SampleShader::Kind kind =
          shader.ShadeSample(id, at.x, at.y, color[static_cast<std::size_t>(i)], deferred, i);
      if (kind == SampleShader::Kind::kGround) ground[i] = any_ground = true;
      if (kind == SampleShader::Kind::kDeferred) surface[i] = any_surface = true;
    }
    auto store_color = [&](int i, const glm::vec3& c) { color[static_cast<std::size_t>(i)] = c; };
    if (any_ground) ShadeGroundRow(x0, sy, x1 - x0, ground, store_color);
    if (any_ground_pixel) {
      ShadeGroundPixelRow(x0, sy, (x1 - x0) >> ss_shift, ss, ground_pixel, store_color);
    }
    if (any_surface) ShadeSurfaceRow(x1 - x0, surface, deferred, store_color);
    if (multisample && j == 0) {
      AccumulateWholePixels(x1 - x0, ss_shift, whole, color, s.depth.data() + row,
                            background_rows_.data() + sy, transparent, out_row, s,
                            samples == nullptr ? nullptr : samples + x0, sample_stride);
    }
    for (int sx = x0; sx < x1; ++sx) {
      if (multisample && whole[(sx - x0) >> ss_shift] != Whole::kNo) {
        sx |= ss - 1;  // accumulated above
        continue;
      }
      const std::size_t at = row + static_cast<std::size_t>(sx - x0);
      const std::uint32_t id = s.ids[at];
      const std::size_t pixel = out_row + static_cast<std::size_t>((sx - x0) >> ss_shift);
      const glm::vec4 sample =
          AddSample(id != kNoTriangle, color[static_cast<std::size_t>(sx - x0)], bg, s.depth[at],
                    transparent, s.accum[pixel], s.nearest[pixel]);
      if (samples != nullptr) samples[static_cast<std::size_t>(sx)] = sample;
    }
    if (samples != nullptr) samples += sample_stride;
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
      if (write_depth) image.depth[out] = s.nearest[local] > 0.0f ? 1.0f / s.nearest[local] : inf;
    }
  }
}

void Renderer::FillBackgroundTile(int tile, const RenderSettings& settings, Image& image) {
  // Same values the shading path gives an empty pixel: the box average of the
  // background rows it covers (transparent: zero colour and alpha).
  const int ss = settings.supersample;
  if (!samples_.empty()) {
    const int x0 = (tile % rasterizer_.tiles_x()) * kTileSize;
    const int y0 = (tile / rasterizer_.tiles_x()) * kTileSize;
    const int x1 = std::min(x0 + kTileSize, rasterizer_.width());
    const int y1 = std::min(y0 + kTileSize, rasterizer_.height());
    for (int sy = y0; sy < y1; ++sy) {
      const glm::vec4 sample = settings.background.transparent
                                   ? glm::vec4(0.0f)
                                   : glm::vec4(background_rows_[static_cast<std::size_t>(sy)], 0.0f);
      glm::vec4* row = samples_.data() + static_cast<std::size_t>(sy) * static_cast<std::size_t>(rasterizer_.width());
      std::fill(row + x0, row + x1, sample);
    }
  }
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

void Renderer::TentResolveRows(int row0, int row1, const RenderSettings& settings,
                               Image& image) const {
  // Per axis, the samples from half a pixel before the pixel to half a pixel
  // after it: 2 * ss of them, sample k (from that first one) at offset
  // (k + 0.5) / ss - 1 output pixels from the pixel centre.
  const int ss = settings.supersample, taps = 2 * ss;
  float weight[8];
  for (int k = 0; k < taps; ++k) {
    const float d = (static_cast<float>(k) + 0.5f) / static_cast<float>(ss) - 1.0f;
    weight[k] = 1.0f - std::abs(d);
  }
  const int sw = rasterizer_.width(), sh = rasterizer_.height();
  const bool transparent = settings.background.transparent;
  for (int oy = row0; oy < row1; ++oy) {
    const int sy0 = oy * ss - ss / 2;
    for (int ox = 0; ox < settings.width; ++ox) {
      const int sx0 = ox * ss - ss / 2;
      glm::vec4 sum(0.0f);  // sum of weight * (rgb, coverage)
      float total = 0.0f;   // sum of the weights of samples inside the raster
      for (int j = 0; j < taps; ++j) {
        const int sy = sy0 + j;
        if (sy < 0 || sy >= sh) continue;
        const glm::vec4* row = samples_.data() + static_cast<std::size_t>(sy) * static_cast<std::size_t>(sw);
        for (int i = 0; i < taps; ++i) {
          const int sx = sx0 + i;
          if (sx < 0 || sx >= sw) continue;
          const float w = weight[j] * weight[i];
          sum += w * row[sx];
          total += w;
        }
      }
      glm::vec4& out = image.rgba[image.index(ox, oy)];
      if (transparent) {
        // Straight colour of the covered samples (empty ones hold zero rgb).
        out = sum.w > 0.0f ? glm::vec4(glm::vec3(sum) / sum.w, sum.w / total) : glm::vec4(0.0f);
      } else {
        out = glm::vec4(glm::vec3(sum) / total, 1.0f);
      }
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
