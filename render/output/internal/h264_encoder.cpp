#include "render/output/internal/h264_encoder.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/error.h>
#include <libavutil/imgutils.h>
#include <libavutil/log.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

namespace render::internal {
namespace {

std::string AvError(const char* what, int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, text, sizeof(text));
  return std::string(what) + ": " + text;
}

}  // namespace

struct H264Encoder::State {
  AVFormatContext* format = nullptr;
  AVCodecContext* codec = nullptr;
  AVStream* stream = nullptr;
  AVFrame* frame = nullptr;
  AVPacket* packet = nullptr;
  SwsContext* sws = nullptr;
  bool header_written = false;
  std::int64_t next_pts = 0;

  ~State() {
    sws_freeContext(sws);
    av_packet_free(&packet);
    av_frame_free(&frame);
    avcodec_free_context(&codec);
    if (format != nullptr) {
      if (format->pb != nullptr) avio_closep(&format->pb);
      avformat_free_context(format);
    }
  }

  // Sends `f` (nullptr: flush) and writes every packet the encoder returns.
  int Drain(const AVFrame* f) {
    int rc = avcodec_send_frame(codec, f);
    if (rc < 0) return rc;
    for (;;) {
      rc = avcodec_receive_packet(codec, packet);
      if (rc == AVERROR(EAGAIN) || rc == AVERROR_EOF) return 0;
      if (rc < 0) return rc;
      // Every frame lasts one tick of the codec's 1/fps clock; without it the
      // muxer gives the last frame no duration and readers drop it.
      packet->duration = 1;
      av_packet_rescale_ts(packet, codec->time_base, stream->time_base);
      packet->stream_index = stream->index;
      rc = av_interleaved_write_frame(format, packet);
      if (rc < 0) return rc;
    }
  }
};

std::unique_ptr<H264Encoder> H264Encoder::Open(const std::string& path, int width, int height,
                                               double fps, const char* preset, std::string* error) {
  // x264 reports its statistics at info level on stderr; a render's output
  // is ours. (FFmpeg's log level is process-wide; OpenCV sets it the same way.)
  av_log_set_level(AV_LOG_ERROR);
  std::unique_ptr<H264Encoder> e(new H264Encoder());
  e->s_ = std::make_unique<State>();
  State& s = *e->s_;
  int rc = avformat_alloc_output_context2(&s.format, nullptr, nullptr, path.c_str());
  if (rc < 0 || s.format == nullptr) {
    *error = AvError("no container for this file name", rc);
    return nullptr;
  }
  const AVCodec* codec = avcodec_find_encoder_by_name("libx264");
  if (codec == nullptr) {
    *error = "FFmpeg has no libx264 encoder";
    return nullptr;
  }
  s.stream = avformat_new_stream(s.format, nullptr);
  s.codec = avcodec_alloc_context3(codec);
  s.frame = av_frame_alloc();
  s.packet = av_packet_alloc();
  if (s.stream == nullptr || s.codec == nullptr || s.frame == nullptr || s.packet == nullptr) {
    *error = "out of memory";
    return nullptr;
  }
  // A rational close to fps: 1/1000 s ticks are plenty for a preview.
  const AVRational rate = av_d2q(fps, 100000);
  s.codec->width = width;
  s.codec->height = height;
  s.codec->pix_fmt = AV_PIX_FMT_YUV420P;
  s.codec->time_base = av_inv_q(rate);
  s.codec->framerate = rate;
  s.codec->thread_count = 1;  // bytes independent of the machine; the render has the cores
  // No B-frames: their negative decode times need an MP4 edit list, which
  // OpenCV's reader (and some players) answer by dropping a frame.
  s.codec->max_b_frames = 0;
  if ((s.format->oformat->flags & AVFMT_GLOBALHEADER) != 0)
    s.codec->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  av_opt_set(s.codec->priv_data, "preset", preset, 0);
  av_opt_set(s.codec->priv_data, "crf", "23", 0);
  rc = avcodec_open2(s.codec, codec, nullptr);
  if (rc < 0) {
    *error = AvError("cannot open libx264", rc);
    return nullptr;
  }
  rc = avcodec_parameters_from_context(s.stream->codecpar, s.codec);
  if (rc >= 0) s.stream->time_base = s.codec->time_base;
  if (rc >= 0) rc = avio_open(&s.format->pb, path.c_str(), AVIO_FLAG_WRITE);
  // No encoder or muxer version strings in the file: same bytes from every build.
  if (rc >= 0) s.format->flags |= AVFMT_FLAG_BITEXACT;
  if (rc >= 0) rc = avformat_write_header(s.format, nullptr);
  if (rc < 0) {
    *error = AvError("cannot start the video file", rc);
    return nullptr;
  }
  s.header_written = true;
  s.frame->format = AV_PIX_FMT_YUV420P;
  s.frame->width = width;
  s.frame->height = height;
  rc = av_frame_get_buffer(s.frame, 0);
  s.sws = sws_getContext(width, height, AV_PIX_FMT_RGBA, width, height, AV_PIX_FMT_YUV420P,
                         SWS_BILINEAR, nullptr, nullptr, nullptr);
  if (rc < 0 || s.sws == nullptr) {
    *error = "cannot allocate the frame converter";
    return nullptr;
  }
  return e;
}

H264Encoder::~H264Encoder() = default;

bool H264Encoder::Write(const std::uint8_t* rgba, int stride, std::string* error) {
  State& s = *s_;
  int rc = av_frame_make_writable(s.frame);
  if (rc >= 0) {
    const std::uint8_t* const src[1] = {rgba};
    const int src_stride[1] = {stride};
    sws_scale(s.sws, src, src_stride, 0, s.codec->height, s.frame->data, s.frame->linesize);
    s.frame->pts = s.next_pts++;
    rc = s.Drain(s.frame);
  }
  if (rc < 0) {
    *error = AvError("cannot encode a frame", rc);
    return false;
  }
  return true;
}

bool H264Encoder::Close(std::string* error) {
  State& s = *s_;
  int rc = s.Drain(nullptr);
  if (rc >= 0) rc = av_write_trailer(s.format);
  if (rc >= 0 && s.format->pb != nullptr) rc = avio_closep(&s.format->pb);
  if (rc < 0) {
    *error = AvError("cannot finish the video file", rc);
    return false;
  }
  return true;
}

}  // namespace render::internal
