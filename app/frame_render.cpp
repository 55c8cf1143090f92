#include "app/frame_render.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <utility>

#include "render/raster/overlay.h"

namespace app {
namespace {

void AddSkeleton(const deform::DeformedFrame& f, const mocap::Skeleton& s, render::Overlays& o) {
  render::LineOverlay bones;
  bones.depth_test = false;
  render::AppendSkeletonLines(f.joint_positions, s.parents, bones);
  o.lines.push_back(std::move(bones));
  render::PointOverlay joints;
  joints.points = f.joint_positions;
  joints.depth_test = false;
  o.points.push_back(std::move(joints));
}

// Copies the right half of `right` over `left`, and draws a divider.
void ComposeSplit(const render::Image& right, render::Image& left) {
  const int mid = left.width / 2;
  for (int y = 0; y < left.height; ++y) {
    for (int x = mid; x < left.width; ++x) left.at(x, y) = right.at(x, y);
    left.at(mid, y) = glm::vec4(1.0f);
    if (mid > 0) left.at(mid - 1, y) = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  }
}

// Copies `half` into columns x0.. of `into` (colour, and depth when both have it).
void PasteHalf(const render::Image& half, int x0, render::Image& into) {
  for (int y = 0; y < half.height; ++y) {
    for (int x = 0; x < half.width; ++x) {
      into.at(x0 + x, y) = half.at(x, y);
      if (!into.depth.empty() && !half.depth.empty()) {
        into.depth[into.index(x0 + x, y)] = half.depth[half.index(x, y)];
      }
    }
  }
}

void DrawDivider(render::Image& image) {
  const int mid = image.width / 2;
  for (int y = 0; y < image.height; ++y) {
    image.at(mid, y) = glm::vec4(1.0f);
    if (mid > 0) image.at(mid - 1, y) = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  }
}

// The colour bar of the displacement overlay in the top right corner: the
// ramp from 0 (bottom) to `scale` (top), labelled in model units.
void DrawColorBar(float scale, render::Image& image) {
  const int bar_w = 14, bar_h = std::max(40, image.height / 3);
  const int x0 = image.width - bar_w - 12, y0 = 44;
  if (x0 < 0 || y0 + bar_h + 20 > image.height) return;
  for (int y = 0; y < bar_h; ++y) {
    const glm::vec3 c = HeatRamp(1.0f - static_cast<float>(y) / static_cast<float>(bar_h - 1));
    for (int x = 0; x < bar_w; ++x) image.at(x0 + x, y0 + y) = glm::vec4(c, 1.0f);
  }
  char top[32];
  std::snprintf(top, sizeof(top), "%g", static_cast<double>(scale));
  const double size = 0.45;
  render::DrawText({.text = top, .origin_px = {x0 - 8 * static_cast<int>(std::strlen(top)) - 4, y0 + 8},
                    .scale = size},
                   image);
  render::DrawText({.text = "0", .origin_px = {x0 - 14, y0 + bar_h}, .scale = size}, image);
  render::DrawText({.text = "|d|", .origin_px = {x0 - 10, y0 - 8}, .scale = size}, image);
}

base::Status DrawOne(const Character& ch, const deform::DeformedFrame& f,
                     const render::Camera& camera, const render::RenderSettings& settings,
                     const FrameDrawOptions& o, const std::string& label, int label_x,
                     bool frame_label, std::span<const glm::vec3> colors, render::Renderer& r,
                     render::Image& into) {
  const deform::Mesh& bind = ch.mesh.bind;
  render::SceneMesh body{.positions = f.positions, .normals = f.normals,
                         .triangles = bind.triangles,
                         .vertex_colors = colors.empty() ? std::span<const glm::vec3>(bind.colors)
                                                         : colors,
                         .closed = ch.closed_surface};
  if (o.textures && ch.textures && bind.uvs.size() == bind.positions.size() &&
      ch.textures->triangle_textures.size() == bind.triangles.size()) {
    body.uvs = bind.uvs;
    body.textures = ch.textures->textures;
    body.triangle_textures = ch.textures->triangle_textures;
  }
  render::Overlays overlays;
  if (o.skeleton) AddSkeleton(f, ch.skeleton, overlays);
  overlays.wireframe = o.wireframe;
  std::string frame_text = "frame " + std::to_string(o.frame_number);
  if (o.view >= 0) frame_text += "  view " + std::to_string(o.view);
  if (o.frame_text) frame_text = *o.frame_text;
  if (frame_label && !frame_text.empty()) {
    overlays.text.push_back({.text = frame_text, .origin_px = {10, settings.height - 12}});
  }
  if (!label.empty()) {
    // Shrunk when it would run past its view (about 15 px a character at 0.8).
    const double room = static_cast<double>(settings.width - label_x - 10);
    const double scale = std::min(0.8, 0.8 * room / (15.0 * static_cast<double>(label.size())));
    overlays.text.push_back({.text = label, .origin_px = {label_x, 30}, .scale = std::max(scale, 0.3)});
  }
  const base::JobStatus js = r.Render(camera, {&body, 1}, overlays, settings, into);
  if (!js) {
    return base::MakeError(base::ErrorCode::kInternal, {ch.source, 0, 0, {}},
                           std::string("renderer refused the frame: ") + js.what);
  }
  return base::Status::Ok();
}

}  // namespace

base::Status DrawCharacterFrame(const Character& character, const deform::DeformedFrame& frame,
                                const deform::DeformedFrame* right, const render::Camera& camera,
                                const render::RenderSettings& settings,
                                const FrameDrawOptions& options, render::Renderer& renderer,
                                render::Renderer& right_renderer, render::Image& scratch,
                                render::Image& into) {
  if (right == nullptr) {
    base::Status s = DrawOne(character, frame, camera, settings, options, "", 0, true,
                             options.left_colors, renderer, into);
    if (s.ok() && options.color_bar_scale > 0.0f) DrawColorBar(options.color_bar_scale, into);
    return s;
  }
  if (options.side_by_side) {
    // Each body whole in its own half: two renders of half the width, pasted.
    render::RenderSettings half = settings;
    half.width = settings.width / 2;
    base::Status s = DrawOne(character, frame, camera, half, options, options.left_label, 10, true,
                             options.left_colors, renderer, scratch);
    if (!s.ok()) return s;
    if (into.width != settings.width || into.height != settings.height) {
      into = render::Image(settings.width, settings.height);
    }
    into.depth.resize(scratch.depth.empty() ? 0 : into.rgba.size());
    PasteHalf(scratch, 0, into);
    half.width = settings.width - settings.width / 2;
    s = DrawOne(character, *right, camera, half, options, options.right_label, 10, false,
                options.right_colors, right_renderer, scratch);
    if (!s.ok()) return s;
    PasteHalf(scratch, settings.width / 2, into);
    DrawDivider(into);
    if (options.color_bar_scale > 0.0f) DrawColorBar(options.color_bar_scale, into);
    return base::Status::Ok();
  }
  base::Status s = DrawOne(character, frame, camera, settings, options, options.left_label, 10,
                           true, options.left_colors, renderer, into);
  if (!s.ok()) return s;
  s = DrawOne(character, *right, camera, settings, options, options.right_label,
              settings.width / 2 + 10, true, options.right_colors, right_renderer, scratch);
  if (!s.ok()) return s;
  ComposeSplit(scratch, into);
  if (options.color_bar_scale > 0.0f) DrawColorBar(options.color_bar_scale, into);
  return base::Status::Ok();
}

std::shared_ptr<const CharacterTextures> BuildCharacterTextures(const deform::SkinnedMesh& mesh) {
  const deform::MeshMaterials& m = mesh.materials;
  if (!m.textured() || mesh.bind.uvs.size() != mesh.bind.positions.size() ||
      m.triangle_material.size() != mesh.bind.triangles.size()) {
    return nullptr;
  }
  auto out = std::make_shared<CharacterTextures>();
  std::vector<std::int32_t> of_material(m.materials.size(), -1);
  for (std::size_t k = 0; k < m.materials.size(); ++k) {
    const deform::Material& mat = m.materials[k];
    if (mat.texture < 0 || static_cast<std::size_t>(mat.texture) >= m.images.size()) continue;
    of_material[k] = static_cast<std::int32_t>(out->textures.size());
    out->textures.emplace_back(*m.images[static_cast<std::size_t>(mat.texture)], mat.wrap_s, mat.wrap_t);
  }
  out->triangle_textures.resize(m.triangle_material.size());
  for (std::size_t t = 0; t < m.triangle_material.size(); ++t) {
    const std::int32_t k = m.triangle_material[t];
    out->triangle_textures[t] = k >= 0 && static_cast<std::size_t>(k) < of_material.size() ? of_material[static_cast<std::size_t>(k)] : -1;
  }
  return out;
}

std::vector<glm::vec3> PatchTint(std::span<const deform::PatchSetup> patches, int num_vertices,
                                 std::span<const glm::vec3> base) {
  static constexpr glm::vec3 kTints[] = {{0.95f, 0.35f, 0.1f}, {0.1f, 0.55f, 0.95f},
                                         {0.2f, 0.8f, 0.25f},  {0.85f, 0.2f, 0.75f},
                                         {0.95f, 0.8f, 0.1f},  {0.1f, 0.8f, 0.8f}};
  const glm::vec3 plain = render::SceneMesh{}.base_color;
  const auto nv = static_cast<std::size_t>(num_vertices);
  std::vector<glm::vec3> out(nv);
  for (std::size_t v = 0; v < nv; ++v) out[v] = base.size() == nv ? base[v] : plain;
  std::vector<float> weight(nv, 0.0f);
  for (std::size_t k = 0; k < patches.size(); ++k) {
    const deform::PatchSetup& p = patches[k];
    const glm::vec3 tint = kTints[k % std::size(kTints)];
    for (std::size_t r = 0; r < p.bound.binding.vertex.size() && r < p.border_weight.size(); ++r) {
      const auto v = static_cast<std::size_t>(p.bound.binding.vertex[r]);
      if (v >= nv || p.border_weight[r] <= weight[v]) continue;
      // The strongest patch wins where regions overlap.
      weight[v] = p.border_weight[r];
      const glm::vec3 b = base.size() == nv ? base[v] : plain;
      out[v] = glm::mix(b, tint, 0.75f * weight[v]);
    }
  }
  return out;
}

glm::vec3 HeatRamp(float t) {
  static constexpr glm::vec3 kStops[] = {
      {0.08f, 0.12f, 0.45f}, {0.05f, 0.6f, 0.75f}, {0.95f, 0.8f, 0.15f}, {0.85f, 0.1f, 0.05f}};
  t = std::clamp(t, 0.0f, 1.0f) * 3.0f;
  const int i = std::min(static_cast<int>(t), 2);
  return glm::mix(kStops[i], kStops[i + 1], t - static_cast<float>(i));
}

void DisplacementColors(std::span<const glm::vec3> global, std::span<const glm::vec3> layered,
                        float scale, std::vector<glm::vec3>& out) {
  out.resize(layered.size());
  for (std::size_t v = 0; v < layered.size(); ++v) {
    const float d = v < global.size() ? glm::length(layered[v] - global[v]) : 0.0f;
    out[v] = HeatRamp(scale > 0.0f ? d / scale : 0.0f);
  }
}

float NiceScale(float value) {
  if (!(value > 0.0f) || !std::isfinite(value)) return 1.0f;
  const float decade = std::pow(10.0f, std::floor(std::log10(value)));
  for (const float step : {1.0f, 2.0f, 5.0f, 10.0f}) {
    if (step * decade >= value) return step * decade;
  }
  return 10.0f * decade;
}

}  // namespace app
