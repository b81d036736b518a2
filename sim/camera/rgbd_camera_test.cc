#include "sim/camera/rgbd_camera.h"

#include <gtest/gtest.h>

#include <cmath>

#include "sim/camera/camera_test_world.h"
#include "sim/camera/kinect_disparity.h"
#include "slam/types/error.h"
#include "slam/types/random_stream.h"

namespace slamrig::sim {
namespace {

float DepthAt(const RgbdFrame& f, int u, int v) {
  return f.depth_m[static_cast<std::size_t>(v) * f.width + u];
}

cv::Vec3b RgbAt(const RgbdFrame& f, int u, int v) {
  const std::size_t i = 3 * (static_cast<std::size_t>(v) * f.width + u);
  return {f.rgb[i], f.rgb[i + 1], f.rgb[i + 2]};
}

// Where map point `p` appears in the RGB image (pinhole model, independent of the renderer).
Eigen::Vector2d Project(const RgbdFrame& f, const Pose2& map_from_base, const Eigen::Vector3d& p) {
  Eigen::Isometry3d map_from_base3 = Eigen::Isometry3d::Identity();
  map_from_base3.translation() << map_from_base.x(), map_from_base.y(), 0.0;
  map_from_base3.linear() =
      Eigen::AngleAxisd(map_from_base.theta(), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d q = (map_from_base3 * f.BaseFromRgbOptical()).inverse() * p;
  return {f.intrinsics.fx_px * q.x() / q.z() + f.intrinsics.cx_px,
          f.intrinsics.fy_px * q.y() / q.z() + f.intrinsics.cy_px};
}

class RgbdCameraTest : public ::testing::Test {
 protected:
  std::string dir_ = ::testing::TempDir() + "/rgbd_camera_test";
  WorldSpec world_ = testing::SmallRoom();
  CameraSpec spec_ = testing::IdealCamera(dir_);
};

TEST_F(RgbdCameraTest, WallStraightAheadIsAtItsDistance) {
  RgbdCamera camera(world_, spec_);
  const RgbdFrame f = camera.Render(Pose2(0.0, 0.0, 0.0), Time::FromSeconds(1.5));
  EXPECT_EQ(f.time, Time::FromSeconds(1.5));
  ASSERT_EQ(f.width, 161);
  ASSERT_EQ(f.height, 121);
  EXPECT_DOUBLE_EQ(f.intrinsics.cx_px, 80.0);
  EXPECT_DOUBLE_EQ(f.intrinsics.cy_px, 60.0);
  // The east wall's inner face is at x = 5, the camera at x = 0.1: 4.9 m along the optical axis.
  EXPECT_NEAR(DepthAt(f, 80, 60), 4.9, 0.01);
  // Turned by 0.3 rad and moved, the centre ray meets the face at z-depth (5 - cam_x) / cos(yaw).
  const Pose2 pose(1.0, 0.3, 0.3);
  const RgbdFrame g = camera.Render(pose, Time());
  const double cam_x = 1.0 + 0.1 * std::cos(0.3);
  EXPECT_NEAR(DepthAt(g, 80, 60), (5.0 - cam_x) / std::cos(0.3), 0.01);
}

TEST_F(RgbdCameraTest, EveryWallShapeIsDrawnWhereItIs) {
  // In front of the camera (x = 0.1, looking along +x at 0.5 m height), one shape at a time.
  ShapeSpec circle;
  circle.type = ShapeType::kCircle;
  circle.center_m = {3.0, 0.0};
  circle.radius_m = 0.3;
  ShapeSpec polygon;  // a convex triangle with its west edge on x = 2
  polygon.type = ShapeType::kPolygon;
  polygon.points_m = {{2.0, -1.0}, {3.0, 0.0}, {2.0, 1.0}};
  ShapeSpec concave = polygon;  // an arrow head: not convex, drawn as edges
  concave.points_m = {{2.0, -1.0}, {3.0, 0.0}, {2.0, 1.0}, {2.5, 0.0}};
  ShapeSpec polyline;  // a thin wall on x = 1.5, drawn 5 cm thick
  polyline.type = ShapeType::kPolyline;
  polyline.points_m = {{1.5, -1.0}, {1.5, 1.0}};
  const std::pair<ShapeSpec, double> cases[] = {{circle, 3.0 - 0.3 - 0.1},
                                                {polygon, 2.0 - 0.1},
                                                {concave, 2.5 - 0.025 - 0.1},
                                                {polyline, 1.5 - 0.025 - 0.1}};
  for (const auto& [shape, expected] : cases) {
    WorldSpec world = world_;
    world.walls.push_back(shape);
    RgbdCamera camera(world, spec_);
    const RgbdFrame f = camera.Render(Pose2(), Time());
    EXPECT_NEAR(DepthAt(f, 80, 60), expected, 0.01) << ShapeTypeName(shape.type);
  }
}

TEST_F(RgbdCameraTest, FloorDepthFollowsThePitchRowByRow) {
  // The reports' Kinect: 640 x 480, f = 585.05, off-centre principal point, pitch 0.36 rad.
  CameraSpec spec = spec_;
  const CameraSpec kinect;
  spec.width_px = kinect.width_px;
  spec.height_px = kinect.height_px;
  spec.intrinsics = kinect.intrinsics;
  spec.mount = kinect.mount;
  RgbdCamera camera(world_, spec);
  EXPECT_NEAR(camera.intrinsics().cx_px, kinect.intrinsics.cx_px, 0.25);
  EXPECT_NEAR(camera.intrinsics().cy_px, kinect.intrinsics.cy_px, 0.25);
  const RgbdFrame f = camera.Render(Pose2(0.0, 0.0, 0.0), Time());
  // A ray through row v drops (v - cy) / f below the optical axis: the floor, h below the camera,
  // is at z-depth h / (sin(pitch) + cos(pitch) (v - cy) / f).
  const double h = kinect.mount.z_m, p = kinect.mount.pitch_rad;
  for (int v : {300, 380, 479}) {
    const double expected =
        h / (std::sin(p) + std::cos(p) * (v - f.intrinsics.cy_px) / f.intrinsics.fy_px);
    EXPECT_NEAR(DepthAt(f, 320, v), expected, 0.01) << "row " << v;
  }
}

TEST_F(RgbdCameraTest, FloorColoursAreTheTexturesWhereThePinholeModelPutsThem) {
  spec_.mount.pitch_rad = 0.5;
  RgbdCamera camera(world_, spec_);
  const Pose2 pose(0.8, 0.1, 0.05);
  const RgbdFrame f = camera.Render(pose, Time());
  // A point on the red zone and one on the grey floor beside it.
  const Eigen::Vector2d red = Project(f, pose, {2.3, 0.5, 0.0});
  const Eigen::Vector2d grey = Project(f, pose, {1.7, 0.5, 0.0});
  const Eigen::Vector2d mirrored = Project(f, pose, {2.3, -0.5, 0.0});  // beside the zone
  for (const auto& [px, want] :
       {std::pair{red, cv::Vec3b(200, 30, 30)}, std::pair{grey, cv::Vec3b(100, 100, 100)},
        std::pair{mirrored, cv::Vec3b(100, 100, 100)}}) {
    const int u = static_cast<int>(std::lround(px.x())), v = static_cast<int>(std::lround(px.y()));
    ASSERT_TRUE(u >= 0 && u < f.width && v >= 0 && v < f.height) << px.transpose();
    const cv::Vec3b got = RgbAt(f, u, v);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 3) << "pixel " << u << "," << v;
  }
  // The zone's near edge (x = 2) lies between the two points: the colour changes within a pixel
  // or two of where the model puts it.
  const Eigen::Vector2d edge = Project(f, pose, {2.0, 0.5, 0.0});
  const int u = static_cast<int>(std::lround(edge.x()));
  const int v_edge = static_cast<int>(std::lround(edge.y()));
  EXPECT_EQ(RgbAt(f, u, v_edge - 2)[1], 30);   // above the edge: farther, on the zone
  EXPECT_EQ(RgbAt(f, u, v_edge + 2)[1], 100);  // below: nearer, grey floor
}

TEST_F(RgbdCameraTest, DepthCameraOffsetShiftsTheDepthView) {
  spec_.depth_offset_x_m = 0.025;
  spec_.mount.pitch_rad = 0.4;
  RgbdCamera camera(world_, spec_);
  const RgbdFrame f = camera.Render(Pose2(), Time());
  EXPECT_DOUBLE_EQ(f.depth_offset_x_m, 0.025);
  // A floor point seen by the depth camera at pixel (u, v): project it into the RGB camera, it
  // lands f * offset / z to the right. Check on the floor depth: depth camera pixel row v sees the
  // floor at the same depth as the RGB camera's row v (the offset is horizontal).
  const double h = 0.5, p = 0.4;
  const double expected = h / (std::sin(p) + std::cos(p) * (100 - 60) / 150.0);
  EXPECT_NEAR(DepthAt(f, 80, 100), expected, 0.01);
}

TEST_F(RgbdCameraTest, KinectNoiseIsDeterministicPerSeedAndQuantizedInDisparity) {
  spec_.depth_model = DepthModel::kKinectDisparity;
  spec_.disparity_noise_stddev = 0.0;
  spec_.quantize_disparity = true;
  spec_.max_depth_m = 5.0;
  RgbdCamera quantized(world_, spec_);
  const RgbdFrame q = quantized.Render(Pose2(), Time());
  const double z = DepthAt(q, 80, 60);
  const double d = KinectDisparityFromDepth(4.9);
  EXPECT_DOUBLE_EQ(z, static_cast<float>(KinectDepthFromDisparity(std::round(d))));
  spec_.disparity_noise_stddev = 2.0;
  RgbdCamera a(world_, spec_, 7), b(world_, spec_, 7), c(world_, spec_, 8);
  const RgbdFrame fa = a.Render(Pose2(), Time()), fb = b.Render(Pose2(), Time());
  const RgbdFrame fc = c.Render(Pose2(), Time());
  EXPECT_EQ(fa.depth_m, fb.depth_m);
  EXPECT_NE(fa.depth_m, fc.depth_m);
  EXPECT_NE(fa.depth_m, q.depth_m);
}

TEST_F(RgbdCameraTest, DepthNoiseIsTheCamerasOwnStream) {
  // The noise of pixel after pixel (row-major, pixels that see something) is the camera stream's
  // Gaussian after Gaussian: RandomStream(seed, "camera"), shared with no other sensor.
  RgbdCamera ideal(world_, spec_);
  const RgbdFrame truth = ideal.Render(Pose2(), Time());
  spec_.depth_model = DepthModel::kKinectDisparity;
  spec_.disparity_noise_stddev = 1.5;
  spec_.quantize_disparity = false;
  RgbdCamera noisy(world_, spec_, 42);
  const RgbdFrame f = noisy.Render(Pose2(), Time());
  RandomStream stream(42, "camera");
  int checked = 0;
  for (std::size_t i = 0; i < truth.depth_m.size() && checked < 20; ++i) {
    if (truth.depth_m[i] == 0.0f) continue;
    const double d = KinectDisparityFromDepth(truth.depth_m[i]) + 1.5 * stream.Gaussian();
    EXPECT_NEAR(f.depth_m[i], KinectDepthFromDisparity(d), 1e-4) << "pixel " << i;
    ++checked;
  }
  EXPECT_EQ(checked, 20);
}

TEST_F(RgbdCameraTest, ACameraThatSeesNothingIsAnError) {
  spec_.mount.pitch_rad = -1.2;  // looking at the sky; the room has no ceiling
  RgbdCamera camera(world_, spec_);
  try {
    camera.Render(Pose2(30.0, 30.0, 0.0), Time());
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("camera 'test_cam': sees nothing"), std::string::npos)
        << e.what();
  }
}

TEST_F(RgbdCameraTest, MovingObstaclesAreDrawnWhereTheyAreSaidToBe) {
  ObstacleSpec person;
  person.name = "person";
  person.shape.type = ShapeType::kCircle;
  person.shape.radius_m = 0.3;
  person.path_m = {{3.0, 0.0}, {3.0, 1.8}};
  ObstacleSpec cart;  // a box 0.4 m deep whose origin is 0.5 m behind its centre
  cart.name = "cart";
  cart.shape.center_m = {0.5, 0.0};
  cart.shape.size_m = {0.4, 0.4};
  cart.path_m = {{1.0, -1.5}, {1.0, 1.5}};
  world_.obstacles = {person, cart};
  RgbdCamera camera(world_, spec_);
  // At first each stands at the start of its path: the person 2.6 m ahead of the camera.
  const RgbdFrame at_start = camera.Render(Pose2(0.0, 0.0, 0.0), Time());
  EXPECT_NEAR(DepthAt(at_start, 80, 60), 3.0 - 0.3 - 0.1, 0.01);
  const cv::Vec3b blue_grey(64, 89, 153);
  EXPECT_LE(cv::norm(RgbAt(at_start, 80, 60), blue_grey, cv::NORM_INF), 2.0);
  // The person moved aside and the cart into view: its near face at 1.5 - 0.2 - 0.1.
  const RgbdFrame moved = camera.Render(Pose2(0.0, 0.0, 0.0), Time(),
                                        {Eigen::Vector2d(3.0, 1.8), Eigen::Vector2d(1.0, 0.0)});
  EXPECT_NEAR(DepthAt(moved, 80, 60), 1.5 - 0.2 - 0.1, 0.01);
  // The cart gone too: the east wall behind them.
  const RgbdFrame clear = camera.Render(Pose2(0.0, 0.0, 0.0), Time(),
                                        {Eigen::Vector2d(3.0, 1.8), Eigen::Vector2d(1.0, 1.5)});
  EXPECT_NEAR(DepthAt(clear, 80, 60), 4.9, 0.01);
  EXPECT_THROW(camera.Render(Pose2(), Time(), {Eigen::Vector2d(0.0, 0.0)}), std::invalid_argument);
}

TEST_F(RgbdCameraTest, BadSpecAndMissingTextureAreErrors) {
  CameraSpec bad = spec_;
  bad.intrinsics.fx_px = 100.0;
  EXPECT_THROW(RgbdCamera(world_, bad), ConfigError);
  CameraSpec missing = spec_;
  missing.floor_image = "nowhere.png";
  EXPECT_THROW(RgbdCamera(world_, missing), ParseError);
  missing = spec_;
  missing.wall_image = "nowhere.png";
  EXPECT_THROW(RgbdCamera(world_, missing), ParseError);
}

}  // namespace
}  // namespace slamrig::sim
