#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "slam/grid/occupancy_grid.h"
#include "slam/types/pose2.h"

namespace slamrig::scenario {

/// One estimate to draw: its pose, its recent path and, for a particle filter, its particles.
struct LiveEstimate {
  std::string name;
  bool has_pose = false;  ///< false until the estimator has processed its first scan
  Pose2 pose;
  std::vector<Pose2> particles;
};

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
