#include "slam/io/ece276a_writer.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "slam/io/atomic_file.h"
#include "slam/io/ece276a_reader.h"
#include "slam/io/kinect_disparity.h"
#include "slam/io/npz_reader.h"
#include "slam/io/npz_writer.h"
#include "slam/types/error.h"
#include "tests/util/temp_dir.h"

namespace slamrig::slam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// A frame whose depth sweeps 0.4 .. 6 m over its pixels, with a hole of no readings.
RgbdFrame Frame(double t_s, int width, int height, std::uint32_t seed) {
  std::mt19937 rng(seed);
  RgbdFrame f;
  f.time = Time::FromSeconds(t_s);
  f.width = width;
  f.height = height;
  for (int i = 0; i < width * height; ++i) {
    for (int k = 0; k < 3; ++k) f.rgb.push_back(static_cast<std::uint8_t>(rng() % 256));
    f.depth_m.push_back(0.4f + 5.6f * static_cast<float>(i) / static_cast<float>(width * height));
  }
  f.depth_m[3] = 0.0f;
  return f;
}

struct Written {
  std::vector<WheelTicks> ticks;
  std::vector<ImuSample> imu;
  std::vector<LaserScan> scans;
  std::vector<RgbdFrame> frames;
};

// One second of a robot: encoders at 40 Hz, IMU at 100 Hz, scans at 40 Hz, frames at 10 Hz.
Written WriteRun(const std::string& dir, int frame_width = 8, int frame_height = 6) {
  Written w;
  Ece276aSink sink(dir, {.dataset = 7});
  std::vector<Record> records;
  for (int i = 0; i < 40; ++i) {
    const double t = 1000.0 + i / 40.0;
    w.ticks.push_back({Time::FromSeconds(t), {i, i + 1}, {-i, 2 * i}});
    LaserScan s;
    s.time = Time::FromSeconds(t + 0.001);
    s.angle_min_rad = -2.356194490192345;
    s.angle_increment_rad = 0.004363323129985824;
    s.range_min_m = 0.1;
    s.range_max_m = 30.0;
    for (int b = 0; b < 1081; ++b) s.ranges_m.push_back(0.5f + 0.01f * static_cast<float>(b + i));
    w.scans.push_back(s);
  }
  for (int i = 0; i < 100; ++i) {
    ImuSample m;
    m.time = Time::FromSeconds(1000.0 + i / 100.0 + 0.002);
    m.angular_velocity_rad_s = Eigen::Vector3d(0.01 * i, -0.02, 0.3 + 0.001 * i);
    m.linear_acceleration_m_s2 = Eigen::Vector3d(0.1, -0.2 * i, 9.81);
    w.imu.push_back(m);
  }
  for (int i = 0; i < 10; ++i) {
    w.frames.push_back(
        Frame(1000.0 + i / 10.0 + 0.003, frame_width, frame_height, static_cast<unsigned>(i)));
  }
  for (const auto& r : w.ticks) records.emplace_back(r);
  for (const auto& r : w.imu) records.emplace_back(r);
  for (const auto& r : w.scans) records.emplace_back(r);
  for (const auto& r : w.frames) records.emplace_back(r);
  std::stable_sort(records.begin(), records.end(),
                   [](const Record& a, const Record& b) { return RecordTime(a) < RecordTime(b); });
  for (const Record& r : records) sink.Add(r, nullptr);
  records.emplace_back(OdometryPose{});  // not part of the layout: skipped
  sink.Commit();
  EXPECT_EQ(sink.encoder_readings(), 40);
  EXPECT_EQ(sink.imu_samples(), 100);
  EXPECT_EQ(sink.scans(), 40);
  EXPECT_EQ(sink.frames(), 10);
  return w;
}

