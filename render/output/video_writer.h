#pragma once
// Preview video (OpenCV and FFmpeg stay in the .cpp files).
// Tries, in order, H.264 in MP4 ("avc1"), MPEG-4 Part 2 in MP4 ("mp4v") and Motion
// JPEG in AVI ("MJPG"), whichever this machine's OpenCV/FFmpeg can encode, and
// says which one it used. The MJPEG fallback replaces the path's extension by .avi.
// Debian 12's OpenCV 4.6 with FFmpeg 5.1 writes all three. H.264 at an even size
// goes through libavcodec directly with x264's "veryfast" preset on one thread
// (internal/h264_encoder.h): OpenCV cannot set a preset, and its default one made
// the preview the slowest output of a render. OpenCV's avc1 is its fallback.
//
// Like frames, the video is written under a temporary name in the same folder
// and renamed on Close(), so a half-written video never has the final name.
// Frames are linear RGBA, sRGB-encoded to 8 bits (alpha dropped), or arrive
// encoded (Srgb8Image).

#include <memory>
#include <string>
#include <vector>

#include "base/error.h"
#include "render/image.h"

namespace render {

using base::Result;
using base::Status;

enum class VideoCodec {
  kH264Mp4,   // "avc1" in .mp4
  kMpeg4Mp4,  // "mp4v" in .mp4
  kMjpegAvi,  // "MJPG" in .avi
};

// "mp4/avc1", "mp4/mp4v", "avi/MJPG".
const char* VideoCodecName(VideoCodec codec);

struct VideoOptions {
  double fps = 24.0;  // frames per second, > 0
  // Codecs to try, in order; the first that opens is used.
  std::vector<VideoCodec> codecs = {VideoCodec::kH264Mp4, VideoCodec::kMpeg4Mp4,
                                    VideoCodec::kMjpegAvi};
};

class VideoWriter {
 public:
  // Opens a video of width x height pixels (even sizes are safest for H.264).
  // `path` should end in .mp4; with the MJPEG fallback the file is <stem>.avi.
  // Errors: kInvalidArgument (size, fps, empty codec list), kIo (no such folder),
  // kUnsupported (no codec
  // could be opened; the message lists those tried).
  [[nodiscard]] static Result<std::unique_ptr<VideoWriter>> Open(const std::string& path,
                                                                 int width, int height,
                                                                 const VideoOptions& options = {});
  ~VideoWriter();  // closes without renaming if Close() was not called: the temp file is removed

  // Appends one frame. A frame of another size is cropped at its right and
  // bottom edges or padded there with black (an odd render size in an even
  // video). Errors: kInvalidArgument (an empty frame), kIo.
  [[nodiscard]] Status AddFrame(const Image& frame);
  // The same frame already sRGB-encoded (EncodeSrgb8): the same video bytes
  // as AddFrame(frame), without converting it again.
  [[nodiscard]] Status AddFrame(const Srgb8Image& frame);
  // Finishes the file and renames it to path(). Errors: kIo.
  [[nodiscard]] Status Close();

  VideoCodec codec() const { return codec_; }
  const std::string& path() const { return path_; }  // final path (.mp4 or .avi)
  int frames_written() const { return frames_; }

 private:
  struct Impl;
  VideoWriter() = default;
  std::unique_ptr<Impl> impl_;
  VideoCodec codec_ = VideoCodec::kMjpegAvi;
  std::string path_;
  std::string temp_path_;
  int width_ = 0;
  int height_ = 0;
  int frames_ = 0;
};

}  // namespace render
