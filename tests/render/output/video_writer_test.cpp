// VideoWriter: what this machine's OpenCV writes, read back with cv::VideoCapture.

#include "render/output/video_writer.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "render/output/image_io.h"
#include "support/data_paths.h"
#include "support/tolerances.h"

namespace render {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 64;
constexpr int kHeight = 48;
constexpr int kFrames = 10;

glm::vec4 Grey(int f) {
  const float v = SrgbToLinear(static_cast<float>(40 + 15 * f) / 255.0f);
  return glm::vec4(v, v, v, 1.0f);
}

// Writes kFrames flat grey frames with `codecs` and checks them read back.
void RoundTrip(const std::vector<VideoCodec>& codecs, VideoCodec expected,
               const std::string& expected_ext) {
  const fs::path dir = testsupport::FreshOutputDir(
      std::string("video/") + VideoCodecName(expected) + "x" + expected_ext.substr(1));
  VideoOptions options;
  options.codecs = codecs;
  auto video = VideoWriter::Open((dir / "preview.mp4").string(), kWidth, kHeight, options);
  ASSERT_TRUE(video.ok()) << video.error().ToString();
  EXPECT_EQ((*video)->codec(), expected);
  EXPECT_EQ(fs::path((*video)->path()).extension(), expected_ext);
  for (int f = 0; f < kFrames; ++f) {
    ASSERT_TRUE((*video)->AddFrame(Image(kWidth, kHeight, Grey(f))));
  }
  EXPECT_FALSE((*video)->AddFrame(Image()).ok());  // no pixels
  ASSERT_TRUE((*video)->Close());
  const std::string path = (*video)->path();
  ASSERT_TRUE(fs::exists(path));
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1u) << "no temporary file left";

  cv::VideoCapture cap(path);
  ASSERT_TRUE(cap.isOpened());
  EXPECT_EQ(cap.get(cv::CAP_PROP_FRAME_WIDTH), kWidth);
  EXPECT_EQ(cap.get(cv::CAP_PROP_FRAME_HEIGHT), kHeight);
  EXPECT_EQ(cap.get(cv::CAP_PROP_FRAME_COUNT), kFrames);
  int read = 0;
  cv::Mat bgr;
  while (cap.read(bgr)) {
    const cv::Scalar mean = cv::mean(bgr);
    EXPECT_NEAR(mean[1], 40 + 15 * read, testsupport::kVideoFlatTol8) << "frame " << read;
    ++read;
  }
  EXPECT_EQ(read, kFrames);
}

TEST(VideoWriter, PrefersH264InMp4) {
  RoundTrip({VideoCodec::kH264Mp4, VideoCodec::kMpeg4Mp4, VideoCodec::kMjpegAvi},
            VideoCodec::kH264Mp4, ".mp4");
}

TEST(VideoWriter, WritesMpeg4InMp4) {
  RoundTrip({VideoCodec::kMpeg4Mp4}, VideoCodec::kMpeg4Mp4, ".mp4");
}

TEST(VideoWriter, MjpegFallbackWritesAvi) {
  RoundTrip({VideoCodec::kMjpegAvi}, VideoCodec::kMjpegAvi, ".avi");
}

// An odd render size (65x49) goes into the even video (64x48) cropped at its
// right and bottom edges: the white last column and row are not in the video.
TEST(VideoWriter, CropsAFrameOnePixelLargerThanTheVideo) {
  const fs::path dir = testsupport::FreshOutputDir("video/odd");
  auto video = VideoWriter::Open((dir / "v.mp4").string(), kWidth, kHeight);
  ASSERT_TRUE(video.ok()) << video.error().ToString();
  Image odd(kWidth + 1, kHeight + 1, Grey(2));
  for (int y = 0; y < odd.height; ++y) odd.at(kWidth, y) = glm::vec4(1.0f);
  for (int x = 0; x < odd.width; ++x) odd.at(x, kHeight) = glm::vec4(1.0f);
  for (int f = 0; f < 3; ++f) ASSERT_TRUE((*video)->AddFrame(odd)) << "frame " << f;
  ASSERT_TRUE((*video)->Close());
  cv::VideoCapture cap((*video)->path());
  ASSERT_TRUE(cap.isOpened());
  EXPECT_EQ(cap.get(cv::CAP_PROP_FRAME_WIDTH), kWidth);
  EXPECT_EQ(cap.get(cv::CAP_PROP_FRAME_HEIGHT), kHeight);
  cv::Mat bgr;
  ASSERT_TRUE(cap.read(bgr));
  EXPECT_NEAR(cv::mean(bgr)[1], 40 + 15 * 2, testsupport::kVideoFlatTol8);
}

