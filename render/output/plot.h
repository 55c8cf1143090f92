#pragma once
// Time plots drawn with OpenCV into a render::Image (write it with WriteImage):
// stacked panels over one time axis, each with its own y range, grid, tick
// labels and a legend. Used to show an elastic patch's response beside the
// acceleration that drives it (ALGORITHMS.md 6), so a user sees the jiggle
// without reading numbers. Drawing is deterministic (no fonts from the system:
// OpenCV's Hershey font).

#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "base/error.h"
#include "render/image.h"

namespace render {

// One curve of a panel.
struct PlotCurve {
  std::string label;                        // legend text (ASCII)
  std::vector<double> values;               // #T samples at PlotOptions times; NaN = gap
  glm::vec4 color{0.1f, 0.3f, 0.9f, 1.0f};  // linear RGB
};

// One panel: curves sharing a y axis; the range covers every finite value and 0.
struct PlotPanel {
  std::string title;              // drawn top-left in the panel, e.g. "driving acceleration"
  std::string unit;               // y unit, e.g. "m/s^2"
  std::vector<PlotCurve> curves;  // >= 1
};

struct PlotOptions {
  int width = 960, height = 540;  // pixels, each in [200, 4096]
  std::string title;              // top line of the image
  std::vector<double> times_s;    // #T >= 2 increasing sample times (the x axis, seconds)
  std::vector<PlotPanel> panels;  // >= 1, stacked top to bottom
};

// Draws the plot. Errors: kInvalidArgument for sizes out of range, fewer than 2
// times, times not increasing, an empty panel or a curve whose length is not #T.
[[nodiscard]] base::Result<Image> DrawTimePlot(const PlotOptions& options);

}  // namespace render
