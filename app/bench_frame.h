#pragma once
// One end-to-end frame as `patchskin bench` times it: a deformed frame drawn at
// 1280x720 with 2x2 supersampling on one thread, framed by the first frame's
// bounds, and written as a PNG (level 1) to a scratch file that the object
// removes. Shared by the rows that compare a layer's cost with a whole frame
// (bench_auto_layer.cpp, bench_elastic_share.cpp). Cost: one render and one
// PNG encode per Draw.

#include <string>

#include "app/character.h"
#include "deform/pipeline/frame_pipeline.h"
#include "base/error.h"
#include "render/camera.h"
#include "render/output/image_io.h"
#include "render/renderer.h"

namespace app::bench {

class EndToEndFrame {
 public:
  // `first`: the frame whose bounds fix the camera; `tag` names the scratch file.
  EndToEndFrame(const Character& character, const deform::DeformedFrame& first,
                const std::string& tag);
  ~EndToEndFrame();
  EndToEndFrame(const EndToEndFrame&) = delete;
  EndToEndFrame& operator=(const EndToEndFrame&) = delete;

  // Draws `frame` (labelled `number`) and writes it. Errors: the renderer's or the writer's.
  base::Status Draw(const deform::DeformedFrame& frame, int number);

 private:
  const Character& character_;
  render::RenderSettings settings_;
  render::Camera camera_;
  render::Renderer renderer_, unused_;
  render::Image image_, scratch_;
  render::WriteOptions png_;
  std::string path_;
};

}  // namespace app::bench
