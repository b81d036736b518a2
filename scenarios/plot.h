#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace slamrig::scenario {

/// An RGB colour for plots.
struct Colour {
  std::uint8_t r = 0, g = 0, b = 0;
};

/// The plot palette: distinguishable colours for series 0, 1, 2, ... (wraps around).
Colour PaletteColour(std::size_t index);

/// One line (or set of points) of a plot. `y_low`/`y_high`, when given (same length as `x`),
/// draw a shaded band or error bars around the line: the spread over seeds, say.
struct PlotSeries {
  std::string label;
  std::vector<double> x;
  std::vector<double> y;
  std::vector<double> y_low;
  std::vector<double> y_high;
  Colour colour;
  bool markers = false;  ///< draw a dot at each point (and error bars instead of a band)
  bool dashed = false;   ///< a reference line, e.g. a threshold
};

/// Axes, labels and size of a plot.
struct PlotOptions {
  std::string title;
  std::string x_label;
  std::string y_label;
  int width_px = 900;
  int height_px = 420;
  bool y_from_zero = true;  ///< include 0 on the y axis (errors, counts)
};

/// A line plot with "nice" ticks, grid, axis labels and a legend, encoded as PNG bytes.
/// Non-finite values are left out of the lines (a gap), never plotted as 0.
std::string RenderLinePlotPng(const std::vector<PlotSeries>& series, const PlotOptions& options);

/// One bar group per category (e.g. SLAM configurations), one bar per value name, encoded as
/// PNG bytes. `values[i][j]` is category i, value j; non-finite values draw no bar.
std::string RenderBarChartPng(const std::vector<std::string>& categories,
                              const std::vector<std::string>& value_names,
                              const std::vector<std::vector<double>>& values,
                              const PlotOptions& options);

}  // namespace slamrig::scenario
