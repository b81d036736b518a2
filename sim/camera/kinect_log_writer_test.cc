#include "sim/camera/kinect_log_writer.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "sim/camera/kinect_disparity.h"
#include "slam/io/npz_reader.h"

namespace slamrig::sim {
namespace {

RgbdFrame Frame(double t, float depth_m) {
  RgbdFrame f;
  f.time = Time::FromSeconds(t);
  f.width = 4;
  f.height = 3;
  for (int i = 0; i < 12; ++i) {
    f.rgb.insert(f.rgb.end(), {static_cast<std::uint8_t>(10 * i), 7, 200});
    f.depth_m.push_back(depth_m + 0.1f * static_cast<float>(i));
  }
  f.depth_m[5] = 0.0f;  // no reading
  return f;
}

TEST(KinectLogWriterTest, WritesTheEce276aLayoutThatReadsBack) {
  const std::string dir = ::testing::TempDir() + "/kinect_log_writer";
  std::filesystem::remove_all(dir);
  KinectLogWriter writer(dir, 20);
  const RgbdFrame a = Frame(1298445274.5, 1.0f), b = Frame(1298445274.6, 2.0f);
  writer.Write(a);
  writer.Write(b);
  writer.Finish();
  EXPECT_EQ(writer.frames(), 2);

  const auto npz = slam::ReadNpz(dir + "/Kinect20.npz");
  ASSERT_EQ(npz.count("rgb_time_stamps"), 1u);
  ASSERT_EQ(npz.count("disparity_time_stamps"), 1u);
  const slam::NpyArray& stamps = npz.at("rgb_time_stamps");
  EXPECT_EQ(stamps.dtype, "<f8");
  ASSERT_EQ(stamps.shape, std::vector<std::size_t>{2});
  EXPECT_EQ(stamps.values[0], a.time.seconds());
  EXPECT_EQ(stamps.values[1], b.time.seconds());

  const cv::Mat rgb = cv::imread(dir + "/dataRGBD/RGB20/rgb20_2.png", cv::IMREAD_UNCHANGED);
  ASSERT_EQ(rgb.type(), CV_8UC3);
  EXPECT_EQ(rgb.at<cv::Vec3b>(1, 2), cv::Vec3b(200, 7, 60));  // BGR on disk, pixel 6
  const cv::Mat d =
      cv::imread(dir + "/dataRGBD/Disparity20/disparity20_2.png", cv::IMREAD_UNCHANGED);
  ASSERT_EQ(d.type(), CV_16UC1);
  EXPECT_EQ(d.at<std::uint16_t>(1, 1), 2047);  // pixel 5: no reading
  // Through the reports' formula the disparity gives the depth back to its quantization
  // (0.00304 z^2 / 1.03 per disparity unit: 3 cm at 3.1 m).
  for (int i : {0, 7, 11}) {
    const double z = b.depth_m[i];
    const double back = KinectDepthFromDisparity(d.at<std::uint16_t>(i / 4, i % 4));
    EXPECT_NEAR(back, z, 0.5 * 0.00304 * z * z / 1.03 * 1.01) << "pixel " << i;
  }
}

}  // namespace
}  // namespace slamrig::sim
