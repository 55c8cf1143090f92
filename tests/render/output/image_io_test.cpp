// Image files: sRGB conversion, round trips per format, atomic writes, frame patterns.

#include "render/output/image_io.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>

#include <OpenImageIO/imageio.h>

#include <gtest/gtest.h>

#include "support/data_paths.h"
#include "support/run_process.h"
#include "support/tolerances.h"

namespace render {
namespace {

namespace fs = std::filesystem;
using testsupport::kFloatTol;

// Every pixel different: colour ramps, a hue pattern and partial alpha.
Image TestPattern(int w, int h) {
  Image img(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      img.at(x, y) = glm::vec4(static_cast<float>(x) / static_cast<float>(w - 1),
                               static_cast<float>(y) / static_cast<float>(h - 1),
                               0.5f + 0.5f * std::sin(0.7f * static_cast<float>(x + 3 * y)),
                               static_cast<float>((x + y) % 5) / 4.0f);
    }
  }
  return img;
}

std::size_t CountEntries(const fs::path& dir) {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
  return n;
}

TEST(Srgb, MatchesTheStandardCurveAtKnownPoints) {
  // Values from the IEC 61966-2-1 formulas, computed by hand.
  EXPECT_NEAR(LinearToSrgb(0.5f), 0.735356983f, kFloatTol);
  EXPECT_NEAR(LinearToSrgb(0.18f), 0.461356129f, kFloatTol);
  EXPECT_NEAR(LinearToSrgb(0.002f), 0.02584f, kFloatTol);  // linear segment: 12.92 * x
  EXPECT_NEAR(SrgbToLinear(0.5f), 0.214041140f, kFloatTol);
  EXPECT_NEAR(SrgbToLinear(0.04f), 0.04f / 12.92f, kFloatTol);
  EXPECT_EQ(LinearToSrgb(-1.0f), 0.0f);
  EXPECT_EQ(LinearToSrgb(2.0f), 1.0f);
  EXPECT_EQ(LinearToSrgb(NAN), 0.0f);
  EXPECT_EQ(LinearToSrgb8(0.5f), 188);  // round(255 * 0.735357) = 188
  EXPECT_EQ(LinearToSrgb8(NAN), 0);
  EXPECT_EQ(LinearToSrgb8(7.0f), 255);
}

TEST(Srgb, EightBitRoundTripIsExactForEveryCode) {
  for (int c = 0; c < 256; ++c) {
    const auto code = static_cast<std::uint8_t>(c);
    EXPECT_EQ(LinearToSrgb8(Srgb8ToLinear(code)), code) << "code " << c;
    EXPECT_NEAR(Srgb8ToLinear(code), SrgbToLinear(static_cast<float>(c) / 255.0f), kFloatTol);
  }
}

TEST(Srgb, EightBitEncodingPicksTheNearestCode) {
  // Independent computation: the rounded curve, except right at a decision
  // boundary where float round-off in pow may fall on either side.
  for (int i = 0; i <= 100000; ++i) {
    const float x = static_cast<float>(i) / 100000.0f;
    const float exact = 255.0f * LinearToSrgb(x);
    const int code = LinearToSrgb8(x);
    EXPECT_LE(std::fabs(static_cast<float>(code) - exact), 0.5f + 1e-3f) << "x=" << x;
  }
}

TEST(ImageFormat, FollowsTheExtension) {
  EXPECT_EQ(*ImageFormatFromPath("a/f_0001.PNG"), ImageFormat::kPng);
  EXPECT_EQ(*ImageFormatFromPath("f.exr"), ImageFormat::kExr);
  EXPECT_EQ(*ImageFormatFromPath("f.tiff"), ImageFormat::kTiff);
  EXPECT_EQ(*ImageFormatFromPath("f.jpeg"), ImageFormat::kJpeg);
  const auto bad = ImageFormatFromPath("f.bmp");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code, base::ErrorCode::kUnsupported);
  EXPECT_NE(bad.error().message.find(".bmp"), std::string::npos);
}

