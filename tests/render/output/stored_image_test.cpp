// render::AsStored against the real round trip: write a frame, read it back,
// and compare every value bit for bit with what AsStored computed without the
// file. A resumed render's contact sheet depends on this equality.

#include "render/output/stored_image.h"

#include <cstring>
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "render/output/contact_sheet.h"
#include "render/output/image_io.h"
#include "support/data_paths.h"

namespace {

// Colours over and beyond [0, 1], every alpha code and a few odd values.
render::Image TestFrame() {
  render::Image image(37, 23);
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> colour(-0.1f, 1.2f), alpha(0.0f, 1.0f);
  for (glm::vec4& p : image.rgba) p = {colour(rng), colour(rng), colour(rng), alpha(rng)};
  image.rgba[0] = {0.0f, 1.0f, 0.5f, 1.0f};
  image.rgba[1] = {std::numeric_limits<float>::quiet_NaN(), 2.0f, -1.0f,
                   std::numeric_limits<float>::quiet_NaN()};
  image.depth.assign(image.rgba.size(), 3.25f);
  return image;
}

bool SameBits(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }

void ExpectRoundTripMatches(const std::string& extension, render::ImageFormat format,
                            bool check_nan_pixel) {
  const render::Image image = TestFrame();
  const std::string path =
      testsupport::TestOutputPath("stored_image/frame." + extension).string();
  ASSERT_TRUE(render::WriteImage(image, path).ok());
  const base::Result<render::Image> read = render::ReadImage(path);
  ASSERT_TRUE(read.ok()) << read.error().ToString();
  const base::Result<render::Image> stored = render::AsStored(image, format);
  ASSERT_TRUE(stored.ok()) << stored.error().ToString();
  ASSERT_EQ(stored->width, read->width);
  ASSERT_EQ(stored->height, read->height);
  int mismatches = 0;
  for (std::size_t i = check_nan_pixel ? 0 : 2; i < read->rgba.size(); ++i) {
    for (int c = 0; c < 4; ++c) {
      if (!SameBits(stored->rgba[i][c], read->rgba[i][c]) && ++mismatches < 5) {
        ADD_FAILURE() << extension << " pixel " << i << " channel " << c << ": AsStored "
                      << stored->rgba[i][c] << ", read back " << read->rgba[i][c];
      }
    }
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_EQ(stored->depth.size(), read->depth.size());
  // The round trip is not the identity (so the test can tell).
  EXPECT_FALSE(SameBits(stored->rgba[5].r, image.rgba[5].r));
}

TEST(AsStored, PngMatchesTheFileReadBack) { ExpectRoundTripMatches("png", render::ImageFormat::kPng, true); }

TEST(AsStored, TiffMatchesTheFileReadBack) {
  ExpectRoundTripMatches("tif", render::ImageFormat::kTiff, true);
}

// EXR keeps NaN and out-of-range values as half; pixel 1 is left out because
// NaN payloads need not survive the conversion bit for bit.
TEST(AsStored, ExrMatchesTheFileReadBack) {
  ExpectRoundTripMatches("exr", render::ImageFormat::kExr, false);
}

TEST(AsStored, JpegIsRefusedAsLossy) {
  const base::Result<render::Image> stored =
      render::AsStored(TestFrame(), render::ImageFormat::kJpeg);
  ASSERT_FALSE(stored.ok());
  EXPECT_EQ(stored.error().code, base::ErrorCode::kUnsupported);
}

}  // namespace

namespace {

// Why the render command feeds its contact sheet AsStored frames: a sheet
// built from frames as rendered differs from one built from the same frames
// read back from PNG (what --resume does), and AsStored closes the gap.
TEST(AsStored, ContactSheetFromStoredValuesEqualsOneFromFramesReadBack) {
  render::Image frame(64, 36);
  for (int y = 0; y < frame.height; ++y) {
    for (int x = 0; x < frame.width; ++x) {
      frame.at(x, y) = {0.003f * static_cast<float>(x) + 0.0011f * static_cast<float>(y),
                        0.5f * static_cast<float>(y) / 36.0f, 0.2f, 1.0f};
    }
  }
  const std::string path = testsupport::TestOutputPath("stored_image/sheet_frame.png").string();
  ASSERT_TRUE(render::WriteImage(frame, path).ok());
  const base::Result<render::Image> read = render::ReadImage(path);
  ASSERT_TRUE(read.ok());
  const base::Result<render::Image> stored = render::AsStored(frame, render::ImageFormat::kPng);
  ASSERT_TRUE(stored.ok());

  auto sheet_of = [](const render::Image& image) {
    auto builder = render::ContactSheetBuilder::Create(1, image.width, image.height,
                                                       {.columns = 1, .thumb_width = 24});
    EXPECT_TRUE(builder.ok());
    EXPECT_TRUE((*builder)->Add(image, 7).ok());
    return (*builder)->sheet().rgba;
  };
  const auto from_frame = sheet_of(frame), from_file = sheet_of(*read), from_stored = sheet_of(*stored);
  EXPECT_TRUE(from_stored == from_file);
  EXPECT_FALSE(from_frame == from_file) << "the test frame no longer shows the difference";
}

}  // namespace
