#include "render/output/video_writer.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <system_error>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
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
  Srgb8Image encoded;                           // AddFrame(Image)'s conversion, reused
  Srgb8Image fitted;  // a frame of another size cropped or padded to the video's
  cv::Mat bgr;        // OpenCV's input, height x width 8-bit BGR
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
  // An inconsistent frame encodes to an inconsistent one, which the 8-bit
  // AddFrame refuses (after the closed check, as before).
  EncodeSrgb8(frame, &impl_->encoded);
  return AddFrame(impl_->encoded);
}

Status VideoWriter::AddFrame(const Srgb8Image& frame) {
  if (!impl_->is_open()) {
    return MakeError(ErrorCode::kIo, base::InFile(path_), "video is closed");
  }
  if (frame.width < 1 || frame.height < 1 ||
      frame.rgba.size() !=
          4 * static_cast<std::size_t>(frame.width) * static_cast<std::size_t>(frame.height)) {
    return base::InvalidArgument(base::InFile(path_), "expected a frame with pixels, found " +
                                                          std::to_string(frame.width) + "x" +
                                                          std::to_string(frame.height));
  }
  // A frame of another size is cropped (its right and bottom edges) or padded
  // with black: an odd render size gives an even video one pixel smaller.
  const Srgb8Image* fitted = &frame;
  if (frame.width != width_ || frame.height != height_) {
    Srgb8Image& f = impl_->fitted;
    f.width = width_;
    f.height = height_;
    f.rgba.assign(4 * static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_), 0);
    const auto row_bytes = 4 * static_cast<std::size_t>(std::min(width_, frame.width));
    for (int y = 0; y < std::min(height_, frame.height); ++y) {
      std::memcpy(
          &f.rgba[4 * static_cast<std::size_t>(y) * static_cast<std::size_t>(width_)],
          &frame.rgba[4 * static_cast<std::size_t>(y) * static_cast<std::size_t>(frame.width)],
          row_bytes);
    }
    fitted = &f;
  }
  if (impl_->h264 != nullptr) {
    std::string error;
    if (!impl_->h264->Write(fitted->rgba.data(), 4 * width_, &error))
      return MakeError(ErrorCode::kIo, base::InFile(path_), "FFmpeg: " + error);
    ++frames_;
    return Status::Ok();
  }
  try {
    // OpenCV takes BGR; the Mat header borrows the bytes.
    const cv::Mat rgba(height_, width_, CV_8UC4, const_cast<std::uint8_t*>(fitted->rgba.data()));
    cv::cvtColor(rgba, impl_->bgr, cv::COLOR_RGBA2BGR);
    impl_->writer.write(impl_->bgr);
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