TEST(WriteImage, PngRoundTripIsExactAfterQuantization) {
  const fs::path dir = testsupport::FreshOutputDir("image_io/png");
  const Image src = TestPattern(37, 23);
  ASSERT_TRUE(WriteImage(src, (dir / "a.png").string()));
  ReadInfo info;
  auto back = ReadImage((dir / "a.png").string(), &info);
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  EXPECT_TRUE(info.srgb_encoded);
  EXPECT_EQ(info.bits, 8);
  EXPECT_EQ(info.channels, 4);
  ASSERT_EQ(back->width, 37);
  ASSERT_EQ(back->height, 23);
  for (std::size_t i = 0; i < src.rgba.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      ASSERT_EQ(back->rgba[i][c], Srgb8ToLinear(LinearToSrgb8(src.rgba[i][c]))) << i;
    }
    ASSERT_EQ(back->rgba[i].a, std::round(src.rgba[i].a * 255.0f) / 255.0f) << i;
  }
}

// EncodeSrgb8 against the one-value conversions, and DecodeSrgb8 against
// what ReadImage gives for the file WriteImage writes of the same frame.
TEST(Srgb8Image, EncodesLikeTheFileAndDecodesLikeTheReadBack) {
  const fs::path dir = testsupport::FreshOutputDir("image_io/srgb8");
  Image src = TestPattern(29, 17);
  src.at(3, 4) = glm::vec4(std::nanf(""), -1.0f, 2.0f, std::nanf(""));
  src.at(5, 6).a = 0.7f;
  Srgb8Image bytes;
  bytes.rgba.assign(7, 99);  // stale contents are replaced
  EncodeSrgb8(src, &bytes);
  ASSERT_EQ(bytes.width, 29);
  ASSERT_EQ(bytes.height, 17);
  ASSERT_EQ(bytes.rgba.size(), 4u * 29u * 17u);
  for (std::size_t i = 0; i < src.rgba.size(); ++i) {
    for (int c = 0; c < 3; ++c)
      ASSERT_EQ(bytes.rgba[4 * i + c], LinearToSrgb8(src.rgba[i][c])) << i;
    const float a = std::isnan(src.rgba[i].a) ? 0.0f : std::clamp(src.rgba[i].a, 0.0f, 1.0f);
    ASSERT_EQ(bytes.rgba[4 * i + 3], static_cast<std::uint8_t>(std::lround(a * 255.0f))) << i;
  }
  ASSERT_TRUE(WriteImage(src, (dir / "a.png").string()));
  const Result<Image> back = ReadImage((dir / "a.png").string());
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  const Image decoded = DecodeSrgb8(bytes);
  ASSERT_EQ(decoded.rgba.size(), back->rgba.size());
  for (std::size_t i = 0; i < decoded.rgba.size(); ++i) {
    for (int c = 0; c < 4; ++c) ASSERT_EQ(decoded.rgba[i][c], back->rgba[i][c]) << i << " " << c;
  }
}

