#pragma once
// H.264 in MP4 through Debian's libavcodec/libavformat directly (FFmpeg
// stays in h264_encoder.cpp). OpenCV 4.6's VideoWriter cannot choose an x264
// preset, and its default ("medium", with trellis quantisation) made the
// preview the slowest output of a render; a real-time preset is about 5x
// faster for a file the same size to within tens of percent (a preview).
//
// One encoder thread, so the stream's bytes are a function of the frames
// alone, and the render keeps the cores. Frames are 8-bit sRGB RGBA (alpha
// ignored), width x height (both even), converted to YUV 4:2:0 with libswscale.

#include <cstdint>
#include <memory>
#include <string>

namespace render::internal {

class H264Encoder {
 public:
  // Opens `path` (container from its extension, .mp4) for width x height
  // frames at `fps`, x264 `preset` (e.g. "veryfast"). On failure returns
  // nullptr and sets *error (FFmpeg's message); nothing is left open.
  static std::unique_ptr<H264Encoder> Open(const std::string& path, int width, int height,
                                           double fps, const char* preset, std::string* error);
  ~H264Encoder();  // frees everything; the file is left as written so far

  // Encodes one frame of height rows of 4 * width bytes (R, G, B, A), rows
  // `stride` bytes apart. False (with *error) on an encoder or write failure.
  bool Write(const std::uint8_t* rgba, int stride, std::string* error);
  // Flushes the encoder and writes the MP4 index. False (with *error) on failure.
  bool Close(std::string* error);

 private:
  struct State;
  H264Encoder() = default;
  std::unique_ptr<State> s_;
};

}  // namespace render::internal
