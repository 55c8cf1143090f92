#include "render/output/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "render/output/image_io.h"

namespace render {
namespace {

using base::ErrorCode;
using base::FileLoc;
using base::MakeError;

base::Error PlotError(const std::string& what) {
  return base::InvalidArgument(FileLoc{}, "plot: " + what);
}

// OpenCV draws anti-aliased lines on 8-bit images only: draw in 8-bit sRGB (BGR order).
cv::Scalar ToBgr8(const glm::vec4& linear) {
  return cv::Scalar(LinearToSrgb8(linear.b), LinearToSrgb8(linear.g), LinearToSrgb8(linear.r));
}

// A "nice" tick step (1, 2 or 5 x 10^k) giving about `count` ticks over `span`.
double NiceStep(double span, int count) {
  const double raw = span / std::max(count, 1);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * mag >= raw) return m * mag;
  return 10.0 * mag;
}

std::string FormatTick(double v, double step) {
  char buf[32];
  const int decimals = step >= 1.0 ? 0 : static_cast<int>(std::ceil(-std::log10(step)));
  std::snprintf(buf, sizeof buf, "%.*f", std::min(decimals, 6), v);
  return buf;
}

const cv::Scalar kInk(40, 40, 40), kGrid(225, 225, 225), kWhite(255, 255, 255);
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;

}  // namespace

base::Result<Image> DrawTimePlot(const PlotOptions& options) {
  const int W = options.width, H = options.height;
  if (W < 200 || H < 200 || W > 4096 || H > 4096) return PlotError("size outside [200, 4096]");
  const std::vector<double>& t = options.times_s;
  if (t.size() < 2) return PlotError("fewer than 2 sample times");
  for (std::size_t k = 1; k < t.size(); ++k)
    if (!(t[k] > t[k - 1])) return PlotError("sample times are not increasing");
  if (options.panels.empty()) return PlotError("no panel");
  for (const PlotPanel& panel : options.panels) {
    if (panel.curves.empty()) return PlotError("panel '" + panel.title + "' has no curve");
    for (const PlotCurve& c : panel.curves)
      if (c.values.size() != t.size()) return PlotError("curve '" + c.label + "' is not #T long");
  }

  cv::Mat canvas(H, W, CV_8UC3, kWhite);
  try {
    const int left = 80, right = 20, top = options.title.empty() ? 20 : 50, bottom = 50;
    const int gap = 30;
    const int num_panels = static_cast<int>(options.panels.size());
    const int panel_h = (H - top - bottom - gap * (num_panels - 1)) / num_panels;
    if (panel_h < 40) return PlotError("too many panels for the height");
    if (!options.title.empty()) {
      cv::putText(canvas, options.title, {left, 32}, kFont, 0.7, kInk, 1, cv::LINE_AA);
    }
    const double t0 = t.front(), t1 = t.back();
    const int plot_w = W - left - right;
    const auto x_of = [&](double time) {
      return left + static_cast<int>(std::lround((time - t0) / (t1 - t0) * plot_w));
    };
    const double t_step = NiceStep(t1 - t0, 10);
    for (int p = 0; p < num_panels; ++p) {
      const PlotPanel& panel = options.panels[static_cast<std::size_t>(p)];
      const int y_top = top + p * (panel_h + gap), y_bottom = y_top + panel_h;
      double lo = 0.0, hi = 0.0;
      for (const PlotCurve& c : panel.curves) {
        for (double v : c.values) {
          if (!std::isfinite(v)) continue;
          lo = std::min(lo, v);
          hi = std::max(hi, v);
        }
      }
      if (hi - lo <= 0.0) hi = lo + 1.0;
      const double y_step = NiceStep(hi - lo, 5);
      lo = std::floor(lo / y_step) * y_step;
      hi = std::ceil(hi / y_step) * y_step;
      const auto y_of = [&](double v) {
        return y_bottom - static_cast<int>(std::lround((v - lo) / (hi - lo) * panel_h));
      };
      for (double v = lo; v <= hi + 0.5 * y_step; v += y_step) {  // horizontal grid + labels
        const int y = y_of(v);
        cv::line(canvas, {left, y}, {W - right, y}, kGrid, 1, cv::LINE_8);
        cv::putText(canvas, FormatTick(v, y_step), {8, y + 5}, kFont, 0.45, kInk, 1, cv::LINE_AA);
      }
      for (double time = std::ceil(t0 / t_step) * t_step; time <= t1 + 1e-9; time += t_step) {
        const int x = x_of(time);
        cv::line(canvas, {x, y_top}, {x, y_bottom}, kGrid, 1, cv::LINE_8);
        if (p == num_panels - 1) {
          cv::putText(canvas, FormatTick(time, t_step), {x - 10, y_bottom + 20}, kFont, 0.45, kInk,
                      1, cv::LINE_AA);
        }
      }
      cv::rectangle(canvas, {left, y_top}, {W - right, y_bottom}, kInk, 1, cv::LINE_8);
      const std::string heading = panel.title + (panel.unit.empty() ? "" : " [" + panel.unit + "]");
      cv::putText(canvas, heading, {left + 8, y_top + 18}, kFont, 0.5, kInk, 1, cv::LINE_AA);
      int legend_x = W - right - 10;
      for (auto it = panel.curves.rbegin(); it != panel.curves.rend(); ++it) {
        int base = 0;
        const cv::Size size = cv::getTextSize(it->label, kFont, 0.45, 1, &base);
        legend_x -= size.width + 34;
        cv::line(canvas, {legend_x, y_top + 13}, {legend_x + 22, y_top + 13}, ToBgr8(it->color),
                 2, cv::LINE_AA);
        cv::putText(canvas, it->label, {legend_x + 28, y_top + 18}, kFont, 0.45, kInk, 1,
                    cv::LINE_AA);
      }
      for (const PlotCurve& c : panel.curves) {
        std::vector<cv::Point> run;
        const auto flush = [&] {
          if (run.size() >= 2) {
            cv::polylines(canvas, run, false, ToBgr8(c.color), 2, cv::LINE_AA);
          }
          run.clear();
        };
        for (std::size_t k = 0; k < t.size(); ++k) {
          if (!std::isfinite(c.values[k])) {
            flush();
            continue;
          }
          run.emplace_back(x_of(t[k]), y_of(c.values[k]));
        }
        flush();
      }
    }
    cv::putText(canvas, "time [s]", {W / 2 - 30, H - 8}, kFont, 0.5, kInk, 1, cv::LINE_AA);
  } catch (const cv::Exception& e) {
    return MakeError(ErrorCode::kInternal, FileLoc{}, std::string("plot: OpenCV: ") + e.what());
  }

  Image image(W, H);
  for (int y = 0; y < H; ++y) {
    const cv::Vec3b* row = canvas.ptr<cv::Vec3b>(y);
    for (int x = 0; x < W; ++x) {
      image.at(x, y) = glm::vec4(Srgb8ToLinear(row[x][2]), Srgb8ToLinear(row[x][1]),
                                 Srgb8ToLinear(row[x][0]), 1.0f);
    }
  }
  return image;
}

}  // namespace render