// A frame encoded once writes the files the linear frame writes, byte for byte.
TEST(WriteImage, EncodedFrameWritesTheSameBytesAsTheLinearOne) {
  const fs::path dir = testsupport::FreshOutputDir("image_io/encoded");
  const Image src = TestPattern(41, 19);
  Srgb8Image bytes;
  EncodeSrgb8(src, &bytes);
  WriteOptions o;
  o.frame = 12;
  o.source_file = "walk.bvh";
  auto file = [](const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  for (const std::string ext : {"png", "tif", "jpg"}) {
    const fs::path linear = dir / ("linear." + ext), encoded = dir / ("encoded." + ext);
    ASSERT_TRUE(WriteImage(src, linear.string(), o)) << ext;
    const Status s = WriteImage(bytes, encoded.string(), o);
    ASSERT_TRUE(s) << ext << ": " << s.error().ToString();
    EXPECT_EQ(file(linear), file(encoded)) << ext;
  }
  // Linear formats need the linear values; a buffer of the wrong size is refused.
  const Status exr = WriteImage(bytes, (dir / "a.exr").string());
  ASSERT_FALSE(exr);
  EXPECT_NE(exr.error().message.find("EXR"), std::string::npos) << exr.error().ToString();
  WriteOptions sixteen;
  sixteen.tiff_bits = 16;
  EXPECT_FALSE(WriteImage(bytes, (dir / "b.tif").string(), sixteen));
  Srgb8Image short_buffer = bytes;
  short_buffer.rgba.pop_back();
  const Status bad = WriteImage(short_buffer, (dir / "c.png").string());
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, base::ErrorCode::kInvalidArgument);
  EXPECT_FALSE(WriteImage(Srgb8Image{}, (dir / "d.png").string()));
  EXPECT_FALSE(fs::exists(dir / "a.exr") || fs::exists(dir / "c.png") || fs::exists(dir / "d.png"));
}

TEST(WriteImage, PngCompressionLevelChangesSizeNotPixels) {
  const fs::path dir = testsupport::FreshOutputDir("image_io/png_levels");
  const Image src = TestPattern(64, 64);
  WriteOptions fast;
  fast.png_compression = 0;
  WriteOptions small;
  small.png_compression = 9;
  ASSERT_TRUE(WriteImage(src, (dir / "fast.png").string(), fast));
  ASSERT_TRUE(WriteImage(src, (dir / "small.png").string(), small));
  EXPECT_GT(fs::file_size(dir / "fast.png"), fs::file_size(dir / "small.png"));
  auto a = ReadImage((dir / "fast.png").string());
  auto b = ReadImage((dir / "small.png").string());
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->rgba, b->rgba);
}

TEST(WriteImage, PngFilterChangesBytesNotPixels) {
  const fs::path dir = testsupport::FreshOutputDir("image_io/png_filters");
  const Image src = TestPattern(64, 64);
  WriteOptions none, adaptive;
  none.png_filter = PngFilter::kNone;
  adaptive.png_filter = PngFilter::kAdaptive;
  ASSERT_TRUE(WriteImage(src, (dir / "none.png").string(), none));
  ASSERT_TRUE(WriteImage(src, (dir / "adaptive.png").string(), adaptive));
  EXPECT_NE(fs::file_size(dir / "none.png"), fs::file_size(dir / "adaptive.png"));
  auto a = ReadImage((dir / "none.png").string());
  auto b = ReadImage((dir / "adaptive.png").string());
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->rgba, b->rgba);
}

TEST(WriteImage, ExrKeepsHalfPrecisionAndDepth) {
  const fs::path dir = testsupport::FreshOutputDir("image_io/exr");
  Image src = TestPattern(16, 8);
  src.at(3, 2) = glm::vec4(12.5f, 0.001f, 100.0f, 1.0f);  // HDR values survive
  src.depth.resize(src.rgba.size());
  for (std::size_t i = 0; i < src.depth.size(); ++i) src.depth[i] = 1.0f + 0.123457f * float(i);
  ASSERT_TRUE(WriteImage(src, (dir / "a.exr").string()));
  ReadInfo info;
  auto back = ReadImage((dir / "a.exr").string(), &info);
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  EXPECT_FALSE(info.srgb_encoded);
  EXPECT_EQ(info.channels, 5);
  ASSERT_EQ(back->depth.size(), src.depth.size());
  for (std::size_t i = 0; i < src.rgba.size(); ++i) {
    for (int c = 0; c < 4; ++c) {
      // Half has an 11-bit significand: relative error <= 2^-11.
      const float v = src.rgba[i][c];
      ASSERT_NEAR(back->rgba[i][c], v, std::fabs(v) * testsupport::kHalfRelTol + testsupport::kHalfAbsTol) << i << " " << c;
    }
    ASSERT_EQ(back->depth[i], src.depth[i]) << "depth is stored as float";
  }
}

