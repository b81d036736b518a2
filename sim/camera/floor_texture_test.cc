#include "sim/camera/floor_texture.h"

#include <gtest/gtest.h>

#include "sim/camera/camera_test_world.h"
#include "slam/types/error.h"

namespace slamrig::sim {
namespace {

TEST(FloorTextureTest, ZonesPaintTheirImageOverTheFloorImage) {
  const std::string dir = ::testing::TempDir() + "/floor_texture_zones";
  const WorldSpec world = testing::SmallRoom();
  CameraSpec camera = testing::IdealCamera(dir);
  const FloorTexture floor(world, camera);
  EXPECT_EQ(floor.ColorAt({2.5, 0.5}), cv::Vec3b(200, 30, 30));
  EXPECT_EQ(floor.ColorAt({2.5, -0.5}), cv::Vec3b(100, 100, 100));
  EXPECT_EQ(floor.ColorAt({2.5, 1.2}), cv::Vec3b(100, 100, 100));
  EXPECT_EQ(floor.ColorAt({0.0, 0.0}), cv::Vec3b(100, 100, 100));
  // The texture covers the walls (x -1.2..5.2, y -2.2..2.2) plus 1 m.
  EXPECT_NEAR(floor.min_m().x(), -2.2, 1e-9);
  EXPECT_NEAR(floor.min_m().y(), -3.2, 1e-9);
  EXPECT_GE(floor.max_m().x(), 6.2 - 1e-9);
  EXPECT_GE(floor.max_m().y(), 3.2 - 1e-9);
}

TEST(FloorTextureTest, ImageRowZeroIsTheNorthEdgeOfEachTile) {
  const std::string dir = ::testing::TempDir() + "/floor_texture_rows";
  WorldSpec world = testing::SmallRoom();
  CameraSpec camera = testing::IdealCamera(dir);
  // Top half blue, bottom half green; one copy per 2 m: y in [0, 1) is green, [1, 2) blue.
  cv::Mat3b bgr(8, 8, cv::Vec3b(0, 255, 0));
  bgr.rowRange(0, 4).setTo(cv::Vec3b(255, 0, 0));
  cv::imwrite(dir + "/halves.png", bgr);
  camera.floor_image = "halves.png";
  camera.floor_tile_m = 2.0;
  const FloorTexture floor(world, camera);
  EXPECT_EQ(floor.ColorAt({0.5, 0.5}), cv::Vec3b(0, 255, 0));
  EXPECT_EQ(floor.ColorAt({0.5, 1.5}), cv::Vec3b(0, 0, 255));
  EXPECT_EQ(floor.ColorAt({0.5, -0.5}), cv::Vec3b(0, 0, 255));  // [-1, 0) is the upper half
}

TEST(FloorTextureTest, TruthIsTheCellMeanAndWallsAreNotFloor) {
  const std::string dir = ::testing::TempDir() + "/floor_texture_truth";
  const FloorTexture floor(testing::SmallRoom(), testing::IdealCamera(dir));
  slam::TextureMapOptions o;
  o.resolution_m = 0.5;
  o.min_m = {1.5, -2.5};
  o.max_m = {3.0, 0.5};
  const cv::Mat3b truth = floor.TruthColors(o);
  const cv::Mat1b mask = floor.FloorMask(o);
  ASSERT_EQ(truth.cols, 3);
  ASSERT_EQ(truth.rows, 6);
  // Row 0 is y in [0, 0.5): x in [1.5, 2) is grey, [2, 2.5) red.
  EXPECT_EQ(truth(0, 0), cv::Vec3b(100, 100, 100));
  EXPECT_EQ(truth(0, 1), cv::Vec3b(200, 30, 30));
  EXPECT_EQ(mask(0, 1), 255);
  // Row 5 is y in [-2.5, -2): its centre y = -2.25 is outside the room, not in a wall; row 4's
  // centre, y = -1.75, is floor. The wall covers y in [-2.2, -2.0].
  EXPECT_EQ(mask(4, 0), 255);
  slam::TextureMapOptions wall = o;
  wall.min_m = {1.5, -2.2};
  wall.max_m = {2.0, -2.0};
  wall.resolution_m = 0.2;
  EXPECT_EQ(floor.FloorMask(wall)(0, 0), 0);
}

TEST(FloorTextureTest, AMissingImageNamesTheFileAndTheField) {
  const std::string dir = ::testing::TempDir() + "/floor_texture_missing";
  CameraSpec camera = testing::IdealCamera(dir);
  camera.zones[0].image = "no_such.png";
  try {
    FloorTexture floor(testing::SmallRoom(), camera);
    FAIL() << "expected a ParseError";
  } catch (const ParseError& e) {
    EXPECT_NE(std::string(e.what()).find(dir + "/no_such.png: camera.zones[0].image: texture "
                                               "file not found"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace slamrig::sim
