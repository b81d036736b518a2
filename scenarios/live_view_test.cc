#include "scenarios/live_view.h"

#include <gtest/gtest.h>

#include "scenarios/plot.h"

namespace slamrig::scenario {
namespace {

struct Bgr {
  int b = 0, g = 0, r = 0;
};

Bgr PixelAt(const LiveFrame& frame, const Eigen::Vector2d& world) {
  const Eigen::Vector2i c = frame.PixelOf(world);
  const std::size_t i = 3 * (static_cast<std::size_t>(c.y()) * frame.width_px + c.x());
  return {frame.bgr[i], frame.bgr[i + 1], frame.bgr[i + 2]};
}

bool IsLoopColour(const Bgr& p) {
  return p.b == kLoopClosureBgr[0] && p.g == kLoopClosureBgr[1] && p.r == kLoopClosureBgr[2];
}

int CountLoopColour(const LiveFrame& frame) {
  int n = 0;
  for (std::size_t i = 0; i + 2 < frame.bgr.size(); i += 3) {
    n += IsLoopColour({frame.bgr[i], frame.bgr[i + 1], frame.bgr[i + 2]});
  }
  return n;
}

// A graph estimate whose odometry chain runs along y = 0 and y = 4 (a square's two sides) and
// whose one loop closure joins (0, 0) and (0, 4), well away from the truth (y = -4).
LiveEstimate GraphEstimate() {
  LiveEstimate e;
  e.name = "graph";
  e.has_pose = true;
  e.pose = Pose2(6.0, 4.0, 0.0);
  e.edges = {{{0.0, 0.0}, {6.0, 0.0}, false},
             {{6.0, 0.0}, {6.0, 4.0}, false},
             {{6.0, 4.0}, {0.5, 4.0}, false},
             {{0.0, 0.0}, {0.0, 4.0}, true}};
  return e;
}

TEST(LiveViewTest, DrawsOdometryEdgesInTheEstimateColourAndLoopClosuresInTheirOwn) {
  const slam::OccupancyGrid map{slam::OccupancyGridOptions{}};
  const std::vector<Pose2> truth = {Pose2(0.0, -4.0, 0.0), Pose2(6.0, -4.0, 0.0)};
  const LiveEstimate graph = GraphEstimate();
  const LiveFrame frame =
      DrawLiveFrame(12.0, map, Pose2(), truth, {graph}, {{Pose2(), Pose2(6.0, 4.0, 0.0)}});
  ASSERT_EQ(frame.bgr.size(), 3u * frame.width_px * frame.height_px);

  const Colour c = PaletteColour(0);
  const Bgr odometry = PixelAt(frame, {3.0, 0.0});
  EXPECT_EQ(odometry.b, c.b);
  EXPECT_EQ(odometry.g, c.g);
  EXPECT_EQ(odometry.r, c.r);
  EXPECT_TRUE(IsLoopColour(PixelAt(frame, {0.0, 2.0})));
  // The edges are thin lines: a metre beside them is the background.
  const Bgr beside = PixelAt(frame, {3.0, 2.0});
  EXPECT_EQ(beside.b, 205);
  EXPECT_EQ(beside.r, 205);
  // The loop closure's colour appears along it and nowhere else (about one pixel per row).
  const int rows_spanned = frame.PixelOf({0.0, 0.0}).y() - frame.PixelOf({0.0, 4.0}).y();
  EXPECT_GE(CountLoopColour(frame), rows_spanned);
  EXPECT_LE(CountLoopColour(frame), 2 * rows_spanned + 2);
}

TEST(LiveViewTest, AnEstimateWithoutEdgesDrawsNoLoopClosure) {
  const slam::OccupancyGrid map{slam::OccupancyGridOptions{}};
  LiveEstimate pf;
  pf.name = "pf";
  pf.has_pose = true;
  pf.particles = {Pose2(1.0, 1.0, 0.0), Pose2(1.1, 1.0, 0.0)};
  const LiveFrame frame = DrawLiveFrame(1.0, map, Pose2(), {Pose2()}, {pf}, {{Pose2()}});
  EXPECT_EQ(CountLoopColour(frame), 0);
}

}  // namespace
}  // namespace slamrig::scenario

namespace slamrig::scenario {
namespace {

// A landmark estimate: each landmark's 3-sigma ellipse (here 0.5 m sigma along x, 0.1 m along y)
// is drawn in the estimate's colour at 1.5 m beside the landmark on the x axis, not 1.5 m
// beside it on the y axis.
TEST(LiveViewTest, DrawsLandmarksWithTheirCovarianceEllipses) {
  const slam::OccupancyGrid map{slam::OccupancyGridOptions{}};
  LiveEstimate e;
  e.name = "ekf-slam";
  e.has_pose = true;
  e.pose = Pose2(0.0, 0.0, 0.0);
  e.landmarks.push_back({{4.0, 4.0}, Eigen::Vector2d(0.25, 0.01).asDiagonal()});
  const LiveFrame frame = DrawLiveFrame(1.0, map, Pose2(), {Pose2()}, {e}, {{Pose2()}});
  const Colour c = PaletteColour(0);
  const auto is_estimate = [&](const Eigen::Vector2d& p) {
    const Eigen::Vector2i px = frame.PixelOf(p);
    bool found = false;
    // The ellipse is a 1 px line: look in a 3 x 3 neighbourhood.
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const std::size_t i =
            3 * (static_cast<std::size_t>(px.y() + dy) * frame.width_px + px.x() + dx);
        found =
            found || (frame.bgr[i] == c.b && frame.bgr[i + 1] == c.g && frame.bgr[i + 2] == c.r);
      }
    }
    return found;
  };
  EXPECT_TRUE(is_estimate({5.5, 4.0}));
  EXPECT_TRUE(is_estimate({2.5, 4.0}));
  EXPECT_FALSE(is_estimate({4.0, 5.5}));
  EXPECT_TRUE(is_estimate({4.0, 4.3}));
}

}  // namespace
}  // namespace slamrig::scenario
