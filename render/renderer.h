#pragma once
// The top-level frame renderer: camera + meshes + overlays -> Image.
//
//   render::Renderer renderer;                 // keep one per output stream
//   render::RenderSettings settings{.width = 1280, .height = 720, .supersample = 2};
//   render::SceneMesh body{.positions = p, .normals = n, .triangles = t};
//   base::JobStatus s = renderer.Render(camera, {&body, 1}, overlays, settings, image);
//
// Stages: world -> clip transform (threaded over vertices), rasterizer setup
// and binning, then per 64x64-sample tile: visibility (z-buffer) pass,
// deferred shading of each visible sample once, box resolve of the
// supersample x supersample samples of each output pixel (or, for a tent
// resolve, a second pass over the kept samples); then overlays. With
// multisampling a pixel inside one triangle is shaded once.
// Output bytes are identical for any thread count.

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "base/error.h"
#include "render/raster/background_fill.h"
#include "render/camera.h"
#include "render/raster/ground_shader.h"
#include "render/image.h"
#include "render/raster/overlay.h"
#include "render/raster/rasterizer.h"
#include "render/raster/shading.h"
#include "render/raster/shading4.h"
#include "render/raster/shadow_map.h"
#include "render/raster/texture.h"

namespace render {

// One triangle mesh in world space. Spans are borrowed for the Render call.
struct SceneMesh {
  std::span<const glm::vec3> positions{};        // #V world-space positions
  std::span<const glm::vec3> normals{};          // #V unit normals, or empty (flat shading)
  std::span<const glm::uvec3> triangles{};       // #T vertex indices, counter-clockwise = front
  std::span<const glm::vec3> vertex_colors{};    // #V linear RGB albedo, or empty
  std::span<const glm::vec3> triangle_colors{};  // #T albedo per triangle (e.g. per patch), or
                                               // empty; wins over vertex_colors
  glm::vec3 base_color{0.75f, 0.72f, 0.68f};   // albedo when both colour spans are empty
  // Base colour textures. A textured triangle's albedo is texture(uv) times its
  // triangle colour, else its interpolated vertex colour, else 1 (base_color is
  // for untextured triangles only). uv is interpolated perspective-correctly per
  // sample and filtered trilinearly, its level of detail from the exact screen
  // derivatives of that interpolation.
  std::span<const glm::vec2> uvs{};                  // #V, required with textures
  std::span<const Texture> textures{};               // borrowed like the spans
  std::span<const std::int32_t> triangle_textures{};  // #T index into textures (-1 or out of
                                                     // range: untextured), or empty: textures[0]
  bool casts_contact_shadow = true;            // darken the ground under this mesh
  bool closed = false;  // closed and outward (deform::IsClosedOutward): a cheaper shadow map
};

// How the supersample x supersample samples of a pixel become its colour.
enum class ResolveFilter {
  // The mean of the pixel's own samples (a one-pixel box).
  kBox,
  // A tent of radius one output pixel, weight max(0, 1 - |dx|) * max(0, 1 - |dy|)
  // with (dx, dy) the sample's offset from the pixel centre in output pixels:
  // the pixel's own samples and the nearer half of its neighbours' (at 2x2 the
  // per-axis weights are 1/4, 3/4, 3/4, 1/4). Softer edges, less stair-stepping
  // in motion. At the image border the weights of the samples inside are
  // renormalized. Costs a frame-sized sample buffer (16 bytes a sample) and a
  // second pass; colour only (depth stays the nearest of the pixel's own samples).
  kTent,
};

// How the supersample x supersample samples of a pixel are shaded.
enum class AntiAlias {
  // Every sample is shaded (ss^2 shades a pixel). The default.
  kSupersample,
  // Multisampling: depth and coverage per sample as above, but a pixel whose
  // samples all see the same mesh triangle is shaded once, at its centre, and
  // that colour goes to all of its samples; so is a pixel all ground, with its
  // grid lines box-filtered over the pixel and the cast shadow's visibility
  // averaged over its samples (GroundShader::ShadePixels4). Pixels on an edge
  // are shaded per sample, so edges equal supersampling's. Against a 4x4
  // supersampled reference its mean and 99th-percentile errors are at most
  // 2x2 supersampling's (tests/render/raster/multisample_test.cpp): one shade
  // at the centre of a curved interior is a little further off than the mean
  // of four, and filtered grid lines much closer.
  kMultisample,
};

struct RenderSettings {
  int width = 1280;        // output pixels, >= 1; width * supersample <= 16384
  int height = 720;        // output pixels, >= 1; height * supersample <= 16384
  int supersample = 1;     // samples per axis per pixel: 1, 2 or 4
  ResolveFilter resolve = ResolveFilter::kBox;  // with supersample 1 both are the identity
  AntiAlias antialias = AntiAlias::kSupersample;  // with supersample 1 both are the identity
  int threads = 0;         // worker threads; 0 = hardware concurrency
  bool cull_back_faces = false;
  bool clip_far = false;   // clip at camera.far_plane: nothing beyond it is drawn (see RasterSettings)
  ShadingMode shading = ShadingMode::kSmooth;
  LightingModel lighting = LightingModel::kBlinnPhong;
  LightRig lights;
  bool ground = true;          // draw the ground plane
  bool ground_at_scene_min = true;  // place the ground at the lowest scene y ...
  float ground_y = 0.0f;       // ... or at this world y when ground_at_scene_min is false
  GroundStyle ground_style;
  // The key light's cast shadow of every mesh, on the ground and on the
  // meshes themselves (a shadow map with percentage-closer filtering, see
  // shadow_map.h), taking away the key light's share only (ambient, fill and
  // rim remain). The ground gets it when the key light is above it (key
  // direction y > 0). About 14 % of a default frame (bench shadow_frame_share).
  // Off: the image of a renderer without shadow maps, bit for bit.
  bool shadows = true;
  ShadowMapSettings shadow_map;
  Background background;
  bool write_depth = true;     // fill Image::depth (needed for depth-tested overlays)
};

// Renders frames, reusing its buffers between calls; not thread-safe itself
// (it uses its own threads inside Render).
class Renderer {
 public:
  // Validates sizes (spans against #V/#T, settings ranges), then renders into
  // `image`, resizing it to width x height. Triangles with out-of-range
  // indices are skipped. On a bad argument returns the failed check and leaves
  // `image` untouched.
  base::JobStatus Render(const Camera& camera, std::span<const SceneMesh> meshes,
                         const Overlays& overlays, const RenderSettings& settings, Image& image);

