#include "scenarios/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace slamrig::scenario {
namespace {

constexpr int kMarginLeft = 80;
constexpr int kMarginRight = 20;
constexpr int kMarginTop = 40;
constexpr int kMarginBottom = 60;
const cv::Scalar kBlack(0, 0, 0);
const cv::Scalar kGrid(225, 225, 225);

cv::Scalar Bgr(const Colour& c) { return cv::Scalar(c.b, c.g, c.r); }

// Ticks at 1, 2 or 5 times a power of ten covering [lo, hi] with about `target` steps.
std::vector<double> NiceTicks(double lo, double hi, int target) {
  const double span = hi - lo;
  const double raw = span / std::max(1, target);
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  double step = power;
  for (const double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * power >= raw) {
      step = m * power;
      break;
    }
  }
  std::vector<double> ticks;
  for (double t = std::ceil(lo / step - 1e-9) * step; t <= hi + step * 1e-9; t += step) {
    ticks.push_back(std::abs(t) < step * 1e-9 ? 0.0 : t);
  }
  return ticks;
}

std::string TickLabel(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%g", v);
  return buffer;
}

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void Add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  // Padded so that a constant series or an empty plot still has a span.
  void Finish(bool from_zero) {
    if (lo > hi) lo = 0.0, hi = 1.0;
    if (from_zero) lo = std::min(lo, 0.0), hi = std::max(hi, 0.0);
    if (hi - lo < 1e-12) {
      const double pad = std::max(std::abs(hi) * 0.1, 1e-3);
      lo -= pad;
      hi += pad;
    }
  }
};

void PutText(cv::Mat& image, const std::string& text, cv::Point at, double scale = 0.45,
             const cv::Scalar& colour = kBlack) {
  cv::putText(image, text, at, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
}

int TextWidth(const std::string& text, double scale = 0.45) {
  int baseline = 0;
  return cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &baseline).width;
}

// The frame shared by both chart kinds: axes, grid, ticks, labels, title. Returns the
// value-to-pixel map for y; x is handled by the caller.
struct Frame {
  cv::Mat image;
  cv::Rect area;
  Range y;
  int Y(double v) const {
    return area.y + area.height -
           static_cast<int>(std::lround((v - y.lo) / (y.hi - y.lo) * area.height));
  }
};

Frame MakeFrame(const PlotOptions& options, Range y) {
  Frame f;
  f.image = cv::Mat(options.height_px, options.width_px, CV_8UC3, cv::Scalar(255, 255, 255));
  f.area = cv::Rect(kMarginLeft, kMarginTop, options.width_px - kMarginLeft - kMarginRight,
                    options.height_px - kMarginTop - kMarginBottom);
  const std::vector<double> ticks = NiceTicks(y.lo, y.hi, 6);
  y.lo = std::min(y.lo, ticks.front());
  y.hi = std::max(y.hi, ticks.back());
  f.y = y;
  for (const double t : ticks) {
    const int py = f.Y(t);
    cv::line(f.image, {f.area.x, py}, {f.area.x + f.area.width, py}, kGrid, 1);
    const std::string label = TickLabel(t);
    PutText(f.image, label, {f.area.x - 8 - TextWidth(label), py + 5});
  }
  PutText(f.image, options.title, {kMarginLeft, 18}, 0.6);
  // y label, written horizontally above the axis (OpenCV cannot rotate text).
  PutText(f.image, options.y_label, {8, kMarginTop - 4}, 0.45, cv::Scalar(60, 60, 60));
  const int xl = f.area.x + (f.area.width - TextWidth(options.x_label)) / 2;
  PutText(f.image, options.x_label, {xl, options.height_px - 12});
  return f;
}

