#include "scenarios/live_view.h"

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <opencv2/highgui.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "scenarios/plot.h"

namespace slamrig::scenario {
namespace {

constexpr int kSizePx = 720;

double WallSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

LiveView::LiveView(const std::string& title, double max_fps)
    : title_(title), min_period_s_(1.0 / max_fps) {
  const char* display = std::getenv("DISPLAY");
  if (display == nullptr || *display == '\0') {
    throw std::runtime_error("--view needs a display (DISPLAY is not set; try xvfb-run)");
  }
  cv::namedWindow(title_, cv::WINDOW_AUTOSIZE);
}

LiveView::~LiveView() {
  if (texture_shown_) cv::destroyWindow(title_ + ": texture");
  cv::destroyWindow(title_);
}

void LiveView::ShowTexture(const cv::Mat3b& colors) {
  // At most kSizePx on its longer side, whatever the world's extent.
  const double scale = static_cast<double>(kSizePx) / std::max(colors.cols, colors.rows);
  cv::Mat bgr, shown;
  cv::cvtColor(colors, bgr, cv::COLOR_RGB2BGR);
  cv::resize(bgr, shown, cv::Size(), scale, scale, cv::INTER_NEAREST);
  cv::imshow(title_ + ": texture", shown);
  texture_shown_ = true;
  cv::waitKey(1);
}

Eigen::Vector2i LiveFrame::PixelOf(const Eigen::Vector2d& p) const {
  return {static_cast<int>((p.x() - min_world.x()) * px_per_m),
          static_cast<int>(height_px - (p.y() - min_world.y()) * px_per_m)};
}

LiveFrame DrawLiveFrame(double sim_time_s, const slam::OccupancyGrid& map,
                        const Pose2& world_from_map, const std::vector<Pose2>& truth_path,
                        const std::vector<LiveEstimate>& estimates,
                        const std::vector<std::vector<Pose2>>& estimate_paths) {
  // Frame the robot's whereabouts and the landmarks with 5 m around them (the map may reach much
  // further).
  Eigen::AlignedBox2d box;
  for (const Pose2& p : truth_path) box.extend(p.translation());
  for (const auto& path : estimate_paths) {
    for (const Pose2& p : path) box.extend(p.translation());
  }
  for (const LiveEstimate& e : estimates) {
    for (const LiveLandmark& l : e.landmarks) box.extend(l.position_m);
  }
  if (box.isEmpty()) box.extend(Eigen::Vector2d::Zero());
  box.min() -= Eigen::Vector2d::Constant(5.0);
  box.max() += Eigen::Vector2d::Constant(5.0);
  LiveFrame frame;
  frame.width_px = kSizePx;
  frame.height_px = kSizePx;
  frame.min_world = box.min();
  frame.px_per_m = kSizePx / std::max(box.sizes().maxCoeff(), 10.0);
  const double scale = frame.px_per_m;
  cv::Mat image(kSizePx, kSizePx, CV_8UC3, cv::Scalar(205, 205, 205));
  const Pose2 map_from_world = world_from_map.Inverse();
  const auto px = [&](const Eigen::Vector2d& p) {
    const Eigen::Vector2i c = frame.PixelOf(p);
    return cv::Point(c.x(), c.y());
  };
  for (int row = 0; row < kSizePx; ++row) {
    auto* out = image.ptr<cv::Vec3b>(row);
    for (int col = 0; col < kSizePx; ++col) {
      const Eigen::Vector2d w(box.min().x() + (col + 0.5) / scale,
                              box.min().y() + (kSizePx - row - 0.5) / scale);
      const float l = map.LogOdds(map.WorldToCell(map_from_world * w));
      if (l == 0.0f) continue;
      const auto v =
          static_cast<std::uint8_t>(std::lround(255.0 / (1.0 + std::exp(static_cast<double>(l)))));
      out[col] = cv::Vec3b(v, v, v);
    }
  }
  auto draw_path = [&](const std::vector<Pose2>& path, const cv::Scalar& colour) {
    std::vector<cv::Point> points;
    for (const Pose2& p : path) points.push_back(px(p.translation()));
    if (points.size() >= 2) cv::polylines(image, points, false, colour, 1, cv::LINE_AA);
  };
  auto draw_pose = [&](const Pose2& p, const cv::Scalar& colour) {
    const cv::Point c = px(p.translation());
    const cv::Point tip = px(p * Eigen::Vector2d(0.5, 0.0));
    cv::circle(image, c, 5, colour, 2, cv::LINE_AA);
    cv::line(image, c, tip, colour, 2, cv::LINE_AA);
  };
  // A 3-sigma ellipse, at least 2 px across so that a confident one stays visible.
  auto draw_ellipse = [&](const Eigen::Vector2d& c, const Eigen::Matrix2d& covariance,
                          const cv::Scalar& colour) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(covariance);
    const Eigen::Vector2d axes = 3.0 * eigen.eigenvalues().cwiseMax(0.0).cwiseSqrt() * scale;
    const Eigen::Vector2d major = eigen.eigenvectors().col(1);
    // Rows grow downwards: the angle in the image is the negated world angle.
    const double angle_deg = -std::atan2(major.y(), major.x()) * 180.0 / M_PI;
    cv::ellipse(
        image, px(c),
        cv::Size(std::max(2, static_cast<int>(axes(1))), std::max(2, static_cast<int>(axes(0)))),
        angle_deg, 0.0, 360.0, colour, 1, cv::LINE_8);
  };
  const cv::Scalar truth_colour(40, 160, 40);
  draw_path(truth_path, truth_colour);
  if (!truth_path.empty()) draw_pose(truth_path.back(), truth_colour);
  const cv::Scalar loop_colour(kLoopClosureBgr[0], kLoopClosureBgr[1], kLoopClosureBgr[2]);
  for (std::size_t i = 0; i < estimates.size(); ++i) {
    const Colour c = PaletteColour(i == 2 ? 4 : i);
    const cv::Scalar colour(c.b, c.g, c.r);
    // Odometry edges first, so the loop closures stay visible on top of the chain.
    for (const LiveEdge& e : estimates[i].edges) {
      if (!e.loop_closure) cv::line(image, px(e.from), px(e.to), colour, 1, cv::LINE_8);
    }
    for (const LiveEdge& e : estimates[i].edges) {
      if (e.loop_closure) cv::line(image, px(e.from), px(e.to), loop_colour, 1, cv::LINE_8);
    }
    for (const Pose2& p : estimates[i].particles)
      cv::circle(image, px(p.translation()), 1, colour, cv::FILLED);
    if (i < estimate_paths.size() && estimates[i].edges.empty())
      draw_path(estimate_paths[i], colour);
    for (const LiveLandmark& l : estimates[i].landmarks) {
      cv::drawMarker(image, px(l.position_m), colour, cv::MARKER_CROSS, 7, 1);
      draw_ellipse(l.position_m, l.covariance, colour);
    }
    if (estimates[i].has_pose) draw_pose(estimates[i].pose, colour);
    if (estimates[i].has_pose && estimates[i].position_covariance)
      draw_ellipse(estimates[i].pose.translation(), *estimates[i].position_covariance, colour);
    cv::putText(image, estimates[i].name, {10, 44 + 20 * static_cast<int>(i)},
                cv::FONT_HERSHEY_SIMPLEX, 0.5, colour, 1, cv::LINE_AA);
  }
  char text[64];
  std::snprintf(text, sizeof(text), "t = %.1f s   truth", sim_time_s);
  cv::putText(image, text, {10, 22}, cv::FONT_HERSHEY_SIMPLEX, 0.5, truth_colour, 1, cv::LINE_AA);
  frame.bgr.assign(image.data, image.data + image.total() * image.elemSize());
  return frame;
}

void LiveView::Update(double sim_time_s, const slam::OccupancyGrid& map,
                      const Pose2& world_from_map, const Pose2& truth,
                      const std::vector<LiveEstimate>& estimates) {
  truth_path_.push_back(truth);
  estimate_paths_.resize(estimates.size());
  for (std::size_t i = 0; i < estimates.size(); ++i)
    estimate_paths_[i].push_back(estimates[i].pose);
  const double now = WallSeconds();
  if (now - last_draw_s_ < min_period_s_) return;
  last_draw_s_ = now;
  LiveFrame frame =
      DrawLiveFrame(sim_time_s, map, world_from_map, truth_path_, estimates, estimate_paths_);
  cv::imshow(title_, cv::Mat(frame.height_px, frame.width_px, CV_8UC3, frame.bgr.data()));
  cv::waitKey(1);
}

}  // namespace slamrig::scenario
