#pragma once
// Drawing one evaluated frame of a character (or a split view of two), shared by
// `patchskin render` and the golden-image tests so both go through the same
// deform::FramePipeline -> render::Renderer path.

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "app/character.h"
#include "deform/pipeline/frame_pipeline.h"
#include "deform/patch/patch_layer.h"
#include "base/error.h"
#include "render/camera.h"
#include "render/image.h"
#include "render/renderer.h"

namespace app {

struct FrameDrawOptions {
  bool skeleton = false;     // overlay the skeleton (bones and joints, no depth test)
  bool wireframe = false;    // overlay the mesh edges
  int frame_number = 0;      // printed at the bottom left as "frame N" (a turntable's motion frame) ...
  int view = -1;             // ... then a turntable's view (0-based) as "  view V"; -1 none ...
  std::optional<std::string> frame_text{};  // ... unless this is set (empty: no label)
  std::string left_label;    // two bodies: what each shows, printed at the top of each half
  std::string right_label;
  // Two bodies: true = side by side (each whole body in its own half-width
  // viewport; `camera` must be made for that half's aspect), false = a wipe
  // (both rendered full width from `camera`, the right half of `right` copied
  // over the left one's).
  bool side_by_side = false;
  // Albedo per vertex of each body (#V; empty: the mesh's own): the patch and
  // displacement overlays (PatchTint, DisplacementColors).
  std::span<const glm::vec3> left_colors{};
  std::span<const glm::vec3> right_colors{};
  // > 0: a colour bar of DisplacementColors' ramp from 0 to this (model units)
  // in the top right corner.
  float color_bar_scale = 0.0f;
  bool textures = true;  // draw the character's textures (false: its colours alone, as untextured)
};

// Albedo of every vertex with each patch's region tinted by its own colour,
// weighted by the border fade beta of its bound vertices (so the fade shows
// as a fade of the tint); elsewhere `base` (#V, or empty: the default albedo).
std::vector<glm::vec3> PatchTint(std::span<const deform::PatchSetup> patches, int num_vertices,
                                 std::span<const glm::vec3> base);

// The heat ramp of the displacement overlay at t in [0, 1] (blue, cyan,
// yellow, red), linear RGB.
glm::vec3 HeatRamp(float t);

// The textures of a character's mesh as the renderer samples them: one mip
// pyramid per material with a texture (its image and wrap modes), and the
// texture of each bind triangle (-1: untextured).
struct CharacterTextures {
  std::vector<render::Texture> textures;
  std::vector<std::int32_t> triangle_textures;  // #T
};
// Null when no material of `mesh` has a texture (or the mesh has no uvs).
// Costs one pass over each image's texels.
std::shared_ptr<const CharacterTextures> BuildCharacterTextures(const deform::SkinnedMesh& mesh);

// Albedo of every vertex by |layered - global| / scale on HeatRamp (#V each).
void DisplacementColors(std::span<const glm::vec3> global, std::span<const glm::vec3> layered,
                        float scale, std::vector<glm::vec3>& out);

// The smallest of 1, 2, 5 x 10^k at or above `value` (> 0), for a scale that
// does not change with every small change of the largest displacement; 1 for
// value <= 0.
float NiceScale(float value);

// Renders `frame` into `into` (settings.width x settings.height), or, when
// `right` is set, `frame` and `right` side by side or as a wipe, with a
// divider. `right_renderer` and `scratch` are only used for two bodies.
// Errors: kInternal when the renderer refuses the frame.
base::Status DrawCharacterFrame(const Character& character, const deform::DeformedFrame& frame,
                                const deform::DeformedFrame* right, const render::Camera& camera,
                                const render::RenderSettings& settings,
                                const FrameDrawOptions& options, render::Renderer& renderer,
                                render::Renderer& right_renderer, render::Image& scratch,
                                render::Image& into);

}  // namespace app
