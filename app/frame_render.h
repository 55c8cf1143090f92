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
  int frame_number = 0;      // printed at the bottom left (a turntable's motion frame)
  int view = -1;             // a turntable's view (0-based), printed after it; -1 none
  std::string left_label;    // split view: method names printed at the top of each half
  std::string right_label;
};

// Renders `frame` (and, when `right` is set, the right half from `right`, with a
// divider) into `into` (settings.width x settings.height). `right_renderer` and
// `scratch` are only used for the split view. Errors: kInternal when the renderer
// refuses the frame.
mocap::Status DrawCharacterFrame(const Character& character, const DeformedFrame& frame,
                                 const DeformedFrame* right, const render::Camera& camera,
                                 const render::RenderSettings& settings,
                                 const FrameDrawOptions& options, render::Renderer& renderer,
                                 render::Renderer& right_renderer, render::Image& scratch,
                                 render::Image& into);

}  // namespace app