// Red, green and blue thirds come back in their places through every codec
// (the encoder takes R, G, B, A bytes; OpenCV's writer B, G, R).
TEST(VideoWriter, KeepsEachColourInItsChannel) {
  for (VideoCodec codec : {VideoCodec::kH264Mp4, VideoCodec::kMpeg4Mp4, VideoCodec::kMjpegAvi}) {
    const fs::path dir = testsupport::FreshOutputDir(std::string("video/rgb") +
                                                     std::to_string(static_cast<int>(codec)));
    VideoOptions options;
    options.codecs = {codec};
    auto video = VideoWriter::Open((dir / "v.mp4").string(), kWidth, kHeight, options);
    ASSERT_TRUE(video.ok()) << video.error().ToString();
    Image frame(kWidth, kHeight);
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        const int third = 3 * x / kWidth;
        frame.at(x, y) = glm::vec4(third == 0, third == 1, third == 2, 1.0f);
      }
    }
    for (int f = 0; f < 3; ++f) ASSERT_TRUE((*video)->AddFrame(frame));
    ASSERT_TRUE((*video)->Close());
    cv::VideoCapture cap((*video)->path());
    ASSERT_TRUE(cap.isOpened());
    cv::Mat bgr;
    ASSERT_TRUE(cap.read(bgr));
    for (int third = 0; third < 3; ++third) {
      // The middle of the third, away from chroma bleeding at the borders.
      const int x = (2 * third + 1) * kWidth / 6;
      const cv::Vec3b p = bgr.at<cv::Vec3b>(kHeight / 2, x);
      const int rgb[3] = {p[2], p[1], p[0]};
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(rgb[c], c == third ? 255 : 0, testsupport::kVideoColourTol8)
            << VideoCodecName(codec) << " third " << third << " channel " << c;
      }
    }
  }
}

// A frame given as its sRGB bytes makes the same video, byte for byte, as the
// linear frame; a smaller frame is padded with black at its right and bottom.
TEST(VideoWriter, EncodedFramesMakeTheSameVideoAndSmallOnesArePadded) {
  const fs::path dir = testsupport::FreshOutputDir("video/encoded");
  auto write = [&](const std::string& name, bool encoded, int w, int h) {
    auto video = VideoWriter::Open((dir / name).string(), kWidth, kHeight);
    EXPECT_TRUE(video.ok());
    if (!video.ok()) return std::string();
    for (int f = 0; f < kFrames; ++f) {
      const Image frame(w, h, Grey(f));
      if (encoded) {
        Srgb8Image bytes;
        EncodeSrgb8(frame, &bytes);
        EXPECT_TRUE((*video)->AddFrame(bytes));
      } else {
        EXPECT_TRUE((*video)->AddFrame(frame));
      }
    }
    EXPECT_TRUE((*video)->Close());
    std::ifstream in((*video)->path(), std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  const std::string linear = write("linear.mp4", false, kWidth, kHeight);
  EXPECT_FALSE(linear.empty());
  EXPECT_EQ(write("encoded.mp4", true, kWidth, kHeight), linear);
  EXPECT_EQ(write("encoded_odd.mp4", true, kWidth + 1, kHeight + 1),
            write("linear_odd.mp4", false, kWidth + 1, kHeight + 1));

  write("small.mp4", true, kWidth / 2, kHeight / 2);
  cv::VideoCapture cap((dir / "small.mp4").string());
  ASSERT_TRUE(cap.isOpened());
  cv::Mat bgr;
  ASSERT_TRUE(cap.read(bgr));
  EXPECT_NEAR(bgr.at<cv::Vec3b>(kHeight / 4, kWidth / 4)[1], 40, testsupport::kVideoFlatTol8);
  EXPECT_NEAR(bgr.at<cv::Vec3b>(3 * kHeight / 4, 3 * kWidth / 4)[1], 0,
              testsupport::kVideoFlatTol8);

  auto video = VideoWriter::Open((dir / "bad.mp4").string(), kWidth, kHeight);
  ASSERT_TRUE(video.ok());
  Srgb8Image wrong;
  wrong.width = 2;
  wrong.height = 2;
  wrong.rgba.assign(15, 0);
  EXPECT_EQ((*video)->AddFrame(wrong).error().code, base::ErrorCode::kInvalidArgument);
}

TEST(VideoWriter, RejectsBadArgumentsAndUnwritablePaths) {
  EXPECT_EQ(VideoWriter::Open("x.mp4", 0, 10).error().code, base::ErrorCode::kInvalidArgument);
  VideoOptions none;
  none.codecs.clear();
  EXPECT_FALSE(VideoWriter::Open("x.mp4", 16, 16, none).ok());
  const fs::path dir = testsupport::FreshOutputDir("video/bad");
  auto r = VideoWriter::Open((dir / "missing" / "v.mp4").string(), 16, 16);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, base::ErrorCode::kIo);
  EXPECT_NE(r.error().ToString().find("v.mp4"), std::string::npos);
}

TEST(VideoWriter, DestroyingWithoutCloseLeavesNothing) {
  const fs::path dir = testsupport::FreshOutputDir("video/abandon");
  {
    auto video = VideoWriter::Open((dir / "v.mp4").string(), kWidth, kHeight);
    ASSERT_TRUE(video.ok());
    ASSERT_TRUE((*video)->AddFrame(Image(kWidth, kHeight, Grey(1))));
  }
  EXPECT_TRUE(fs::is_empty(dir));
}

}  // namespace
}  // namespace render
