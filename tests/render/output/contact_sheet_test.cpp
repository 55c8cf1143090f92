// Contact sheet: layout size, thumbnail placement, labels, errors.

#include "render/output/contact_sheet.h"

#include <cmath>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "support/tolerances.h"

namespace render {
namespace {

using testsupport::kFloatTol;

glm::vec4 ColourOf(int i) {
  return glm::vec4(0.1f * static_cast<float>(i), 0.5f, 1.0f - 0.1f * static_cast<float>(i), 1.0f);
}

TEST(ContactSheetLayout, FollowsTheDocumentedFormula) {
  ContactSheetOptions o;
  o.columns = 3;
  o.thumb_width = 40;
  o.padding = 5;
  o.label_height = 12;
  auto l = ComputeContactSheetLayout(7, 80, 60, o);
  ASSERT_TRUE(l.ok());
  EXPECT_EQ(l->columns, 3);
  EXPECT_EQ(l->rows, 3);
  EXPECT_EQ(l->thumb_height, 30);
  EXPECT_EQ(l->width, 3 * 40 + 4 * 5);            // 140
  EXPECT_EQ(l->height, 3 * (30 + 12) + 4 * 5);    // 146
  auto one = ComputeContactSheetLayout(2, 80, 60, o);
  EXPECT_EQ(one->columns, 2) << "no empty columns for short sequences";
  EXPECT_EQ(one->rows, 1);
}

// Even steps from the first frame to the last, both included: 24 of 100
// frames are 0, 4.30..., 99 rounded; consecutive picks differ by 4 or 5.
TEST(ContactSheetPick, EvenStepsFromTheFirstFrameToTheLast) {
  EXPECT_EQ(render::ContactSheetPick(0, 24, 100), 0);
  EXPECT_EQ(render::ContactSheetPick(23, 24, 100), 99);
  for (int k = 0; k < 24; ++k) {
    const double exact = k * 99.0 / 23.0;
    EXPECT_LE(std::abs(static_cast<double>(render::ContactSheetPick(k, 24, 100)) - exact), 0.5) << k;
  }
  for (int k = 1; k < 24; ++k) {
    const std::int64_t step = render::ContactSheetPick(k, 24, 100) - render::ContactSheetPick(k - 1, 24, 100);
    EXPECT_TRUE(step == 4 || step == 5) << k;
  }
  // As many picks as frames: every frame; one pick: the first.
  for (int k = 0; k < 7; ++k) EXPECT_EQ(render::ContactSheetPick(k, 7, 7), k);
  EXPECT_EQ(render::ContactSheetPick(0, 1, 50), 0);
  // An hour at 120 fps does not overflow.
  EXPECT_EQ(render::ContactSheetPick(23, 24, 432000), 431999);
}

TEST(ContactSheetColumns, AsFewRowsAsAllowedFilledEvenly) {
  EXPECT_EQ(render::ContactSheetColumns(24), 6);  // 4 rows of 6
  EXPECT_EQ(render::ContactSheetColumns(10), 5);  // 2 rows of 5, not 6 + 4
  EXPECT_EQ(render::ContactSheetColumns(7), 4);   // 4 + 3
  EXPECT_EQ(render::ContactSheetColumns(6), 6);
  EXPECT_EQ(render::ContactSheetColumns(3), 3);
  EXPECT_EQ(render::ContactSheetColumns(1), 1);
  EXPECT_EQ(render::ContactSheetColumns(13), 5);  // 3 rows: 5 + 5 + 3
}

TEST(ContactSheetLayout, RejectsBadArguments) {
  ContactSheetOptions o;
  EXPECT_FALSE(ComputeContactSheetLayout(0, 80, 60, o).ok());
  EXPECT_FALSE(ComputeContactSheetLayout(3, 0, 60, o).ok());
  o.columns = 0;
  EXPECT_FALSE(ComputeContactSheetLayout(3, 80, 60, o).ok());
  o.columns = 100;
  o.thumb_width = 100000;
  auto huge = ComputeContactSheetLayout(1000, 80, 60, o);
  ASSERT_FALSE(huge.ok());
  EXPECT_EQ(huge.error().code, base::ErrorCode::kInvalidArgument);
}

TEST(ContactSheet, PlacesThumbnailsRowByRowWithLabels) {
  ContactSheetOptions o;
  o.columns = 3;
  o.thumb_width = 40;
  o.padding = 5;
  o.label_height = 12;
  std::vector<Image> frames;
  for (int i = 0; i < 7; ++i) frames.emplace_back(80, 60, ColourOf(i));
  std::vector<NumberedFrame> numbered;
  for (int i = 0; i < 7; ++i) numbered.push_back({&frames[static_cast<std::size_t>(i)], 100 + i});
  auto sheet = MakeContactSheet(numbered, o);
  ASSERT_TRUE(sheet.ok()) << sheet.error().ToString();
  ASSERT_EQ(sheet->width, 140);
  ASSERT_EQ(sheet->height, 146);
  for (int i = 0; i < 9; ++i) {
    const int x0 = 5 + (i % 3) * 45;
    const int y0 = 5 + (i / 3) * 47;
    const glm::vec4 centre = sheet->at(x0 + 20, y0 + 15);
    const glm::vec4 expected = i < 7 ? ColourOf(i) : o.background;
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(centre[c], expected[c], kFloatTol) << "cell " << i;
    // Label strip: text pixels exist under filled cells only.
    int text_pixels = 0;
    for (int y = y0 + 30; y < y0 + 42; ++y) {
      for (int x = x0; x < x0 + 40; ++x) text_pixels += sheet->at(x, y) != o.background;
    }
    if (i < 7) {
      EXPECT_GT(text_pixels, 10) << "cell " << i;
    } else {
      EXPECT_EQ(text_pixels, 0) << "cell " << i;
    }
  }
  EXPECT_EQ(sheet->at(2, 2), o.background);  // outer padding
}

TEST(ContactSheetBuilder, RejectsWrongSizesAndTooManyFrames) {
  auto b = ContactSheetBuilder::Create(1, 16, 16, {});
  ASSERT_TRUE(b.ok());
  EXPECT_FALSE((*b)->Add(Image(8, 16), 0).ok());
  EXPECT_TRUE((*b)->Add(Image(16, 16), 0).ok());
  EXPECT_FALSE((*b)->Add(Image(16, 16), 1).ok());
  EXPECT_EQ((*b)->frames_added(), 1);
}

}  // namespace
}  // namespace render
