#include "slam/io/bag/ros_messages.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <limits>
#include <numbers>
#include <random>

#include "slam/io/bag/cdr.h"
#include "slam/io/bag/mcap_records.h"

namespace slamrig::slam {
namespace {

// Expected payloads are spelled out field by field; every padding run is placed by hand from
// the CDR rule (align to the primitive's size, counted from the byte after the 4-byte header).
struct Bytes {
  std::string s{"\x00\x01\x00\x00", 4};
  Bytes& U32(std::uint32_t v) { return Raw(&v, 4); }
  Bytes& I32(std::int32_t v) { return Raw(&v, 4); }
  Bytes& F32(float v) { return Raw(&v, 4); }
  Bytes& F64(double v) { return Raw(&v, 8); }
  Bytes& Str(const char* text) {  // length with NUL, bytes, NUL
    U32(static_cast<std::uint32_t>(std::strlen(text) + 1));
    s.append(text, std::strlen(text) + 1);
    return *this;
  }
  Bytes& Pad(std::size_t n) {
    s.append(n, '\0');
    return *this;
  }
  Bytes& Raw(const void* p, std::size_t n) {
    s.append(static_cast<const char*>(p), n);
    return *this;
  }
  // Offset of the next byte, counted after the header.
  std::size_t Body() const { return s.size() - 4; }
};

TEST(CdrTest, ClockBytes) {
  std::string out;
  EncodeClock(Time{1'500'000'000}, &out);
  const std::string want("\x00\x01\x00\x00\x01\x00\x00\x00\x00\x65\xcd\x1d", 12);
  EXPECT_EQ(out, want);
  EXPECT_EQ(DecodeClock(out), Time{1'500'000'000});
}

TEST(CdrTest, LaserScanBytes) {
  LaserScan scan;
  scan.time = Time{2'000'000'007};
  scan.angle_min_rad = -0.5;
  scan.angle_increment_rad = 1.0;
  scan.time_increment_s = 0.25;
  scan.range_min_m = 0.125;
  scan.range_max_m = 8.0;
  scan.ranges_m = {1.5f, 8.0f};
  std::string out;
  EncodeLaserScan(scan, "ls", &out);
  Bytes b;
  b.I32(2).U32(7).Str("ls");  // 8 + 4 + 3 = 15 bytes
  ASSERT_EQ(b.Body(), 15u);
  b.Pad(1);  // float32 at 16
  b.F32(-0.5f).F32(0.5f).F32(1.0f).F32(0.25f).F32(0.5f).F32(0.125f).F32(8.0f);
  b.U32(2).F32(1.5f).F32(8.0f).U32(0);
  EXPECT_EQ(out, b.s);
  std::string frame;
  const LaserScan back = DecodeLaserScan(out, &frame);
  EXPECT_EQ(frame, "ls");
  EXPECT_EQ(back.time, scan.time);
  EXPECT_EQ(back.angle_min_rad, -0.5);
  EXPECT_EQ(back.angle_increment_rad, 1.0);
  EXPECT_EQ(back.time_increment_s, 0.25);
  EXPECT_EQ(back.range_min_m, 0.125);
  EXPECT_EQ(back.range_max_m, 8.0);
  EXPECT_EQ(back.ranges_m, scan.ranges_m);
}

TEST(CdrTest, JointStateBytesAlignDoublesAfterTheHeader) {
  std::string out;
  const std::vector<double> positions = {2.0};
  EncodeJointState(Time{0}, {"a"}, positions, &out);
  Bytes b;
  b.I32(0).U32(0).Str("");   // 13
  b.Pad(3).U32(1).Str("a");  // names: 16..26
  b.Pad(2).U32(1);           // positions count at 28, first double at 32 (36 from the buffer start)
  ASSERT_EQ(b.Body(), 32u);
  b.F64(2.0).U32(0).U32(0);
  EXPECT_EQ(out, b.s);
  const RosJointState js = DecodeJointState(out);
  EXPECT_EQ(js.names, std::vector<std::string>{"a"});
  EXPECT_EQ(js.positions_rad, positions);
}

TEST(CdrTest, ImuBytes) {
  ImuSample imu;
  imu.time = Time{3'000'000'000};
  imu.angular_velocity_rad_s = {0.1, 0.2, 0.3};
  imu.linear_acceleration_m_s2 = {1.0, 2.0, 9.81};
  std::string out;
  EncodeImu(imu, "i", &out);
  Bytes b;
  b.I32(3).U32(0).Str("i").Pad(2);  // 14 -> 16
  b.F64(0).F64(0).F64(0).F64(1);
  b.F64(-1);
  for (int i = 0; i < 8; ++i) b.F64(0);
  b.F64(0.1).F64(0.2).F64(0.3);
  for (int i = 0; i < 9; ++i) b.F64(0);
  b.F64(1.0).F64(2.0).F64(9.81);
  for (int i = 0; i < 9; ++i) b.F64(0);
  EXPECT_EQ(out.size(), 316u);
  EXPECT_EQ(out, b.s);
  const ImuSample back = DecodeImu(out);
  EXPECT_EQ(back.time, imu.time);
  EXPECT_EQ(back.angular_velocity_rad_s, imu.angular_velocity_rad_s);
  EXPECT_EQ(back.linear_acceleration_m_s2, imu.linear_acceleration_m_s2);
}

TEST(CdrTest, OdometryBytes) {
  const Pose2 pose(1.0, -2.0, 0.5);
  std::string out;
  EncodeOdometry({Time{5}, "o", "b", pose}, &out);
  Bytes b;
  b.I32(0).U32(5).Str("o").Pad(2).Str("b").Pad(2);  // child at 16..22, doubles from 24
  ASSERT_EQ(b.Body(), 24u);
  b.F64(1.0).F64(-2.0).F64(0.0);
  b.F64(0).F64(0).F64(std::sin(0.25)).F64(std::cos(0.25));
  for (int i = 0; i < 36 + 6 + 36; ++i) b.F64(0);
  EXPECT_EQ(out, b.s);
  const RosOdometry back = DecodeOdometry(out);
  EXPECT_EQ(back.frame_id, "o");
  EXPECT_EQ(back.child_frame_id, "b");
  EXPECT_EQ(back.pose, pose);
}

TEST(CdrTest, TfMessageBytes) {
  const Pose2 pose(0.25, 0.0, -1.0);
  std::string out;
  EncodeTfMessage({{Time{1'000'000'001}, "p", "c", pose}}, &out);
  Bytes b;
  b.U32(1).I32(1).U32(1).Str("p").Pad(2).Str("c").Pad(6);  // 4 + 8 + 6, +2, +6 -> 32
  ASSERT_EQ(b.Body(), 32u);
  b.F64(0.25).F64(0).F64(0).F64(0).F64(0).F64(std::sin(-0.5)).F64(std::cos(-0.5));
  EXPECT_EQ(out, b.s);
  const std::vector<RosTransform> back = DecodeTfMessage(out);
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].parent_frame, "p");
  EXPECT_EQ(back[0].child_frame, "c");
  EXPECT_EQ(back[0].time, Time{1'000'000'001});
  EXPECT_EQ(back[0].parent_from_child, pose);
}

TEST(CdrTest, TfMessage3dCarriesACameraMountingAndPlanarOnesAsBefore) {
  RgbdFrame frame;  // the ECE276A Kinect's mounting: pitched, yawed, 0.36 m up
  const Eigen::Isometry3d mount = frame.BaseFromRgbOptical();
  const RosTransform planar{Time{7}, "base_link", "laser", Pose2(0.133, 0.01, 0.2)};
  std::string out;
  EncodeTfMessage(
      {RosTransform3d::From(planar), RosTransform3d::From(Time{7}, "base_link", "cam", mount)},
      &out);
  const std::vector<RosTransform3d> back = DecodeTfMessage3d(out);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[1].child_frame, "cam");
  EXPECT_TRUE(back[1].translation.isApprox(Eigen::Vector3d(0.18, 0.005, 0.36), 1e-15));
  EXPECT_GE(back[1].rotation.w(), 0.0);
  EXPECT_TRUE(back[1].rotation.toRotationMatrix().isApprox(mount.linear(), 1e-14));
  // The optical z axis (forward) points ahead and 0.36 rad down.
  const Eigen::Vector3d forward = back[1].rotation * Eigen::Vector3d::UnitZ();
  EXPECT_NEAR(std::asin(-forward.z()), 0.36, 1e-12);
  // A planar transform in a 3-D message is byte for byte the planar encoder's.
  std::string planar_only;
  EncodeTfMessage({planar}, &planar_only);
  std::string as_3d;
  EncodeTfMessage({RosTransform3d::From(planar)}, &as_3d);
  EXPECT_EQ(as_3d, planar_only);
  EXPECT_EQ(DecodeTfMessage(out)[0].parent_from_child, planar.parent_from_child);
}

TEST(CdrTest, RejectsTruncatedAndBadLengths) {
  std::string out;
  EncodeOdometry({Time{5}, "odom", "base_link", Pose2(1, 2, 3)}, &out);
  for (std::size_t n : {std::size_t{0}, std::size_t{3}, std::size_t{10}, out.size() - 1}) {
    EXPECT_THROW(DecodeOdometry(out.substr(0, n)), CdrError) << n;
  }
  std::string bad_header = out;
  bad_header[1] = 0x00;  // big-endian CDR
  EXPECT_THROW(DecodeOdometry(bad_header), CdrError);
  // A JointState whose name count claims far more than the payload holds.
  EncodeJointState(Time{0}, {"a"}, std::vector<double>{1.0}, &out);
  std::string huge = out;
  const std::uint32_t count = 100'000'000;
  std::memcpy(huge.data() + 4 + 16, &count, 4);
  try {
    DecodeJointState(huge);
    FAIL() << "no error";
  } catch (const CdrError& e) {
    EXPECT_NE(std::string(e.what()).find("claims 100000000 elements"), std::string::npos);
  }
  // A string whose length runs past the end.
  std::string long_string = out;
  const std::uint32_t length = 1000;
  std::memcpy(long_string.data() + 4 + 8, &length, 4);
  EXPECT_THROW(DecodeJointState(long_string), CdrError);
}

// sin and cos of the half angle are not injective on doubles, so a yaw decodes to the exact
// double written only most of the time; otherwise to a neighbour within a few ulps that
// encodes to the very same quaternion (write -> read -> write is byte-identical).
TEST(RosMessagesTest, YawRoundTripsToTheSameQuaternion) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-std::numbers::pi, std::numbers::pi);
  std::string out, again;
  int exact = 0;
  const int trials = 20000;
  for (int i = 0; i < trials; ++i) {
    // Sequenced draws, the last coordinate first (the order these cases were generated in).
    const double theta = i == 0 ? std::numbers::pi : u(rng), y = u(rng), x = u(rng);
    const Pose2 pose(x, y, theta);
    EncodeOdometry({Time{0}, "o", "b", pose}, &out);
    const Pose2 back = DecodeOdometry(out).pose;
    ASSERT_EQ(back.x(), pose.x());
    ASSERT_EQ(back.y(), pose.y());
    ASSERT_NEAR(back.theta(), pose.theta(), 4 * std::numeric_limits<double>::epsilon()) << i;
    EncodeOdometry({Time{0}, "o", "b", back}, &again);
    ASSERT_EQ(again, out) << i;
    exact += back.theta() == pose.theta() ? 1 : 0;
  }
  EXPECT_GT(exact, trials / 2);
  std::printf("yaw decoded bit-exactly in %d of %d random poses\n", exact, trials);
}

TEST(RosMessagesTest, DefinitionsNameEveryNestedTypeOnce) {
  const std::string& text = RosMessageDefinition(RosType::kOdometry);
  EXPECT_TRUE(text.starts_with("std_msgs/Header header\n"));
  const std::string separator = std::string(80, '=') + "\nMSG: geometry_msgs/Pose\n";
  EXPECT_EQ(text.find(separator), text.rfind(separator));
  EXPECT_NE(text.find(separator), std::string::npos);
  EXPECT_NE(text.find("MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"),
            std::string::npos);
  EXPECT_EQ(RosTypeFromName("sensor_msgs/LaserScan"), RosType::kLaserScan);
  EXPECT_EQ(RosTypeFromName("nav_msgs/msg/Odometry"), RosType::kOdometry);
  EXPECT_EQ(RosTypeFromName("nav_msgs/msg/GridCells"), std::nullopt);
}

TEST(Crc32Test, KnownVectors) {
  EXPECT_EQ(mcap::Crc32(""), 0u);
  EXPECT_EQ(mcap::Crc32("123456789"), 0xCBF43926u);
  EXPECT_EQ(mcap::Crc32("The quick brown fox jumps over the lazy dog"), 0x414FA339u);
}

}  // namespace
}  // namespace slamrig::slam