void DrawLegend(cv::Mat& image, const cv::Rect& area, const std::vector<std::string>& labels,
                const std::vector<Colour>& colours) {
  int width = 0;
  for (const auto& l : labels) width = std::max(width, TextWidth(l));
  const int x = area.x + area.width - width - 40;
  int y = area.y + 8;
  const int height = 20 * static_cast<int>(labels.size()) + 6;
  if (labels.empty()) return;
  cv::rectangle(image, {x - 6, y - 4}, {area.x + area.width - 4, y + height - 4},
                cv::Scalar(255, 255, 255), cv::FILLED);
  cv::rectangle(image, {x - 6, y - 4}, {area.x + area.width - 4, y + height - 4}, kGrid, 1);
  for (std::size_t i = 0; i < labels.size(); ++i) {
    cv::line(image, {x, y + 8}, {x + 22, y + 8}, Bgr(colours[i]), 3, cv::LINE_AA);
    PutText(image, labels[i], {x + 28, y + 13});
    y += 20;
  }
}

std::string EncodePng(const cv::Mat& image) {
  std::vector<std::uint8_t> png;
  if (!cv::imencode(".png", image, png)) throw std::runtime_error("PNG encoding failed");
  return std::string(png.begin(), png.end());
}

}  // namespace

Colour PaletteColour(std::size_t index) {
  // Colour-blind friendly (Okabe-Ito), then a few more.
  static const Colour kPalette[] = {{0, 114, 178}, {213, 94, 0},   {0, 158, 115},   {204, 121, 167},
                                    {230, 159, 0}, {86, 180, 233}, {120, 120, 120}, {0, 0, 0}};
  return kPalette[index % (sizeof(kPalette) / sizeof(kPalette[0]))];
}

std::string RenderLinePlotPng(const std::vector<PlotSeries>& series, const PlotOptions& options) {
  Range x, y;
  for (const auto& s : series) {
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      x.Add(s.x[i]);
      y.Add(s.y[i]);
      if (i < s.y_low.size()) y.Add(s.y_low[i]);
      if (i < s.y_high.size()) y.Add(s.y_high[i]);
    }
  }
  x.Finish(false);
  y.Finish(options.y_from_zero);
  Frame f = MakeFrame(options, y);
  const std::vector<double> xticks = NiceTicks(x.lo, x.hi, 8);
  const auto X = [&](double v) {
    return f.area.x + static_cast<int>(std::lround((v - x.lo) / (x.hi - x.lo) * f.area.width));
  };
  for (const double t : xticks) {
    if (t < x.lo - 1e-12 || t > x.hi + 1e-12) continue;
    const int px = X(t);
    cv::line(f.image, {px, f.area.y}, {px, f.area.y + f.area.height}, kGrid, 1);
    const std::string label = TickLabel(t);
    PutText(f.image, label, {px - TextWidth(label) / 2, f.area.y + f.area.height + 18});
  }
  cv::rectangle(f.image, f.area, cv::Scalar(120, 120, 120), 1);

  std::vector<std::string> labels;
  std::vector<Colour> colours;
  for (const auto& s : series) {
    const cv::Scalar colour = Bgr(s.colour);
    const bool band = s.y_low.size() == s.x.size() && s.y_high.size() == s.x.size();
    if (band && !s.markers) {
      // Shaded band between low and high, blended over the grid.
      std::vector<cv::Point> polygon;
      for (std::size_t i = 0; i < s.x.size(); ++i) {
        if (std::isfinite(s.y_high[i])) polygon.emplace_back(X(s.x[i]), f.Y(s.y_high[i]));
      }
      for (std::size_t i = s.x.size(); i-- > 0;) {
        if (std::isfinite(s.y_low[i])) polygon.emplace_back(X(s.x[i]), f.Y(s.y_low[i]));
      }
      if (polygon.size() >= 3) {
        cv::Mat overlay = f.image.clone();
        cv::fillPoly(overlay, std::vector<std::vector<cv::Point>>{polygon}, colour, cv::LINE_AA);
        cv::addWeighted(overlay, 0.2, f.image, 0.8, 0.0, f.image);
      }
    }
    std::vector<cv::Point> run;
    auto flush = [&] {
      if (run.size() >= 2) {
        if (s.dashed) {
          for (std::size_t i = 1; i < run.size(); ++i) {
            const cv::Point a = run[i - 1], b = run[i];
            const double length = std::hypot(b.x - a.x, b.y - a.y);
            for (double d = 0; d < length; d += 12) {
              const double e = std::min(d + 6, length);
              cv::line(f.image, a + (b - a) * (d / length), a + (b - a) * (e / length), colour, 2,
                       cv::LINE_AA);
            }
          }
        } else {
          cv::polylines(f.image, run, false, colour, 2, cv::LINE_AA);
        }
      }
      run.clear();
    };
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) {
        flush();
        continue;
      }
      const cv::Point p(X(s.x[i]), f.Y(s.y[i]));
      run.push_back(p);
      if (s.markers) {
        if (band && std::isfinite(s.y_low[i]) && std::isfinite(s.y_high[i])) {
          cv::line(f.image, {p.x, f.Y(s.y_low[i])}, {p.x, f.Y(s.y_high[i])}, colour, 1,
                   cv::LINE_AA);
          cv::line(f.image, {p.x - 4, f.Y(s.y_low[i])}, {p.x + 4, f.Y(s.y_low[i])}, colour, 1);
          cv::line(f.image, {p.x - 4, f.Y(s.y_high[i])}, {p.x + 4, f.Y(s.y_high[i])}, colour, 1);
        }
        cv::circle(f.image, p, 4, colour, cv::FILLED, cv::LINE_AA);
      }
    }
    flush();
    if (!s.label.empty()) {
      labels.push_back(s.label);
      colours.push_back(s.colour);
    }
  }
  DrawLegend(f.image, f.area, labels, colours);
  return EncodePng(f.image);
}

