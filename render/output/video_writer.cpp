#include "render/output/video_writer.h"

#include <algorithm>
#include <filesystem>
#include <limits>
#include <system_error>

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "render/output/image_io.h"
#include "render/output/internal/h264_encoder.h"

namespace render {
namespace {

using base::ErrorCode;
using base::FileLoc;
using base::MakeError;

struct CodecInfo {
  const char* fourcc;
  const char* extension;
};

CodecInfo Info(VideoCodec codec) {
  switch (codec) {
    case VideoCodec::kH264Mp4: return {"avc1", ".mp4"};
    case VideoCodec::kMpeg4Mp4: return {"mp4v", ".mp4"};
    case VideoCodec::kMjpegAvi: return {"MJPG", ".avi"};
  }
  return {"MJPG", ".avi"};
}

}  // namespace

// x264's preset for the H.264 preview: real time on one core at 1280x720.
constexpr const char* kX264Preset = "veryfast";

struct VideoWriter::Impl {
  std::unique_ptr<internal::H264Encoder> h264;  // H.264 through libavcodec, or
  cv::VideoWriter writer;                       // any codec through OpenCV
  cv::Mat bgr;  // reused conversion buffer, height x width 8-bit BGR
  bool is_open() const { return h264 != nullptr || writer.isOpened(); }
};

const char* VideoCodecName(VideoCodec codec) {
  switch (codec) {
    case VideoCodec::kH264Mp4: return "mp4/avc1";
    case VideoCodec::kMpeg4Mp4: return "mp4/mp4v";
    case VideoCodec::kMjpegAvi: return "avi/MJPG";
  }
  return "?";
}

Result<std::unique_ptr<VideoWriter>> VideoWriter::Open(const std::string& path, int width,
                                                       int height, const VideoOptions& options) {
  const FileLoc loc = base::InFile(path);
  if (width <= 0 || height <= 0 || !(options.fps > 0.0)) {
    return base::InvalidArgument(loc, "expected a positive size and fps");
  }
  if (options.codecs.empty()) {
    return base::InvalidArgument(loc, "expected at least one codec to try");
  }
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty() && !std::filesystem::is_directory(parent)) {
    return MakeError(ErrorCode::kIo, loc, "the output folder does not exist");
  }
  std::unique_ptr<VideoWriter> w(new VideoWriter());
  w->impl_ = std::make_unique<Impl>();
  w->width_ = width;
  w->height_ = height;
  std::string tried;
  for (VideoCodec codec : options.codecs) {
    const CodecInfo info = Info(codec);
    std::filesystem::path final_path(path);
    final_path.replace_extension(info.extension);
    // OpenCV picks the container from the extension, so the temporary name keeps it.
    const std::filesystem::path temp = TemporaryPathFor(final_path.string(), info.extension);
    bool opened = false;
    std::string libav_error;
    // H.264 with a real-time preset through libavcodec first (an odd size
    // cannot be 4:2:0: OpenCV then decides), else through OpenCV.
    if (codec == VideoCodec::kH264Mp4 && width % 2 == 0 && height % 2 == 0) {
      w->impl_->h264 = internal::H264Encoder::Open(temp.string(), width, height, options.fps,
                                                   kX264Preset, &libav_error);
      opened = w->impl_->h264 != nullptr;
    }
    if (!opened) try {
      const int fourcc =
          cv::VideoWriter::fourcc(info.fourcc[0], info.fourcc[1], info.fourcc[2], info.fourcc[3]);
      opened = w->impl_->writer.open(temp.string(), cv::CAP_FFMPEG, fourcc, options.fps,
                                     cv::Size(width, height), true);
    } catch (const cv::Exception&) {
      opened = false;
    }
    if (opened) {
      w->codec_ = codec;
      w->path_ = final_path.string();
      w->temp_path_ = temp.string();
      return w;
    }
    std::error_code ec;
    std::filesystem::remove(temp, ec);
    tried += std::string(tried.empty() ? "" : ", ") + VideoCodecName(codec);
  }
  return MakeError(ErrorCode::kUnsupported, loc,
                   "OpenCV could not open a video writer with any of: " + tried);
}

VideoWriter::~VideoWriter() {
  if (impl_ && impl_->is_open()) {
    impl_->h264.reset();
    impl_->writer.release();
    std::error_code ec;
    std::filesystem::remove(temp_path_, ec);
  }
}

Status VideoWriter::AddFrame(const Image& frame) {
  if (!impl_->is_open()) {
    return MakeError(ErrorCode::kIo, base::InFile(path_), "video is closed");
  }
  if (frame.width < 1 || frame.height < 1 ||
      frame.rgba.size() != static_cast<std::size_t>(frame.width) * static_cast<std::size_t>(frame.height)) {
    return base::InvalidArgument(base::InFile(path_), "expected a frame with pixels, found " +
                                                          std::to_string(frame.width) + "x" +
                                                          std::to_string(frame.height));
  }
  // A frame of another size is cropped (its right and bottom edges) or padded
  // with black: an odd render size gives an even video one pixel smaller.
  cv::Mat& bgr = impl_->bgr;
  bgr.create(height_, width_, CV_8UC3);
  bgr.setTo(cv::Scalar(0, 0, 0));
  const int w = std::min(width_, frame.width);
  const int h = std::min(height_, frame.height);
  for (int y = 0; y < h; ++y) {
    auto* row = bgr.ptr<std::uint8_t>(y);
    // Runs of equal pixels (background rows) reuse the previous pixel's
    // bytes; NaN never compares equal, so it is always converted.
    glm::vec3 last(std::numeric_limits<float>::quiet_NaN());
    std::uint8_t b = 0, g = 0, r = 0;
    for (int x = 0; x < w; ++x) {
      const glm::vec3 p(frame.at(x, y));
      if (!(p == last)) {
        b = LinearToSrgb8(p.b);  // OpenCV stores BGR
        g = LinearToSrgb8(p.g);
        r = LinearToSrgb8(p.r);
        last = p;
      }
      row[3 * x + 0] = b;
      row[3 * x + 1] = g;
      row[3 * x + 2] = r;
    }
  }
  if (impl_->h264 != nullptr) {
    std::string error;
    if (!impl_->h264->Write(bgr.ptr<std::uint8_t>(0), static_cast<int>(bgr.step[0]), &error))
      return MakeError(ErrorCode::kIo, base::InFile(path_), "FFmpeg: " + error);
    ++frames_;
    return Status::Ok();
  }
  try {
    impl_->writer.write(bgr);
  } catch (const cv::Exception& e) {
    return MakeError(ErrorCode::kIo, base::InFile(path_), std::string("OpenCV: ") + e.what());
  }
  ++frames_;
  return Status::Ok();
}

Status VideoWriter::Close() {
  if (!impl_->is_open()) {
    return MakeError(ErrorCode::kIo, base::InFile(path_), "video is already closed");
  }
  if (impl_->h264 != nullptr) {
    std::string error;
    const bool closed = impl_->h264->Close(&error);
    impl_->h264.reset();
    if (!closed) {
      std::error_code ignored;
      std::filesystem::remove(temp_path_, ignored);
      return MakeError(ErrorCode::kIo, base::InFile(path_), "FFmpeg: " + error);
    }
  }
  impl_->writer.release();
  std::error_code ec;
  std::filesystem::rename(temp_path_, path_, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(temp_path_, ignored);
    return MakeError(ErrorCode::kIo, base::InFile(path_),
                     "cannot rename the finished video into place: " + ec.message());
  }
  return Status::Ok();
}

}  // namespace render
