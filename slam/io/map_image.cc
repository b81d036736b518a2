#include "slam/io/map_image.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "slam/io/atomic_file.h"

namespace slamrig::slam {
namespace {

// A "nice" scale-bar length (1, 2 or 5 times a power of ten) near `target_m`.
double NiceLength(double target_m) {
  const double power = std::pow(10.0, std::floor(std::log10(target_m)));
  for (const double step : {5.0, 2.0, 1.0}) {
    if (step * power <= target_m) return step * power;
  }
  return power;
}

// The world region to draw: where the walls are and the trajectories, plus `margin_m`. Walls
// are cells hit at least twice more than passed through, between the 0.5 and 99.5 percentiles, so
// that stray returns far away (a lidar's random readings, each hit once) do not shrink the
// building to a dot.
Eigen::AlignedBox2d MapRegion(const OccupancyGrid& grid,
                              const std::vector<TrajectoryOverlay>& overlays, double margin_m) {
  Eigen::AlignedBox2d region;
  std::vector<double> xs, ys;
  const float wall = std::min(2.0f * grid.options().hit_log_odds, grid.options().max_log_odds);
  for (int y = 0; y < grid.height(); ++y) {
    for (int x = 0; x < grid.width(); ++x) {
      const float l = grid.LogOdds({x, y});
      if (l >= wall) {
        const Eigen::Vector2d c = grid.CellCenter({x, y});
        xs.push_back(c.x());
        ys.push_back(c.y());
      } else if (l != 0.0f && xs.size() < 100) {
        region.extend(grid.CellCenter({x, y}));
      }
    }
  }
  if (xs.size() >= 100) {
    region.setEmpty();
    auto quantile = [](std::vector<double>& v, double q) {
      const auto k = static_cast<std::ptrdiff_t>(q * static_cast<double>(v.size() - 1));
      std::nth_element(v.begin(), v.begin() + k, v.end());
      return v[static_cast<std::size_t>(k)];
    };
    region.extend(Eigen::Vector2d(quantile(xs, 0.005), quantile(ys, 0.005)));
    region.extend(Eigen::Vector2d(quantile(xs, 0.995), quantile(ys, 0.995)));
  } else {
    for (std::size_t i = 0; i < xs.size(); ++i) region.extend(Eigen::Vector2d(xs[i], ys[i]));
  }
  for (const auto& overlay : overlays) {
    for (const auto& p : overlay.trajectory->poses()) region.extend(p.pose.translation());
  }
  if (region.isEmpty()) region.extend(Eigen::Vector2d::Zero());
  region.min() -= Eigen::Vector2d::Constant(margin_m);
  region.max() += Eigen::Vector2d::Constant(margin_m);
  return region;
}

// The legend above the map (`legend_h` pixels): title, one line per trajectory, scale bar.
void DrawLegend(const std::vector<TrajectoryOverlay>& overlays, const std::string& title,
                double px_per_m, int legend_h, cv::Mat* image) {
  cv::Mat& image_out = *image;
  const int width = image_out.cols;
  int y = 24;
  if (!title.empty()) {
    cv::putText(image_out, title, {10, y}, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(0, 0, 0), 1,
                cv::LINE_AA);
    y += 28;
  }
  for (const auto& overlay : overlays) {
    const cv::Scalar colour(overlay.blue, overlay.green, overlay.red);
    cv::line(image_out, {10, y - 6}, {40, y - 6}, colour, 3, cv::LINE_AA);
    cv::putText(image_out, overlay.label, {50, y}, cv::FONT_HERSHEY_SIMPLEX, 0.55,
                cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    y += 28;
  }
  const double bar_m = NiceLength(0.25 * width / px_per_m);
  const int bar_px = static_cast<int>(std::lround(bar_m * px_per_m));
  cv::rectangle(image_out, {10, y - 4}, {10 + bar_px, y + 4}, cv::Scalar(0, 0, 0), cv::FILLED);
  char label[32];
  std::snprintf(label, sizeof(label), "%g m", bar_m);
  cv::putText(image_out, label, {16 + bar_px, y + 5}, cv::FONT_HERSHEY_SIMPLEX, 0.55,
              cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  cv::line(image_out, {0, legend_h - 1}, {width, legend_h - 1}, cv::Scalar(160, 160, 160), 1);
}

}  // namespace

std::string RenderMapPng(const OccupancyGrid& grid, const std::vector<TrajectoryOverlay>& overlays,
                         const MapImageOptions& options) {
  const double res = grid.resolution();
  const Eigen::AlignedBox2d region = MapRegion(grid, overlays, options.margin_m);

  const int cells_x = static_cast<int>(std::ceil(region.sizes().x() / res));
  const int cells_y = static_cast<int>(std::ceil(region.sizes().y() / res));
  const int largest = std::max(cells_x, cells_y);
  const int scale = std::max(1, (options.min_size_px + largest - 1) / std::max(1, largest));
  // Pixels per metre; large maps shrink below one pixel per cell.
  double px_per_m = scale / res;
  if (largest * scale > options.max_size_px) px_per_m = options.max_size_px / (largest * res);
  const int width = std::max(1, static_cast<int>(std::lround(region.sizes().x() * px_per_m)));
  const int legend_h =
      28 * static_cast<int>(overlays.size() + (options.title.empty() ? 0 : 1)) + 40;
  const int height = std::max(1, static_cast<int>(std::lround(region.sizes().y() * px_per_m)));

  cv::Mat image(height + legend_h, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const auto to_pixel = [&](const Eigen::Vector2d& p) {
    return cv::Point2d((p.x() - region.min().x()) * px_per_m,
                       legend_h + (region.max().y() - p.y()) * px_per_m);
  };
  // Map: sample the grid at each pixel centre (nearest cell).
  for (int row = 0; row < height; ++row) {
    auto* out = image.ptr<cv::Vec3b>(row + legend_h);
    const double wy = region.max().y() - (row + 0.5) / px_per_m;
    for (int col = 0; col < width; ++col) {
      const double wx = region.min().x() + (col + 0.5) / px_per_m;
      const Eigen::Array2i cell = grid.WorldToCell({wx, wy});
      const float l = grid.LogOdds(cell);
      std::uint8_t v = 205;  // unknown: map_server grey
      if (l != 0.0f) {
        const double p = 1.0 - 1.0 / (1.0 + std::exp(static_cast<double>(l)));
        v = static_cast<std::uint8_t>(std::lround(255.0 * (1.0 - p)));
        if (l < 0.0f) v = static_cast<std::uint8_t>(std::max<int>(v, 232));  // free reads as white
      }
      out[col] = cv::Vec3b(v, v, v);
    }
  }
  // Trajectories, thick enough to see at any scale, with a start marker.
  const int thickness = std::max(2, width / 600);
  for (const auto& overlay : overlays) {
    const cv::Scalar colour(overlay.blue, overlay.green, overlay.red);
    std::vector<cv::Point> points;
    for (const auto& p : overlay.trajectory->poses()) {
      const cv::Point2d q = to_pixel(p.pose.translation());
      points.emplace_back(static_cast<int>(std::lround(q.x)), static_cast<int>(std::lround(q.y)));
    }
    if (points.size() >= 2) cv::polylines(image, points, false, colour, thickness, cv::LINE_AA);
    if (!points.empty())
      cv::circle(image, points.front(), 3 * thickness, colour, cv::FILLED, cv::LINE_AA);
  }
  // Segments (loop closures), thin, over the trajectories.
  for (const SegmentOverlay& segment : options.segments) {
    const cv::Point2d a = to_pixel(segment.a), b = to_pixel(segment.b);
    cv::line(image, {static_cast<int>(std::lround(a.x)), static_cast<int>(std::lround(a.y))},
             {static_cast<int>(std::lround(b.x)), static_cast<int>(std::lround(b.y))},
             cv::Scalar(segment.blue, segment.green, segment.red), std::max(1, thickness / 2),
             cv::LINE_AA);
  }
  DrawLegend(overlays, options.title, px_per_m, legend_h, &image);

  std::vector<std::uint8_t> png;
  if (!cv::imencode(".png", image, png)) throw std::runtime_error("PNG encoding failed");
  return std::string(png.begin(), png.end());
}

void WriteMapPng(const std::string& path, const OccupancyGrid& grid,
                 const std::vector<TrajectoryOverlay>& overlays, const MapImageOptions& options) {
  WriteFileAtomically(path, RenderMapPng(grid, overlays, options));
}

}  // namespace slamrig::slam