TEST(NpzWriterTest, ArraysReadBackWithTheirDtypesAndShapes) {
  testing::TempDir tmp;
  const std::string path = tmp.File("a.npz");
  WriteFileAtomically(path, MakeNpz({{"m", "<i4", {2, 3}, {1, -2, 3, 4, 5, -6}},
                                     {"f", "<f4", {3}, {0.5, 1.25, -3.0}},
                                     {"s", "<f8", {}, {3.141592653589793}},
                                     {"h", "<i2", {2}, {-32768, 32767}}}));
  const auto a = ReadNpz(path);
  EXPECT_EQ(a.at("m").dtype, "<i4");
  EXPECT_EQ(a.at("m").shape, (std::vector<std::size_t>{2, 3}));
  EXPECT_EQ(a.at("m").values, (std::vector<double>{1, -2, 3, 4, 5, -6}));
  EXPECT_EQ(a.at("f").dtype, "<f4");
  EXPECT_EQ(a.at("f").values, (std::vector<double>{0.5, 1.25, -3.0}));
  EXPECT_TRUE(a.at("s").shape.empty());
  EXPECT_EQ(a.at("s").values, (std::vector<double>{3.141592653589793}));
  EXPECT_EQ(a.at("h").values, (std::vector<double>{-32768, 32767}));
  EXPECT_THROW(MakeNpz({{"x", "<i2", {1}, {40000}}}), std::invalid_argument);
  EXPECT_THROW(MakeNpz({{"x", "<f8", {2, 2}, {1, 2, 3}}}), std::invalid_argument);
  EXPECT_THROW(MakeNpz({{"x", "<c16", {1}, {1}}}), std::invalid_argument);
}

