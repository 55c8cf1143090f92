// Time plots: bad input is refused; curves are drawn where their values say.

#include "render/output/plot.h"

#include <gtest/gtest.h>

namespace {

render::PlotOptions Ramp() {
  render::PlotOptions o;
  o.width = 400;
  o.height = 300;
  for (int k = 0; k <= 100; ++k) o.times_s.push_back(k * 0.01);
  render::PlotCurve c{"ramp", {}, {1.0f, 0.0f, 0.0f, 1.0f}};
  for (double t : o.times_s) c.values.push_back(t);
  o.panels = {{"ramp", "", {c}}};
  return o;
}

TEST(DrawTimePlot, RejectsBadInput) {
  render::PlotOptions o = Ramp();
  o.width = 10;
  EXPECT_FALSE(render::DrawTimePlot(o).ok());
  o = Ramp();
  o.times_s[5] = o.times_s[4];
  EXPECT_FALSE(render::DrawTimePlot(o).ok());
  o = Ramp();
  o.panels[0].curves[0].values.pop_back();
  EXPECT_FALSE(render::DrawTimePlot(o).ok());
  o = Ramp();
  o.panels[0].curves.clear();
  EXPECT_FALSE(render::DrawTimePlot(o).ok());
}

// A rising ramp: the red pixels in the left quarter of the plot sit lower on
// screen (larger y) than those in the right quarter.
TEST(DrawTimePlot, RampRisesToTheRight) {
  auto image = render::DrawTimePlot(Ramp());
  ASSERT_TRUE(image.ok()) << image.error().ToString();
  ASSERT_EQ(image->width, 400);
  const auto mean_red_y = [&](int x0, int x1) {
    double sum = 0.0;
    int count = 0;
    for (int y = 0; y < image->height; ++y) {
      for (int x = x0; x < x1; ++x) {
        const glm::vec4 c = image->at(x, y);
        if (c.r > 0.8f && c.g < 0.1f && c.b < 0.1f) {
          sum += y;
          ++count;
        }
      }
    }
    return count > 0 ? sum / count : -1.0;
  };
  const double left = mean_red_y(100, 160), right = mean_red_y(300, 360);
  ASSERT_GT(left, 0.0);
  ASSERT_GT(right, 0.0);
  EXPECT_GT(left, right + 100.0);
}

}  // namespace
