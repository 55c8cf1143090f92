// Image comparison: figures against hand-computed values, the pass/fail rule, diffs.

#include "render/output/image_compare.h"

#include <cmath>

#include <gtest/gtest.h>

#include "render/output/image_io.h"
#include "support/tolerances.h"

namespace render {
namespace {

using testsupport::kFloatTol;

CompareThresholds Linear() {
  CompareThresholds t;
  t.space = CompareSpace::kLinear;
  return t;
}

TEST(Compare, FiguresMatchHandComputedValues) {
  // Two pixels, eight values; two of them differ: by 0.1 (R of pixel 0) and by
  // 0.02 (A of pixel 1).
  Image a(2, 1, glm::vec4(0.0f));
  Image b = a;
  b.at(0, 0).r = 0.1f;
  b.at(1, 0).a = 0.02f;
  auto r = Compare(a, b, Linear());
  ASSERT_TRUE(r.ok()) << r.error().ToString();
  const double mean = (0.1 + 0.02) / 8.0;                 // 0.015
  const double rms = std::sqrt((0.01 + 0.0004) / 8.0);    // 0.0360555
  const double psnr = 20.0 * std::log10(1.0 / rms);       // 28.86 dB
  EXPECT_NEAR(r->mean_error, mean, kFloatTol);
  EXPECT_NEAR(r->rms_error, rms, kFloatTol);
  EXPECT_NEAR(r->psnr_db, psnr, testsupport::kPsnrTolDb);
  EXPECT_NEAR(r->max_error, 0.1, kFloatTol);
  EXPECT_EQ(r->max_x, 0);
  EXPECT_EQ(r->max_y, 0);
  EXPECT_EQ(r->max_channel, 0);
  EXPECT_EQ(r->num_pixels, 2);
  EXPECT_EQ(r->num_failing, 2);
  EXPECT_DOUBLE_EQ(r->failing_percent, 100.0);
  EXPECT_FALSE(r->passed);
}

TEST(Compare, MaxErrorLocationAndPixelCounting) {
  Image a(5, 4, glm::vec4(0.25f, 0.5f, 0.75f, 1.0f));
  Image b = a;
  b.at(3, 2).b += 0.05f;  // the largest difference, in blue
  b.at(1, 1).r += 0.01f;  // one pixel with two failing channels counts once
  b.at(1, 1).g += 0.01f;
  auto r = Compare(a, b, Linear());
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->max_x, 3);
  EXPECT_EQ(r->max_y, 2);
  EXPECT_EQ(r->max_channel, 2);
  EXPECT_EQ(r->num_failing, 2);
}

TEST(Compare, IdenticalImagesHaveInfinitePsnr) {
  Image a(3, 3, glm::vec4(0.3f, 0.2f, 0.1f, 1.0f));
  auto r = Compare(a, a);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->max_error, 0.0);
  EXPECT_EQ(r->rms_error, 0.0);
  EXPECT_TRUE(std::isinf(r->psnr_db));
  EXPECT_TRUE(r->passed);
  CompareThresholds exact = Linear();
  exact.fail_thresh = exact.fail_percent = exact.hard_fail = 0.0f;
  EXPECT_TRUE(Compare(a, a, exact)->passed);
  Image b = a;
  b.at(2, 2).g = std::nextafter(b.at(2, 2).g, 1.0f);
  EXPECT_FALSE(Compare(a, b, exact)->passed) << "one ulp fails a bit-exact comparison";
}

// 100x100 = 10000 pixels; 0.02 % of them is 2 pixels.
TEST(Compare, FailPercentAndHardFailRule) {
  const Image a(100, 100, glm::vec4(0.5f));
  Image two = a;
  two.at(10, 10).r += 0.008f;  // over fail (0.004), under hard fail (0.012)
  two.at(20, 20).r += 0.008f;
  auto r2 = Compare(a, two, Linear());
  ASSERT_TRUE(r2.ok());
  EXPECT_EQ(r2->num_failing, 2);
  EXPECT_TRUE(r2->passed) << "2 failing pixels of 10000 is exactly 0.02 %";

  Image three = two;
  three.at(30, 30).r += 0.008f;
  auto r3 = Compare(a, three, Linear());
  EXPECT_EQ(r3->num_failing, 3);
  EXPECT_FALSE(r3->passed);

  CompareThresholds looser = Linear();
  looser.fail_percent = 0.05f;  // 5 pixels allowed
  EXPECT_TRUE(Compare(a, three, looser)->passed);

  Image hard = a;
  hard.at(50, 50).a += 0.02f;  // one pixel, but over the hard limit
  auto rh = Compare(a, hard, Linear());
  EXPECT_EQ(rh->num_failing, 1);
  EXPECT_FALSE(rh->passed);
}

TEST(Compare, SrgbSpaceComparesEncodedValues) {
  const Image a(1, 1, glm::vec4(0.5f, 0.5f, 0.5f, 1.0f));
  const Image b(1, 1, glm::vec4(0.55f, 0.5f, 0.5f, 1.0f));
  // Independent evaluation of the sRGB curve.
  auto encode = [](double x) { return 1.055 * std::pow(x, 1.0 / 2.4) - 0.055; };
  auto r = Compare(a, b);
  ASSERT_TRUE(r.ok());
  EXPECT_NEAR(r->max_error, encode(0.55) - encode(0.5), kFloatTol);
  EXPECT_NEAR(Compare(a, b, Linear())->max_error, 0.05, kFloatTol);
}

TEST(Compare, RejectsDifferentSizes) {
  auto r = Compare(Image(4, 4), Image(4, 5));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, base::ErrorCode::kInvalidArgument);
  EXPECT_NE(r.error().message.find("4x4 and 4x5"), std::string::npos);
  EXPECT_FALSE(Compare(Image(), Image()).ok());
  EXPECT_FALSE(MakeDiffImage(Image(2, 2), Image(3, 2)).ok());
}

TEST(MakeDiffImage, AmplifiesAndClamps) {
  Image a(2, 1, glm::vec4(0.2f, 0.2f, 0.2f, 1.0f));
  Image b = a;
  b.at(0, 0).g = 0.21f;
  b.at(1, 0).b = 0.9f;
  auto d = MakeDiffImage(a, b, 10.0f, CompareSpace::kLinear);
  ASSERT_TRUE(d.ok());
  EXPECT_NEAR(d->at(0, 0).g, 0.1f, kFloatTol);
  EXPECT_EQ(d->at(0, 0).r, 0.0f);
  EXPECT_EQ(d->at(1, 0).b, 1.0f) << "7.0 clamps to 1";
  EXPECT_EQ(d->at(1, 0).a, 1.0f);
}

}  // namespace
}  // namespace render