// Same image, same bytes, whenever it is written: the EXR and TIFF writers
// would otherwise stamp the current time (the writes are a second apart).
TEST(WriteImage, SameImageGivesSameBytesAcrossTime) {
  const fs::path dir = testsupport::FreshOutputDir("image_io/same_bytes");
  const Image src = TestPattern(16, 8);
  for (const char* ext : {".exr", ".tif", ".png"}) {
    const std::string a = (dir / (std::string("a") + ext)).string();
    const std::string b = (dir / (std::string("b") + ext)).string();
    ASSERT_TRUE(WriteImage(src, a));
    std::this_thread::sleep_for(std::chrono::milliseconds(1100));
    ASSERT_TRUE(WriteImage(src, b));
    EXPECT_EQ(testsupport::SlurpFile(a), testsupport::SlurpFile(b)) << ext;
  }
}

TEST(WriteImage, ExrWithoutDepthHasFourChannels) {
  const fs::path dir = testsupport::FreshOutputDir("image_io/exr_nodepth");
  Image src = TestPattern(8, 8);
  src.depth.assign(src.rgba.size(), 2.0f);
  WriteOptions o;
  o.exr_write_depth = false;
  o.exr_compression = "none";
  ASSERT_TRUE(WriteImage(src, (dir / "a.exr").string(), o));
  ReadInfo info;
  auto back = ReadImage((dir / "a.exr").string(), &info);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(info.channels, 4);
  EXPECT_TRUE(back->depth.empty());
}

TEST(WriteImage, TiffEightAndSixteenBitRoundTrip) {
  const fs::path dir = testsupport::FreshOutputDir("image_io/tiff");
  const Image src = TestPattern(20, 10);
  ASSERT_TRUE(WriteImage(src, (dir / "a8.tif").string()));
  WriteOptions o16;
  o16.tiff_bits = 16;
  ASSERT_TRUE(WriteImage(src, (dir / "a16.tiff").string(), o16));
  ReadInfo info8, info16;
  auto b8 = ReadImage((dir / "a8.tif").string(), &info8);
  auto b16 = ReadImage((dir / "a16.tiff").string(), &info16);
  ASSERT_TRUE(b8.ok() && b16.ok());
  EXPECT_EQ(info8.bits, 8);
  EXPECT_EQ(info16.bits, 16);
  for (std::size_t i = 0; i < src.rgba.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      ASSERT_EQ(b8->rgba[i][c], Srgb8ToLinear(LinearToSrgb8(src.rgba[i][c])));
      // 16 bits: one code step in encoded space is 1/65535.
      ASSERT_NEAR(LinearToSrgb(b16->rgba[i][c]), LinearToSrgb(src.rgba[i][c]),
                  testsupport::kUint16Step);
    }
  }
}

TEST(WriteImage, JpegIsCloseAndQualityMatters) {
  const fs::path dir = testsupport::FreshOutputDir("image_io/jpeg");
  Image src(32, 32, glm::vec4(0.2f, 0.4f, 0.6f, 1.0f));  // flat colour: JPEG keeps it well
  WriteOptions hi, lo;
  hi.jpeg_quality = 95;
  lo.jpeg_quality = 10;
  const Image pattern = TestPattern(64, 64);
  ASSERT_TRUE(WriteImage(src, (dir / "flat.jpg").string(), hi));
  ASSERT_TRUE(WriteImage(pattern, (dir / "hi.jpg").string(), hi));
  ASSERT_TRUE(WriteImage(pattern, (dir / "lo.jpg").string(), lo));
  EXPECT_GT(fs::file_size(dir / "hi.jpg"), fs::file_size(dir / "lo.jpg"));
  ReadInfo info;
  auto back = ReadImage((dir / "flat.jpg").string(), &info);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(info.channels, 3);
  const glm::vec4 p = back->at(16, 16);
  EXPECT_NEAR(LinearToSrgb(p.r), LinearToSrgb(0.2f), testsupport::kJpegFlatTol);
  EXPECT_NEAR(LinearToSrgb(p.g), LinearToSrgb(0.4f), testsupport::kJpegFlatTol);
  EXPECT_NEAR(LinearToSrgb(p.b), LinearToSrgb(0.6f), testsupport::kJpegFlatTol);
  EXPECT_EQ(p.a, 1.0f);
}