  // The rasterizer of the last frame (for tests and statistics).
  const Rasterizer& rasterizer() const { return rasterizer_; }

 private:
  struct TileScratch {
    std::vector<float> depth;               // kTileSize^2 samples, 1/view depth
    std::vector<std::uint32_t> ids;         // kTileSize^2 samples
    std::vector<glm::vec4> accum;           // output pixels of one tile: rgb sum, covered count
    std::vector<float> nearest;             // output pixels of one tile: max 1/w (0 = empty)
  };
  class SampleShader;
  // Tent resolve only (it also fills samples_); the box resolve writes
  // background tiles through fill_.
  void FillBackgroundTile(int tile, const RenderSettings& settings, Image& image);
  // Calls store(i, colour) for every i in [0, n) with ground[i] set (`ground`
  // holds n rounded up to 4 entries), the colour of ground sample (x0 + i, sy).
  template <class Store>
  void ShadeGroundRow(int x0, int sy, int n, const bool* ground, Store&& store) const;
  // Multisampling: calls store(p * ss, colour) for every pixel p in [0, n)
  // of sample row sy with whole[p] set (n rounded up to 4 entries), the
  // colour of the ground pixel whose first sample is (x0 + p * ss, sy).
  template <class Store>
  void ShadeGroundPixelRow(int x0, int sy, int n, int ss, const bool* whole, Store&& store) const;
  enum class Whole : std::uint8_t { kNo, kTriangle, kGround, kEmpty };
  void AccumulateWholePixels(int n, int ss_shift, const Whole* whole, const glm::vec3* color,
                             const float* depth, const glm::vec3* background, bool transparent,
                             std::size_t out_row, TileScratch& s, glm::vec4* samples,
                             std::size_t sample_stride) const;
  void ClassifyPixels(const std::uint32_t* ids, int n, int ss_shift, std::uint32_t ground_mesh,
                      Whole* whole) const;
  // Calls store(i, colour) for every i in [0, n) with surface[i] set: the
  // Blinn-Phong colour from the ShadeSurface inputs in lane i % 4 of
  // deferred[i / 4], four at a time (ShadeSurface4). Fills unused lanes.
  template <class Store>
  void ShadeSurfaceRow(int n, const bool* surface, SurfacePoints4* deferred,
                       Store&& store) const;
  void ShadeTile(int tile, const RenderSettings& settings, std::span<const SceneMesh> meshes,
                 TileScratch& scratch, Image& image);
  // Tent resolve of output rows [row0, row1) from samples_ into `image`.
  void TentResolveRows(int row0, int row1, const RenderSettings& settings, Image& image) const;

  Rasterizer rasterizer_;
  std::vector<std::vector<glm::vec4>> clip_positions_;  // per mesh (+ ground), #V
  std::vector<glm::vec3> ground_positions_;             // 4 corners of the ground quad
  std::vector<glm::uvec3> ground_triangles_;            // its 2 triangles
  std::vector<ContactShadow> shadows_;
  std::vector<glm::vec3> background_rows_;              // per sample row
  std::vector<TileScratch> scratch_;                    // per thread
  // Box resolve: the background tiles, written in row runs (see background_fill.h).
  BackgroundFill fill_;
  std::vector<int> shaded_tiles_;                       // tiles with triangles, ascending
  // Tent resolve only: every shaded sample of the frame, row-major over the
  // sample raster: rgb (the background where empty; 0 there when transparent)
  // and coverage (1 covered, 0 empty). Empty otherwise.
  std::vector<glm::vec4> samples_;
  ShadingContext context_;
  GroundShader ground_shader_;                          // this frame's ground (when drawn)
  ShadowMap shadow_map_;                                // this frame's key-light map (when used)
  const ShadowMap* body_shadow_ = nullptr;              // &shadow_map_ when this frame has one
  std::vector<ShadowCaster> casters_;
  float grid_spacing_ = 1.0f;
};

// One-shot convenience: a temporary Renderer. Returns an empty image when the
// arguments fail validation.
Image Render(const Camera& camera, std::span<const SceneMesh> meshes, const Overlays& overlays,
             const RenderSettings& settings);

}  // namespace render
