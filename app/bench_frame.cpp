#include "app/bench_frame.h"

#include <unistd.h>

#include <filesystem>

#include "app/frame_render.h"

namespace app::bench {

EndToEndFrame::EndToEndFrame(const Character& character, const deform::DeformedFrame& first,
                             const std::string& tag)
    : character_(character),
      camera_(
          render::FrameBounds(first.bounds, 35.0f, 1280.0f / 720.0f, glm::vec3(0.0f, 0.0f, -1.0f))),
      path_((std::filesystem::temp_directory_path() /
             ("patchskin_bench_" + tag + "_" + std::to_string(getpid()) + ".png"))
                .string()) {
  settings_.width = 1280;
  settings_.height = 720;
  settings_.supersample = 2;
  settings_.threads = 1;
  png_.png_compression = 1;
}

EndToEndFrame::~EndToEndFrame() {
  std::error_code ec;
  std::filesystem::remove(path_, ec);
}

base::Status EndToEndFrame::Draw(const deform::DeformedFrame& frame, int number) {
  FrameDrawOptions draw;
  draw.frame_number = number;
  base::Status s = DrawCharacterFrame(character_, frame, nullptr, camera_, settings_, draw,
                                      renderer_, unused_, scratch_, image_);
  if (!s.ok()) return s;
  return render::WriteImage(image_, path_, png_);
}

}  // namespace app::bench