TEST(WriteImage, StoresMetadata) {
  const fs::path dir = testsupport::FreshOutputDir("image_io/meta");
  WriteOptions o;
  o.frame = 42;
  o.source_file = "walk.bvh";
  for (const char* name : {"m.png", "m.exr", "m.tif"}) {
    ASSERT_TRUE(WriteImage(TestPattern(4, 4), (dir / name).string(), o));
    auto in = OIIO::ImageInput::open((dir / name).string());
    ASSERT_TRUE(in) << name;
    const OIIO::ImageSpec& spec = in->spec();
    const std::string software = spec.get_string_attribute("Software");
    EXPECT_EQ(software.substr(0, 10), "patchskin ") << name;
    EXPECT_EQ(std::string(spec.get_string_attribute("ImageDescription")),
              "frame 42, source walk.bvh")
        << name;
    if (std::string(name) != "m.tif") {
      EXPECT_EQ(std::string(spec.get_string_attribute("patchskin:source")), "walk.bvh") << name;
      EXPECT_EQ(std::string(spec.get_string_attribute("patchskin:frame")), "42") << name;
    }
  }
}

TEST(WriteImage, IsAtomicAndLeavesNoTemporaryFile) {
  const fs::path dir = testsupport::FreshOutputDir("image_io/atomic");
  ASSERT_TRUE(WriteImage(TestPattern(8, 8), (dir / "ok.png").string()));
  EXPECT_EQ(CountEntries(dir), 1u) << "only the final file";
  EXPECT_FALSE(fs::exists(TemporaryPathFor((dir / "ok.png").string())));

  // Missing folder: fails, creates nothing.
  const Status missing = WriteImage(TestPattern(8, 8), (dir / "nope" / "f.png").string());
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().code, base::ErrorCode::kIo);
  EXPECT_FALSE(fs::exists(dir / "nope"));

  // The final name is taken by a non-empty folder: the encoder finishes the
  // temporary file, the rename fails, and the temporary file must be gone.
  fs::create_directories(dir / "taken.exr" / "child");
  const Status taken = WriteImage(TestPattern(8, 8), (dir / "taken.exr").string());
  ASSERT_FALSE(taken.ok());
  EXPECT_EQ(taken.error().code, base::ErrorCode::kIo);
  EXPECT_NE(taken.error().ToString().find("taken.exr"), std::string::npos);
  EXPECT_TRUE(fs::is_directory(dir / "taken.exr" / "child"));
  EXPECT_EQ(CountEntries(dir), 2u) << "ok.png and taken.exr only";
}

TEST(WriteImage, RejectsBadImagesAndOptions) {
  const fs::path dir = testsupport::FreshOutputDir("image_io/reject");
  EXPECT_EQ(WriteImage(Image(), (dir / "e.png").string()).error().code,
            base::ErrorCode::kInvalidArgument);
  Image broken(4, 4);
  broken.depth.resize(3);
  EXPECT_EQ(WriteImage(broken, (dir / "b.exr").string()).error().code,
            base::ErrorCode::kInvalidArgument);
  WriteOptions o;
  o.png_compression = 10;
  EXPECT_EQ(WriteImage(Image(2, 2), (dir / "o.png").string(), o).error().code,
            base::ErrorCode::kInvalidArgument);
  EXPECT_EQ(WriteImage(Image(2, 2), (dir / "x.gif").string()).error().code,
            base::ErrorCode::kUnsupported);
  EXPECT_EQ(CountEntries(dir), 0u);
}

