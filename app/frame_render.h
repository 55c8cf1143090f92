#pragma once
// Drawing one evaluated frame of a character (or a split view of two), shared by
// `patchskin render` and the golden-image tests so both go through the same
// FramePipeline -> render::Renderer path.

#include <string>

#include "app/pipeline.h"
#include "mocap/error.h"
#include "render/camera.h"
#include "render/image.h"
#include "render/renderer.h"

namespace app {

struct FrameDrawOptions {
  bool skeleton = false;     // overlay the skeleton (bones and joints, no depth test)
  bool wireframe = false;    // overlay the mesh edges
  int frame_number = 0;      // printed at the bottom left
  std::string left_label;    // two bodies: what each shows, printed at the top of each half
  std::string right_label;
  // Two bodies: true = side by side (each whole body in its own half-width
  // viewport; `camera` must be made for that half's aspect), false = a wipe
  // (both rendered full width from `camera`, the right half of `right` copied
  // over the left one's).
  bool side_by_side = false;
};

// Renders `frame` into `into` (settings.width x settings.height), or, when
// `right` is set, `frame` and `right` side by side or as a wipe, with a
// divider. `right_renderer` and `scratch` are only used for two bodies.
// Errors: kInternal when the renderer refuses the frame.
mocap::Status DrawCharacterFrame(const Character& character, const DeformedFrame& frame,
                                 const DeformedFrame* right, const render::Camera& camera,
                                 const render::RenderSettings& settings,
                                 const FrameDrawOptions& options, render::Renderer& renderer,
                                 render::Renderer& right_renderer, render::Image& scratch,
                                 render::Image& into);

}  // namespace app