TEST(Ece276aWriterTest, TheReportsArraysHaveTheirLayout) {
  testing::TempDir tmp;
  const Written w = WriteRun(tmp.path().string());
  const auto enc = ReadNpz(tmp.File("Encoders7.npz"));
  ASSERT_EQ(enc.at("counts").shape, (std::vector<std::size_t>{4, 40}));
  // [FR, FL, RR, RL] rows: right {FR, RR} = {i, i + 1}, left {FL, RL} = {-i, 2i}.
  EXPECT_EQ(enc.at("counts").values[5], 5);
  EXPECT_EQ(enc.at("counts").values[40 + 5], -5);
  EXPECT_EQ(enc.at("counts").values[80 + 5], 6);
  EXPECT_EQ(enc.at("counts").values[120 + 5], 10);
  const auto imu = ReadNpz(tmp.File("Imu7.npz"));
  ASSERT_EQ(imu.at("linear_acceleration").shape, (std::vector<std::size_t>{3, 100}));
  EXPECT_NEAR(imu.at("linear_acceleration").values[200], 9.81 / 9.80665, 1e-12);  // in g
  const auto hok = ReadNpz(tmp.File("Hokuyo7.npz"));
  ASSERT_EQ(hok.at("ranges").shape, (std::vector<std::size_t>{1081, 40}));
  EXPECT_EQ(hok.at("ranges").dtype, "<f4");
  EXPECT_FLOAT_EQ(static_cast<float>(hok.at("ranges").values[10 * 40 + 3]),
                  w.scans[3].ranges_m[10]);
  EXPECT_NEAR(hok.at("angle_max").values[0], 2.356194490192345, 1e-12);
  const auto kin = ReadNpz(tmp.File("Kinect7.npz"));
  EXPECT_EQ(kin.at("rgb_time_stamps").values, kin.at("disparity_time_stamps").values);
  const cv::Mat d =
      cv::imread(tmp.File("dataRGBD/Disparity7/disparity7_2.png"), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(d.type(), CV_16UC1);
  EXPECT_EQ(d.at<std::uint16_t>(0, 3), kKinectNoDisparity);  // pixel 3: no reading
  const cv::Mat rgb = cv::imread(tmp.File("dataRGBD/RGB7/rgb7_2.png"), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(rgb.type(), CV_8UC3);
  EXPECT_EQ(rgb.at<cv::Vec3b>(0, 1)[0], w.frames[1].rgb[5]);  // BGR on disk
  EXPECT_FALSE(fs::exists(tmp.File("dataRGBD/RGB7.partial")));
}

TEST(Ece276aWriterTest, WhatIsWrittenReadsBackAsTheSameRecords) {
  testing::TempDir tmp;
  const Written w = WriteRun(tmp.path().string());
  const Ece276aFiles files = FindEce276aFiles(tmp.File("Kinect7.npz"));
  EXPECT_EQ(files.dataset, 7);
  const Dataset data = ReadEce276a(files);
  ASSERT_EQ(data.records.size(), 40u + 100u + 40u + 10u);
  for (std::size_t i = 1; i < data.records.size(); ++i) {
    ASSERT_FALSE(RecordTime(data.records[i]) < RecordTime(data.records[i - 1])) << i;
  }
  std::size_t t = 0, m = 0, s = 0, f = 0;
  for (const Record& r : data.records) {
    if (const auto* ticks = std::get_if<WheelTicks>(&r)) {
      EXPECT_EQ(ticks->time, w.ticks[t].time);
      EXPECT_EQ(ticks->right_ticks, w.ticks[t].right_ticks);
      EXPECT_EQ(ticks->left_ticks, w.ticks[t].left_ticks);
      ++t;
    } else if (const auto* imu = std::get_if<ImuSample>(&r)) {
      EXPECT_EQ(imu->time, w.imu[m].time);
      EXPECT_EQ(imu->angular_velocity_rad_s, w.imu[m].angular_velocity_rad_s);
      EXPECT_TRUE(imu->linear_acceleration_m_s2.isApprox(w.imu[m].linear_acceleration_m_s2, 1e-14));
      ++m;
    } else if (const auto* scan = std::get_if<LaserScan>(&r)) {
      EXPECT_EQ(scan->time, w.scans[s].time);
      EXPECT_EQ(scan->ranges_m, w.scans[s].ranges_m);
      EXPECT_NEAR(scan->angle_increment_rad, w.scans[s].angle_increment_rad, 1e-15);
      EXPECT_EQ(scan->range_max_m, 30.0);
      ++s;
    } else if (const auto* frame = std::get_if<RgbdFrame>(&r)) {
      const RgbdFrame& in = w.frames[f];
      EXPECT_EQ(frame->time, in.time);
      ASSERT_EQ(frame->width, in.width);
      ASSERT_EQ(frame->height, in.height);
      EXPECT_EQ(frame->rgb, in.rgb);
      for (std::size_t p = 0; p < in.depth_m.size(); ++p) {
        const double z = in.depth_m[p];
        // Within the disparity's reach (0.311 m .. 2047 units) the depth comes back to half a
        // disparity unit, dz = 0.00304 z^2 / 1.03 per unit; the hole stays a hole.
        if (z == 0.0 || z < 0.32) {
          EXPECT_EQ(frame->depth_m[p], 0.0f) << "pixel " << p;
        } else {
          EXPECT_NEAR(frame->depth_m[p], z, 0.5 * 0.00304 * z * z / 1.03 * 1.001) << "pixel " << p;
        }
      }
      EXPECT_EQ(frame->depth_offset_x_m, 0.025);
      EXPECT_EQ(frame->intrinsics.fx_px, 585.05108211);
      ++f;
    }
  }
  EXPECT_EQ(f, 10u);
}

TEST(Ece276aWriterTest, RgbImagesArePairedByNearestStampAndEveryKthFrameRead) {
  testing::TempDir tmp;
  WriteRun(tmp.path().string());
  // Real logs stamp the two cameras apart: disparity at the written times, RGB 20 ms later, and
  // one RGB image fewer.
  const auto kin = ReadNpz(tmp.File("Kinect7.npz"));
  std::vector<double> td = kin.at("disparity_time_stamps").values, tr = td;
  tr.pop_back();
  for (double& t : tr) t += 0.02;
  WriteFileAtomically(tmp.File("Kinect7.npz"), MakeNpz({{"disparity_time_stamps", "<f8", {10}, td},
                                                        {"rgb_time_stamps", "<f8", {9}, tr}}));
  Ece276aReadOptions options;
  options.kinect_every = 3;
  const Dataset data = ReadEce276a(FindEce276aFiles(tmp.File("7")), options);
  std::vector<const RgbdFrame*> frames;
  for (const Record& r : data.records) {
    if (const auto* f = std::get_if<RgbdFrame>(&r)) frames.push_back(f);
  }
  ASSERT_EQ(frames.size(), 4u);  // disparity images 1, 4, 7, 10
  const cv::Mat rgb9 = cv::imread(tmp.File("dataRGBD/RGB7/rgb7_9.png"), cv::IMREAD_COLOR);
  EXPECT_EQ(frames[3]->time, Time::FromSeconds(td[9]));
  EXPECT_EQ(frames[3]->rgb[0], rgb9.at<cv::Vec3b>(0, 0)[2]);  // the last RGB image is nearest
  const cv::Mat rgb4 = cv::imread(tmp.File("dataRGBD/RGB7/rgb7_4.png"), cv::IMREAD_COLOR);
  EXPECT_EQ(frames[1]->rgb[0], rgb4.at<cv::Vec3b>(0, 0)[2]);
  EXPECT_THAT(data.notes.back(), HasSubstr("4 Kinect frames"));
  EXPECT_THAT(data.notes.back(), HasSubstr("at most 80 ms"));
}

TEST(Ece276aWriterTest, AMissingOrBrokenImageIsOneErrorNamingIt) {
  testing::TempDir tmp;
  WriteRun(tmp.path().string());
  const Ece276aFiles files = FindEce276aFiles(tmp.File("Encoders7.npz"));
  const auto message = [&] {
    try {
      ReadEce276a(files);
    } catch (const ParseError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string disparity = tmp.File("dataRGBD/Disparity7/disparity7_5.png");
  const std::string rgb = tmp.File("dataRGBD/RGB7/rgb7_6.png");
  fs::rename(disparity, disparity + ".away");
  EXPECT_THAT(message(), HasSubstr(disparity + ": missing (disparity image 5 of "));
  fs::rename(disparity + ".away", disparity);

  std::string bytes;
  {
    std::ifstream in(rgb, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  std::ofstream(rgb, std::ios::binary) << bytes.substr(0, 20);  // truncated
  EXPECT_THAT(message(), HasSubstr(rgb + ": not an image OpenCV can read"));
  // The colour image where the disparity belongs: wrong type, named.
  fs::copy_file(tmp.File("dataRGBD/RGB7/rgb7_1.png"), disparity,
                fs::copy_options::overwrite_existing);
  EXPECT_THAT(message(), HasSubstr(disparity + ": expected a 16-bit one-channel PNG"));
  // A frame of another size.
  cv::imwrite(disparity, cv::Mat_<std::uint16_t>(3, 3, std::uint16_t{500}));
  EXPECT_THAT(message(), HasSubstr(disparity + ": 3 x 3 pixels, the frames before it 8 x 6"));

  WriteFileAtomically(tmp.File("Kinect7.npz"),
                      MakeNpz({{"disparity_time_stamps", "<f8", {2}, {2.0, 1.0}},
                               {"rgb_time_stamps", "<f8", {1}, {1.0}}}));
  EXPECT_THAT(message(), HasSubstr("Kinect7.npz: disparity_time_stamps[1]: earlier than"));
  WriteFileAtomically(tmp.File("Kinect7.npz"),
                      MakeNpz({{"disparity_time_stamps", "<f8", {1}, {2.0}}}));
  EXPECT_THAT(message(), HasSubstr("Kinect7.npz: no array 'rgb_time_stamps'"));
}

TEST(Ece276aWriterTest, RecordsTheLayoutCannotHoldAreConfigErrors) {
  testing::TempDir tmp;
  Ece276aSink sink(tmp.path().string());
  EXPECT_THROW(sink.Add(WheelTicks{Time{}, {1, 2, 3}, {1, 2, 3}}, nullptr), ConfigError);
  LaserScan a;
  a.ranges_m.assign(10, 1.0f);
  sink.Add(a, nullptr);
  LaserScan b = a;
  b.ranges_m.resize(11);
  EXPECT_THROW(sink.Add(b, nullptr), ConfigError);
}

TEST(Ece276aWriterTest, ARewriteWithoutTheCameraLeavesNoStaleKinectFiles) {
  testing::TempDir tmp;
  WriteRun(tmp.path().string());
  {
    Ece276aSink sink(tmp.path().string(), {.dataset = 7});
    sink.Add(WheelTicks{Time{}, {1}, {2}}, nullptr);
    sink.Commit();
  }
  EXPECT_TRUE(fs::exists(tmp.File("Encoders7.npz")));
  EXPECT_FALSE(fs::exists(tmp.File("Kinect7.npz")));
  EXPECT_FALSE(fs::exists(tmp.File("Hokuyo7.npz")));
  EXPECT_FALSE(fs::exists(tmp.File("dataRGBD")));
  const Dataset data = ReadEce276a(FindEce276aFiles(tmp.File("7")));
  ASSERT_EQ(data.records.size(), 1u);
  // One wheel a side fills both of the side's columns.
  EXPECT_EQ(std::get<WheelTicks>(data.records[0]).right_ticks, (std::vector<std::int32_t>{1, 1}));
  {
    Ece276aSink uncommitted(tmp.path().string(), {.dataset = 7});
    uncommitted.Add(Frame(1.0, 4, 4, 1), nullptr);
    EXPECT_TRUE(fs::exists(tmp.File("dataRGBD/RGB7.partial/rgb7_1.png")));
  }
  EXPECT_FALSE(fs::exists(tmp.File("dataRGBD/RGB7.partial")));
}

}  // namespace
}  // namespace slamrig::slam
