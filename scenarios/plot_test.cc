#include "scenarios/plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgcodecs.hpp>

namespace slamrig::scenario {
namespace {

cv::Mat Decode(const std::string& png) {
  return cv::imdecode(std::vector<std::uint8_t>(png.begin(), png.end()), cv::IMREAD_COLOR);
}

// Counts pixels of exactly the series colour.
int CountColour(const cv::Mat& image, const Colour& c) {
  int n = 0;
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      const auto p = image.at<cv::Vec3b>(y, x);
      n += p[0] == c.b && p[1] == c.g && p[2] == c.r;
    }
  }
  return n;
}

TEST(PlotTest, LinePlotDrawsEachSeriesAtTheRequestedSize) {
  PlotSeries a{"a", {0, 1, 2, 3}, {0.1, 0.4, 0.2, 0.3}, {}, {}, PaletteColour(0)};
  PlotSeries b{"b", {0, 1, 2, 3}, {1, 2, std::nan(""), 4}, {}, {}, PaletteColour(1)};
  PlotOptions options;
  options.title = "t";
  const cv::Mat image = Decode(RenderLinePlotPng({a, b}, options));
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, options.width_px);
  EXPECT_EQ(image.rows, options.height_px);
  EXPECT_GT(CountColour(image, a.colour), 100);
  EXPECT_GT(CountColour(image, b.colour), 100);
}

TEST(PlotTest, HigherValuesAreDrawnHigher) {
  // A single horizontal line at y = 10 on an axis from 0: its pixels sit in the top part.
  PlotSeries s{"", {0, 1}, {10, 10}, {}, {}, PaletteColour(2)};
  const cv::Mat image = Decode(RenderLinePlotPng({s}, PlotOptions{}));
  int sum_rows = 0, count = 0;
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      const auto p = image.at<cv::Vec3b>(y, x);
      if (p[0] == s.colour.b && p[1] == s.colour.g && p[2] == s.colour.r) sum_rows += y, ++count;
    }
  }
  ASSERT_GT(count, 0);
  EXPECT_LT(sum_rows / count, image.rows / 3);
}

TEST(PlotTest, EmptyAndDegenerateInputsStillRender) {
  EXPECT_FALSE(Decode(RenderLinePlotPng({}, PlotOptions{})).empty());
  PlotSeries constant{"c", {5}, {3}, {}, {}, PaletteColour(0), true};
  EXPECT_FALSE(Decode(RenderLinePlotPng({constant}, PlotOptions{})).empty());
  EXPECT_FALSE(
      Decode(RenderBarChartPng({"pf", "dr"}, {"ate"}, {{0.05}, {std::nan("")}}, PlotOptions{}))
          .empty());
}

}  // namespace
}  // namespace slamrig::scenario
