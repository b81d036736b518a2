#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "slam/grid/occupancy_grid.h"
#include "slam/types/pose2.h"

namespace slamrig::scenario {

/// A pose-graph edge to draw, world frame.
struct LiveEdge {
  Eigen::Vector2d from = Eigen::Vector2d::Zero();
  Eigen::Vector2d to = Eigen::Vector2d::Zero();
  bool loop_closure = false;  ///< drawn in kLoopClosureBgr, else thin in the estimate's colour
};

/// A mapped landmark to draw, world frame: a cross and its 3-sigma ellipse.
struct LiveLandmark {
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
};

/// One estimate to draw: its pose, its recent path and, for a particle filter, its particles,
/// for a graph estimator its edges, for a landmark estimator its landmarks; the pose's 3-sigma
/// position ellipse where it has a covariance.
struct LiveEstimate {
  std::string name;
  bool has_pose = false;  ///< false until the estimator has processed its first scan
  Pose2 pose;
  std::vector<Pose2> particles;
  std::vector<LiveEdge> edges;
  std::vector<LiveLandmark> landmarks;
  std::optional<Eigen::Matrix2d> position_covariance;  ///< of pose's x, y (world frame)
};

/// The colour of loop-closure edges in the live view (orange), blue-green-red.
inline constexpr std::uint8_t kLoopClosureBgr[3] = {0, 140, 255};

/// One drawn frame of the live view: 8-bit blue-green-red pixels, rows top to bottom.
struct LiveFrame {
  int width_px = 0;
  int height_px = 0;
  std::vector<std::uint8_t> bgr;
  /// The pixel (column, row) that world point `p` falls in.
  Eigen::Vector2i PixelOf(const Eigen::Vector2d& p) const;

  Eigen::Vector2d min_world = Eigen::Vector2d::Zero();  ///< world point at the bottom-left
  double px_per_m = 1.0;
};

/// Draws what LiveView shows, without a window (so it can be tested and saved offscreen): `map`
/// (whose frame sits at `world_from_map` in the world) in grey, the true path (its last pose is
/// the truth now) in green, each estimate with its path (`estimate_paths`, one per estimate) and
/// particles in its colour; a graph estimate's edges replace its path (the odometry edges are its
/// revised path), loop closures in kLoopClosureBgr.
LiveFrame DrawLiveFrame(double sim_time_s, const slam::OccupancyGrid& map,
                        const Pose2& world_from_map, const std::vector<Pose2>& truth_path,
                        const std::vector<LiveEstimate>& estimates,
                        const std::vector<std::vector<Pose2>>& estimate_paths);

/// A window (OpenCV highgui) showing a run as it happens: the map being built, the particles,
/// the true and estimated poses and their paths. It needs a display (an X server or Xvfb);
/// nothing else in slamrig does. Drawing is throttled to `max_fps` of wall time, and it never
/// feeds anything back into the run.
class LiveView {
 public:
  /// Opens the window; throws std::runtime_error when no display can be opened.
  LiveView(const std::string& title, double max_fps = 20.0);
  ~LiveView();
  LiveView(const LiveView&) = delete;
  LiveView& operator=(const LiveView&) = delete;

  /// Redraws when due: `map` (whose frame sits at `world_from_map` in the world) in grey, the
  /// true pose and path in green, each estimate (world frame) in its colour.
  void Update(double sim_time_s, const slam::OccupancyGrid& map, const Pose2& world_from_map,
              const Pose2& truth, const std::vector<LiveEstimate>& estimates);
  /// Shows a floor colour map (r, g, b, north up) in a second window, `title` + ": texture".
  void ShowTexture(const cv::Mat3b& colors);

 private:
  std::string title_;
  double min_period_s_;
  double last_draw_s_ = -1e9;
  bool texture_shown_ = false;
  std::vector<Pose2> truth_path_;
  std::vector<std::vector<Pose2>> estimate_paths_;
};

}  // namespace slamrig::scenario