std::string RenderBarChartPng(const std::vector<std::string>& categories,
                              const std::vector<std::string>& value_names,
                              const std::vector<std::vector<double>>& values,
                              const PlotOptions& options) {
  Range y;
  for (const auto& row : values) {
    for (const double v : row) y.Add(v);
  }
  y.Finish(true);
  Frame f = MakeFrame(options, y);
  cv::rectangle(f.image, f.area, cv::Scalar(120, 120, 120), 1);
  const int groups = std::max<int>(1, static_cast<int>(categories.size()));
  const int bars = std::max<int>(1, static_cast<int>(value_names.size()));
  const double group_w = static_cast<double>(f.area.width) / groups;
  const double bar_w = group_w * 0.8 / bars;
  for (int g = 0; g < static_cast<int>(categories.size()); ++g) {
    const double x0 = f.area.x + g * group_w + group_w * 0.1;
    for (int b = 0; b < bars && b < static_cast<int>(values[g].size()); ++b) {
      const double v = values[g][b];
      if (!std::isfinite(v)) continue;
      const int left = static_cast<int>(x0 + b * bar_w);
      const int right = static_cast<int>(x0 + (b + 1) * bar_w) - 2;
      cv::rectangle(f.image, {left, f.Y(v)}, {right, f.Y(0.0)}, Bgr(PaletteColour(b)), cv::FILLED);
      const std::string label = TickLabel(std::round(v * 1000.0) / 1000.0);
      PutText(f.image, label, {(left + right - TextWidth(label, 0.4)) / 2, f.Y(v) - 4}, 0.4);
    }
    const std::string& name = categories[g];
    PutText(f.image, name,
            {static_cast<int>(x0 + group_w * 0.4) - TextWidth(name) / 2,
             f.area.y + f.area.height + 18});
  }
  std::vector<Colour> colours;
  for (int b = 0; b < bars; ++b) colours.push_back(PaletteColour(b));
  DrawLegend(f.image, f.area, value_names, colours);
  return EncodePng(f.image);
}

}  // namespace slamrig::scenario
