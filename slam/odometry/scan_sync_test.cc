#include "slam/odometry/scan_sync.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace slamrig::slam {
namespace {

LaserScan Scan(double t_s) {
  LaserScan scan;
  scan.time = Time::FromSeconds(t_s);
  scan.ranges_m = {1.0f};
  return scan;
}

ImuSample Gyro(double t_s, double wz) {
  ImuSample imu;
  imu.time = Time::FromSeconds(t_s);
  imu.angular_velocity_rad_s.z() = wz;
  return imu;
}

std::vector<Record> SortedByTime(std::vector<Record> records) {
  std::stable_sort(records.begin(), records.end(),
                   [](const Record& a, const Record& b) { return RecordTime(a) < RecordTime(b); });
  return records;
}

// Encoders at 40 Hz, IMU at 100 Hz, scans at 40 Hz offset by 10 ms: counts are summed, rates
// averaged, and the totals survive the regrouping.
TEST(ScanSyncTest, TicksAreSummedAndGyroAveragedPerScanInterval) {
  std::vector<Record> records;
  const double omega = 0.25;
  int total_right = 0, total_left = 0;
  for (int k = 0; k < 400; ++k) {
    const double t = 0.025 * k;
    if (k > 0) {  // the first encoder record would belong to no interval; keep it out of totals
      records.push_back(WheelTicks{Time::FromSeconds(t), {5 + k % 3, 5}, {4, 4 + k % 2}});
      total_right += 10 + k % 3;
      total_left += 8 + k % 2;
    }
    records.push_back(Scan(t + 0.001));
  }
  for (int k = 0; k < 1000; ++k) records.push_back(Gyro(0.002 + 0.01 * k, omega));
  records = SortedByTime(std::move(records));

  ScanSyncOptions options;
  const ScanSyncResult result = SyncToScans(records, options);
  EXPECT_EQ(result.source_used, OdometrySource::kWheelTicks);
  ASSERT_EQ(result.scans.size(), 400u);
  EXPECT_EQ(result.gyro_fallbacks, 0);
  const double m = options.robot.MetresPerTick();
  double distance = 0.0, yaw = 0.0;
  for (std::size_t i = 1; i < result.scans.size(); ++i) {
    const SyncedScan& s = result.scans[i];
    EXPECT_NEAR(s.dt_s, 0.025, 1e-9);
    EXPECT_GE(s.imu_samples, 2);
    EXPECT_LE(s.imu_samples, 3);
    EXPECT_NEAR(s.yaw_change_rad, omega * 0.025, 1e-12);
    distance += s.distance_m;
    yaw += s.yaw_change_rad;
  }
  EXPECT_NEAR(distance, 0.5 * (total_right / 2.0 + total_left / 2.0) * m, 1e-9);
  EXPECT_NEAR(yaw, omega * 399 * 0.025, 1e-9);
  const Pose2 last = result.scans.back().odom_from_base;
  EXPECT_NEAR(NormalizeAngle(last.theta() - NormalizeAngle(yaw)), 0.0, 1e-9);
  // Dead reckoning composes the increments back to the same poses.
  const std::vector<Pose2> dr = DeadReckoningPoses(result.scans);
  EXPECT_NEAR(dr.back().x(), last.x(), 1e-9);
  EXPECT_NEAR(dr.back().y(), last.y(), 1e-9);
}

TEST(ScanSyncTest, GyroDropoutHoldsTheLastRateAndIsCounted) {
  std::vector<Record> records = {Scan(0.0),
                                 Gyro(0.01, 0.5),
                                 WheelTicks{Time::FromSeconds(0.02), {1}, {1}},
                                 Scan(0.025),
                                 WheelTicks{Time::FromSeconds(0.04), {1}, {1}},
                                 Scan(0.05)};
  const ScanSyncResult result = SyncToScans(records, ScanSyncOptions{});
  ASSERT_EQ(result.scans.size(), 3u);
  EXPECT_EQ(result.gyro_fallbacks, 1);
  EXPECT_NEAR(result.scans[2].yaw_change_rad, 0.5 * 0.025, 1e-12);
}

TEST(ScanSyncTest, EncodersAloneGiveYawFromTheWheelDifference) {
  std::vector<Record> records = {Scan(0.0), Gyro(0.01, 0.5),
                                 WheelTicks{Time::FromSeconds(0.02), {10}, {-10}}, Scan(0.025)};
  ScanSyncOptions options;
  options.use_gyro = false;
  const ScanSyncResult result = SyncToScans(records, options);
  const double expected = 20 * options.robot.MetresPerTick() / options.robot.track_width_m;
  EXPECT_NEAR(result.scans[1].yaw_change_rad, expected, 1e-12);
  EXPECT_NEAR(result.scans[1].distance_m, 0.0, 1e-12);
}

// Odometry poses along a circle at 20 Hz, scans at 7 Hz in between: interpolation recovers the
// circle at the scan time to well under a millimetre.
TEST(ScanSyncTest, OdometryPosesAreInterpolatedToScanTimes) {
  const double radius = 2.0, omega = 0.4;
  auto circle = [&](double t) {
    const double phi = omega * t;
    return Pose2(radius * std::sin(phi), radius * (1.0 - std::cos(phi)), phi);
  };
  std::vector<Record> records;
  for (int k = 0; k <= 200; ++k)
    records.push_back(OdometryPose{Time::FromSeconds(0.05 * k), circle(0.05 * k)});
  for (int k = 0; k < 60; ++k) records.push_back(Scan(0.013 + k / 7.0));
  records = SortedByTime(std::move(records));
  const ScanSyncResult result = SyncToScans(records, ScanSyncOptions{});
  EXPECT_EQ(result.source_used, OdometrySource::kOdometryPoses);
  ASSERT_EQ(result.scans.size(), 60u);
  Pose2 composed = result.scans.front().odom_from_base;
  for (const SyncedScan& s : result.scans) {
    const Pose2 truth = circle(s.scan.time.seconds());
    EXPECT_NEAR(s.odom_from_base.x(), truth.x(), 1e-9);
    EXPECT_NEAR(s.odom_from_base.y(), truth.y(), 1e-9);
    EXPECT_NEAR(NormalizeAngle(s.odom_from_base.theta() - truth.theta()), 0.0, 1e-9);
    if (&s != &result.scans.front()) composed = composed * s.increment;
  }
  EXPECT_NEAR(composed.x(), result.scans.back().odom_from_base.x(), 1e-9);
  EXPECT_NEAR(composed.y(), result.scans.back().odom_from_base.y(), 1e-9);
}

// A sweeping scan (time_increment_s > 0) gets the velocity of its interval for undistortion: on
// a circle driven at 0.8 m/s and 0.4 rad/s, forwards or backwards; a scan with simultaneous beams,
// or with `deskew` off, gets none.
TEST(ScanSyncTest, ASweepingScanGetsItsIntervalsVelocity) {
  for (const double direction : {1.0, -1.0}) {
    const double radius = 2.0, omega = 0.4 * direction;
    auto circle = [&](double t) {
      const double phi = omega * t;
      return Pose2(radius * std::sin(phi), radius * (1.0 - std::cos(phi)), phi);
    };
    for (const bool deskew : {true, false}) {
      std::vector<Record> records;
      for (int k = 0; k <= 200; ++k)
        records.push_back(OdometryPose{Time::FromSeconds(0.05 * k), circle(0.05 * k)});
      for (int k = 0; k < 20; ++k) {
        LaserScan scan = Scan(0.013 + k / 7.0);
        scan.time_increment_s = k % 2 == 0 ? 1e-4 : 0.0;
        records.push_back(scan);
      }
      ScanSyncOptions options;
      options.deskew = deskew;
      const ScanSyncResult result = SyncToScans(SortedByTime(std::move(records)), options);
      ASSERT_EQ(result.scans.size(), 20u);
      EXPECT_EQ(result.scans[0].scan.sweep_velocity.forward_m_s, 0.0);  // no interval yet
      for (std::size_t k = 1; k < result.scans.size(); ++k) {
        const BaseVelocity& v = result.scans[k].scan.sweep_velocity;
        if (deskew && k % 2 == 0) {
          EXPECT_NEAR(v.forward_m_s, 0.8 * direction, 1e-3) << k;  // the chord, not the arc
          EXPECT_NEAR(v.yaw_rate_rad_s, omega, 1e-9) << k;
        } else {
          EXPECT_EQ(v.forward_m_s, 0.0) << k;
          EXPECT_EQ(v.yaw_rate_rad_s, 0.0) << k;
        }
      }
    }
  }
}

// Odometry poses at 20 Hz with nothing between 5 s and 8 s, scans at 7 Hz: a scan whose interval
// holds no sample is said to follow a gap as long as the silence it was interpolated across (3 s);
// every other scan, including the first in the hole (its interval still holds the sample at 5 s),
// follows none. Wheel ticks at 10 Hz with the same hole: the time since the last tick record.
TEST(ScanSyncTest, AScanAfterSilentOdometrySaysHowLongItWasSilent) {
  std::vector<Record> poses, ticks;
  for (int k = 0; k <= 200; ++k) {
    const double t = 0.05 * k;
    if (t > 5.0 + 1e-9 && t < 8.0 - 1e-9) continue;
    poses.push_back(OdometryPose{Time::FromSeconds(t), Pose2(0.1 * t, 0.0, 0.0)});
    if (k % 2 == 0) ticks.push_back(WheelTicks{Time::FromSeconds(t), {10}, {10}});
  }
  for (int k = 0; k < 60; ++k) {
    poses.push_back(Scan(0.013 + k / 7.0));
    ticks.push_back(Scan(0.013 + k / 7.0));
  }
  for (std::vector<Record>* records : {&poses, &ticks}) {
    const ScanSyncResult result = SyncToScans(SortedByTime(std::move(*records)), ScanSyncOptions{});
    ASSERT_EQ(result.scans.size(), 60u);
    const bool from_poses = result.source_used == OdometrySource::kOdometryPoses;
    for (std::size_t i = 1; i < result.scans.size(); ++i) {
      const double t = result.scans[i].scan.time.seconds();
      const double previous = result.scans[i - 1].scan.time.seconds();
      const bool silent = previous > 5.0 && t < 8.0;
      const double expected = !silent ? 0.0 : from_poses ? 3.0 : t - 5.0;
      EXPECT_NEAR(result.scans[i].odometry_gap_s, expected, 1e-9)
          << (from_poses ? "poses " : "ticks ") << i << " at " << t;
    }
  }
}

TEST(ScanSyncTest, NoOdometryGivesIdentityIncrementsAndCountsThem) {
  const ScanSyncResult result = SyncToScans({Scan(0.0), Scan(0.1)}, ScanSyncOptions{});
  EXPECT_EQ(result.source_used, OdometrySource::kNone);
  EXPECT_EQ(result.scans_without_odometry, 2);
  EXPECT_EQ(result.scans[1].increment, Pose2());
}

}  // namespace
}  // namespace slamrig::slam
