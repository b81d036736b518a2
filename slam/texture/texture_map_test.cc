#include "slam/texture/texture_map.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "slam/types/error.h"

namespace slamrig::slam {
namespace {

// A camera 1 m above the floor looking straight down (pitch pi/2) with a 0 m depth offset: pixel
// (u, v) sees the floor point x = mount_x - (v - cy) h / f, y = mount_y - (u - cx) h / f.
RgbdFrame DownwardFrame(int width, int height, double h) {
  RgbdFrame f;
  f.width = width;
  f.height = height;
  f.intrinsics = {100.0, 100.0, (width - 1) / 2.0, (height - 1) / 2.0};
  f.base_from_camera = {0.5, 0.2, h, 0.0, std::numbers::pi / 2, 0.0};
  f.rgb.assign(static_cast<std::size_t>(width) * height * 3, 0);
  f.depth_m.assign(static_cast<std::size_t>(width) * height, static_cast<float>(h));
  return f;
}

TEST(TextureMapTest, DownwardCameraPutsEachPixelWhereThePinholeModelSays) {
  RgbdFrame f = DownwardFrame(41, 31, 1.0);
  // Colour every pixel by its (u, v) so each cell's mean says which pixels landed there.
  for (int v = 0; v < f.height; ++v) {
    for (int u = 0; u < f.width; ++u) {
      const std::size_t i = 3 * (static_cast<std::size_t>(v) * f.width + u);
      f.rgb[i] = static_cast<std::uint8_t>(u);
      f.rgb[i + 1] = static_cast<std::uint8_t>(v);
      f.rgb[i + 2] = 200;
    }
  }
  TextureMapOptions o;
  o.resolution_m = 0.01;  // one pixel footprint (h / f = 1 cm): one pixel per cell
  o.min_m = {-2.0, -2.0};
  o.max_m = {2.0, 2.0};
  TextureMap map(o);
  const Pose2 pose(0.3, -0.4, 0.5);
  EXPECT_EQ(map.Insert(f, pose), f.width * f.height);
  const cv::Mat3b colors = map.Colors();
  const cv::Mat1b observed = map.Observed();
  // Independent computation for a few pixels: the point in the base frame, then the pose.
  for (const auto& [u, v] : {std::pair{0, 0}, {40, 0}, {20, 15}, {7, 29}}) {
    const double bx = 0.5 - (v - f.intrinsics.cy_px) / 100.0;
    const double by = 0.2 - (u - f.intrinsics.cx_px) / 100.0;
    const Eigen::Vector2d world = pose * Eigen::Vector2d(bx, by);
    int col = 0, row = 0;
    ASSERT_TRUE(map.CellOf(world.x(), world.y(), &col, &row));
    ASSERT_EQ(observed(row, col), 255) << u << "," << v;
    // Cells are as large as a pixel's footprint, so a neighbour may share the cell: the mean
    // stays within one of the pixel's own code.
    EXPECT_NEAR(colors(row, col)[0], u, 1.0) << u << "," << v;
    EXPECT_NEAR(colors(row, col)[1], v, 1.0) << u << "," << v;
    EXPECT_EQ(colors(row, col)[2], 200);
  }
}

TEST(TextureMapTest, PointsAboveTheFloorAndFarOnesAreDropped) {
  RgbdFrame f = DownwardFrame(10, 10, 1.0);
  // Depth 0.8 m puts the points 0.2 m above the floor: not floor.
  std::fill(f.depth_m.begin(), f.depth_m.begin() + 50, 0.8f);
  f.depth_m[60] = 0.0f;  // no reading
  TextureMapOptions o;
  o.min_m = {-2.0, -2.0};
  o.max_m = {2.0, 2.0};
  TextureMap map(o);
  EXPECT_EQ(map.Insert(f, Pose2()), 49);
  o.max_depth_m = 0.9;  // now the floor is too far
  TextureMap near_only(o);
  EXPECT_EQ(near_only.Insert(f, Pose2()), 0);
}

TEST(TextureMapTest, DepthOffsetSamplesTheShiftedRgbColumn) {
  RgbdFrame f = DownwardFrame(60, 20, 1.0);
  f.depth_offset_x_m = 0.05;  // 5 px at f = 100 px and 1 m
  for (int v = 0; v < f.height; ++v) {
    for (int u = 0; u < f.width; ++u) {
      f.rgb[3 * (static_cast<std::size_t>(v) * f.width + u)] = static_cast<std::uint8_t>(u);
    }
  }
  TextureMapOptions o;
  o.resolution_m = 0.01;
  o.min_m = {-2.0, -2.0};
  o.max_m = {2.0, 2.0};
  TextureMap map(o);
  // The depth camera is 5 cm to the right of the RGB camera: a depth pixel u sees the point the
  // RGB camera sees at u + 5; the last 5 columns fall off the RGB image.
  EXPECT_EQ(map.Insert(f, Pose2()), 55 * 20);
  const CameraIntrinsics& k = f.intrinsics;
  const int u = 10, v = 10;
  // Depth optical point, then base frame (camera looking down, see DownwardFrame), offset included.
  const double xo = (u - k.cx_px) / 100.0 + 0.05;
  const double yo = (v - k.cy_px) / 100.0;
  int col = 0, row = 0;
  ASSERT_TRUE(map.CellOf(0.5 - yo, 0.2 - xo, &col, &row));
  EXPECT_NEAR(map.Colors()(row, col)[0], u + 5, 1.0);
}

TEST(TextureMapTest, RejectsBadOptionsAndFrames) {
  TextureMapOptions o;
  o.resolution_m = 0.0;
  EXPECT_THROW(TextureMap{o}, ConfigError);
  o = TextureMapOptions();
  o.max_m = {-1.0, 5.0};
  EXPECT_EQ(o.Validate().front(), "texture.max_m.x = -1; must be > texture.min_m.x");
  TextureMap map{TextureMapOptions()};
  RgbdFrame f = DownwardFrame(4, 4, 1.0);
  f.rgb.pop_back();
  EXPECT_THROW(map.Insert(f, Pose2()), ConfigError);
}

TEST(TextureMapTest, RasterRowZeroIsTheTop) {
  TextureMapOptions o;
  o.resolution_m = 0.5;
  o.min_m = {1.0, 2.0};
  o.max_m = {3.0, 3.0};
  TextureMap map(o);
  EXPECT_EQ(o.width(), 4);
  EXPECT_EQ(o.height(), 2);
  int col = 0, row = 0;
  ASSERT_TRUE(map.CellOf(1.1, 2.9, &col, &row));
  EXPECT_EQ(col, 0);
  EXPECT_EQ(row, 0);
  ASSERT_TRUE(map.CellOf(2.9, 2.1, &col, &row));
  EXPECT_EQ(col, 3);
  EXPECT_EQ(row, 1);
  EXPECT_FALSE(map.CellOf(0.9, 2.5, &col, &row));
  EXPECT_TRUE(map.CellCenter(3, 1).isApprox(Eigen::Vector2d(2.75, 2.25)));
}

}  // namespace
}  // namespace slamrig::slam