TEST(ReadImage, ReportsMissingAndCorruptFiles) {
  const fs::path dir = testsupport::FreshOutputDir("image_io/read_bad");
  auto missing = ReadImage((dir / "none.png").string());
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().code, base::ErrorCode::kIo);
  EXPECT_NE(missing.error().ToString().find("none.png"), std::string::npos);
  std::ofstream(dir / "junk.png") << "not a png at all";
  auto junk = ReadImage((dir / "junk.png").string());
  ASSERT_FALSE(junk.ok());
  EXPECT_EQ(junk.error().code, base::ErrorCode::kIo);
}

// CRC-32 as PNG chunks use it (ISO 3309, reflected polynomial 0xEDB88320).
std::uint32_t Crc32(const std::string& bytes) {
  std::uint32_t crc = 0xFFFFFFFFu;
  for (unsigned char b : bytes) {
    crc ^= b;
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

std::string BigEndian(std::uint32_t v) {
  return {static_cast<char>(v >> 24), static_cast<char>(v >> 16), static_cast<char>(v >> 8),
          static_cast<char>(v)};
}

TEST(ReadImage, RefusesHugeDimensionsBeforeAllocating) {
  // A valid PNG header announcing 100000 x 100000 RGBA pixels, and no pixel data.
  const fs::path dir = testsupport::FreshOutputDir("image_io/read_huge");
  std::string ihdr = "IHDR" + BigEndian(100000) + BigEndian(100000);
  ihdr += std::string{'\x08', '\x06', '\0', '\0', '\0'};  // 8-bit RGBA
  std::string png = "\x89PNG\r\n\x1a\n";
  png += BigEndian(13) + ihdr + BigEndian(Crc32(ihdr));
  png += BigEndian(0) + "IDAT" + BigEndian(Crc32("IDAT"));  // libpng stops reading here
  png += BigEndian(0) + "IEND" + BigEndian(Crc32("IEND"));
  std::ofstream(dir / "huge.png", std::ios::binary) << png;
  auto r = ReadImage((dir / "huge.png").string());
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, base::ErrorCode::kLimitExceeded) << r.error().ToString();
  EXPECT_NE(r.error().message.find("100000x100000x4"), std::string::npos);
}

TEST(ExpandFramePattern, PadsHashesAndPrintfForms) {
  EXPECT_EQ(*ExpandFramePattern("out/frame_####.png", 7), "out/frame_0007.png");
  EXPECT_EQ(*ExpandFramePattern("out/frame_####.png", 123456), "out/frame_123456.png");
  EXPECT_EQ(*ExpandFramePattern("f#.exr", 12), "f12.exr");
  EXPECT_EQ(*ExpandFramePattern("f_%04d.png", 31), "f_0031.png");
  EXPECT_EQ(*ExpandFramePattern("f_%d.png", 31), "f_31.png");
  EXPECT_EQ(*ExpandFramePattern("f_###.png", -4), "f_-04.png");
  EXPECT_TRUE(HasFramePlaceholder("a_####.png"));
  EXPECT_FALSE(HasFramePlaceholder("a.png"));
  EXPECT_FALSE(HasFramePlaceholder("a_%s.png"));
}

TEST(ExpandFramePattern, RejectsMissingOrRepeatedPlaceholders) {
  for (const char* bad : {"still.png", "a_##_##.png", "a_%04d_####.png", "a_%4d.png"}) {
    auto r = ExpandFramePattern(bad, 1);
    ASSERT_FALSE(r.ok()) << bad;
    EXPECT_EQ(r.error().code, base::ErrorCode::kInvalidArgument);
    EXPECT_NE(r.error().message.find("placeholder"), std::string::npos);
  }
}

}  // namespace
}  // namespace render
