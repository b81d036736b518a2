#include "slam/io/log_perturbation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "slam/io/carmen_writer.h"
#include "slam/io/log_reader.h"
#include "slam/odometry/wheel_odometry.h"
#include "slam/types/error.h"
#include "tests/util/temp_dir.h"

namespace slamrig::slam {
namespace {

LaserScan MakeScan(double t, int beams) {
  LaserScan s;
  s.time = Time::FromSeconds(t);
  s.angle_min_rad = -1.5;
  s.angle_increment_rad = 3.0 / beams;
  s.range_min_m = 0.05;
  s.range_max_m = 30.0;
  for (int i = 0; i < beams; ++i)
    s.ranges_m.push_back(i % 10 == 0 ? 30.0f : 1.0f + 0.2f * static_cast<float>(i % 7));
  return s;
}

// A pose stream with a scan after each pose, the odometry equal to the reference: steps of
// 0.2-0.6 m and rotations of -0.3..0.3 rad, 10 Hz.
Dataset PoseLog(int steps, int beams = 20) {
  Dataset d;
  d.source = "synthetic";
  Pose2 pose(1.0, 2.0, 0.3);
  for (int k = 0; k < steps; ++k) {
    const double t = 100.0 + 0.1 * k;
    if (k > 0) pose = pose * Pose2(0.2 + 0.4 * ((k * 37) % 11) / 10.0, 0.0, 0.3 * std::sin(k));
    d.records.push_back(OdometryPose{Time::FromSeconds(t), pose});
    d.records.push_back(MakeScan(t, beams));
    d.reference.push_back({Time::FromSeconds(t), pose});
  }
  return d;
}

// Wheel ticks every 0.1 s with four gyro samples between them (the ECE276A layout).
Dataset TicksLog(int steps) {
  Dataset d;
  for (int k = 0; k < steps; ++k) {
    const double t = 0.1 * k;
    for (int j = 1; j <= 4 && k > 0; ++j) {
      ImuSample imu;
      imu.time = Time::FromSeconds(t - 0.1 + 0.025 * j - 0.001);
      imu.angular_velocity_rad_s.z() = 0.5 * std::sin(0.1 * k);
      d.records.push_back(imu);
    }
    const std::int32_t r = 2000 + 300 * (k % 5), l = 2000 - 200 * (k % 3);
    d.records.push_back(WheelTicks{Time::FromSeconds(t), {r, r}, {l, l}});
  }
  return d;
}

std::vector<Pose2> Increments(const std::vector<Record>& records) {
  std::vector<Pose2> out;
  std::optional<Pose2> previous;
  for (const Record& r : records) {
    if (const auto* o = std::get_if<OdometryPose>(&r)) {
      if (previous) out.push_back(previous->Between(o->odom_from_base));
      previous = o->odom_from_base;
    }
  }
  return out;
}

template <typename T>
std::size_t Count(const std::vector<Record>& records) {
  std::size_t n = 0;
  for (const Record& r : records) n += std::holds_alternative<T>(r);
  return n;
}

bool SameRecords(const std::vector<Record>& a, const std::vector<Record>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].index() != b[i].index()) return false;
    if (const auto* o = std::get_if<OdometryPose>(&a[i])) {
      if (!(o->odom_from_base == std::get<OdometryPose>(b[i]).odom_from_base)) return false;
    } else if (const auto* s = std::get_if<LaserScan>(&a[i])) {
      if (s->ranges_m != std::get<LaserScan>(b[i]).ranges_m) return false;
    } else if (const auto* w = std::get_if<WheelTicks>(&a[i])) {
      const auto& v = std::get<WheelTicks>(b[i]);
      if (w->right_ticks != v.right_ticks || w->left_ticks != v.left_ticks) return false;
    }
  }
  return true;
}

LogPerturbation Everything() {
  LogPerturbation p;
  p.odometry.noise_per_m = 0.05;
  p.odometry.noise_per_rad = 0.1;
  p.odometry.lost = {{1.0, 2.0}};
  p.scans.drop_fraction = 0.1;
  p.range.noise_m = 0.02;
  p.beams.drop_fraction = 0.1;
  return p;
}

TEST(LogPerturbationTest, DefaultsChangeNothing) {
  const Dataset original = PoseLog(50);
  Dataset d = original;
  EXPECT_FALSE(LogPerturbation{}.Active());
  ApplyLogPerturbation(&d, LogPerturbation{}, 1);
  EXPECT_TRUE(SameRecords(d.records, original.records));
}

TEST(LogPerturbationTest, SameSeedSameOutputOtherSeedOther) {
  const Dataset original = PoseLog(200);
  Dataset a = original, b = original, c = original;
  ApplyLogPerturbation(&a, Everything(), 7);
  ApplyLogPerturbation(&b, Everything(), 7);
  ApplyLogPerturbation(&c, Everything(), 8);
  EXPECT_TRUE(SameRecords(a.records, b.records));
  EXPECT_FALSE(SameRecords(a.records, c.records));
  EXPECT_FALSE(SameRecords(a.records, original.records));
  Dataset t1 = TicksLog(100), t2 = TicksLog(100);
  ApplyLogPerturbation(&t1, Everything(), 3);
  ApplyLogPerturbation(&t2, Everything(), 3);
  EXPECT_TRUE(SameRecords(t1.records, t2.records));
}

TEST(LogPerturbationTest, PoseNoiseHasTheRequestedSigmaPerMetreAndPerRadian) {
  const Dataset original = PoseLog(10001, 1);
  Dataset d = original;
  LogPerturbation p;
  p.odometry.noise_per_m = 0.05;
  p.odometry.noise_per_rad = 0.2;
  ApplyLogPerturbation(&d, p, 11);
  const std::vector<Pose2> before = Increments(original.records), after = Increments(d.records);
  ASSERT_EQ(before.size(), after.size());
  double sx = 0, sy = 0, sr = 0, mx = 0;
  int rotations = 0;
  for (std::size_t i = 0; i < before.size(); ++i) {
    const double length = before[i].translation().norm();
    const Eigen::Vector2d e = (after[i].translation() - before[i].translation()) / length;
    sx += e.x() * e.x();
    sy += e.y() * e.y();
    mx += e.x();
    if (std::abs(before[i].theta()) > 1e-3) {
      const double er = NormalizeAngle(after[i].theta() - before[i].theta()) / before[i].theta();
      sr += er * er;
      ++rotations;
    }
  }
  const double n = static_cast<double>(before.size());
  // 10,000 samples: a sample sigma's standard error is 0.7 % of the true one; 3 % is > 4 of them.
  EXPECT_NEAR(std::sqrt(sx / n), 0.05, 0.0015);
  EXPECT_NEAR(std::sqrt(sy / n), 0.05, 0.0015);
  EXPECT_NEAR(mx / n, 0.0, 0.002);
  EXPECT_NEAR(std::sqrt(sr / rotations), 0.2, 0.006);
}

TEST(LogPerturbationTest, PoseScaleAndBiasAreSystematicAndReaccumulated) {
  const Dataset original = PoseLog(300);
  Dataset d = original;
  LogPerturbation p;
  p.odometry.scale = 1.1;
  p.odometry.bias_rad_per_m = 0.02;
  ApplyLogPerturbation(&d, p, 1);
  const std::vector<Pose2> before = Increments(original.records), after = Increments(d.records);
  Pose2 chained = std::get<OdometryPose>(original.records.front()).odom_from_base;
  for (std::size_t i = 0; i < before.size(); ++i) {
    const double length = before[i].translation().norm();
    EXPECT_NEAR(after[i].x(), 1.1 * before[i].x(), 1e-9);
    EXPECT_NEAR(after[i].y(), 1.1 * before[i].y(), 1e-9);
    EXPECT_NEAR(NormalizeAngle(after[i].theta() - before[i].theta()), 0.02 * length, 1e-9);
    chained = chained *
              Pose2(1.1 * before[i].x(), 1.1 * before[i].y(), before[i].theta() + 0.02 * length);
  }
  // The stream is one trajectory: its last pose is the chain of the perturbed increments.
  const Pose2& last = std::get<OdometryPose>(d.records[d.records.size() - 2]).odom_from_base;
  EXPECT_NEAR(last.x(), chained.x(), 1e-6);
  EXPECT_NEAR(last.y(), chained.y(), 1e-6);
  EXPECT_NEAR(NormalizeAngle(last.theta() - chained.theta()), 0.0, 1e-9);
  // The reference is never perturbed.
  for (std::size_t k = 0; k < d.reference.size(); ++k)
    EXPECT_EQ(d.reference[k].map_from_base, original.reference[k].map_from_base);
}

// Ticks: integrated with WheelOdometry (encoders only, and with the gyro), the perturbed stream
// moves scale times as far and turns bias * distance more, whichever yaw source is used.
TEST(LogPerturbationTest, TicksScaleAndBiasReachEncodersAndGyro) {
  const Dataset original = TicksLog(400);
  Dataset d = original;
  LogPerturbation p;
  p.odometry.scale = 0.9;
  p.odometry.bias_rad_per_m = 0.05;
  const DiffDriveParams robot;
  ApplyLogPerturbation(&d, p, 1, robot);
  for (const bool gyro : {false, true}) {
    WheelOdometryOptions options;
    options.use_gyro = gyro;
    WheelOdometry a(options), b(options);
    double distance = 0.0, yaw_a = 0.0, yaw_b = 0.0;
    Pose2 last_a, last_b;
    for (std::size_t i = 0; i < original.records.size(); ++i) {
      if (const auto* imu = std::get_if<ImuSample>(&original.records[i])) {
        a.AddImu(*imu);
        b.AddImu(std::get<ImuSample>(d.records[i]));
        continue;
      }
      const auto& t = std::get<WheelTicks>(original.records[i]);
      distance +=
          0.5 * (MeanTicks(t.right_ticks) + MeanTicks(t.left_ticks)) * robot.MetresPerTick();
      a.AddTicks(t);
      b.AddTicks(std::get<WheelTicks>(d.records[i]));
      yaw_a += NormalizeAngle(a.pose().theta() - last_a.theta());
      yaw_b += NormalizeAngle(b.pose().theta() - last_b.theta());
      last_a = a.pose();
      last_b = b.pose();
    }
    SCOPED_TRACE(gyro ? "gyro" : "encoders");
    // Ticks are whole: the carried fraction keeps the totals within one tick of exact.
    EXPECT_NEAR(yaw_b - yaw_a, 0.05 * distance, 2.0 * robot.MetresPerTick() / robot.track_width_m);
    ASSERT_GT(distance, 100.0);
  }
  double right_a = 0, right_b = 0, left_a = 0, left_b = 0;
  for (std::size_t i = 0; i < d.records.size(); ++i) {
    if (const auto* t = std::get_if<WheelTicks>(&d.records[i])) {
      const auto& o = std::get<WheelTicks>(original.records[i]);
      right_a += o.right_ticks[0], left_a += o.left_ticks[0];
      right_b += t->right_ticks[0], left_b += t->left_ticks[0];
      EXPECT_EQ(t->right_ticks[0], t->right_ticks[1]);
    }
  }
  EXPECT_NEAR(0.5 * (right_b + left_b), 0.9 * 0.5 * (right_a + left_a), 1.0);
}

TEST(LogPerturbationTest, TicksNoiseHasTheRequestedSigmaAlongTheTrack) {
  const Dataset original = TicksLog(5001);
  Dataset d = original;
  LogPerturbation p;
  p.odometry.noise_per_m = 0.05;
  ApplyLogPerturbation(&d, p, 5);
  double s = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < d.records.size(); ++i) {
    if (const auto* t = std::get_if<WheelTicks>(&d.records[i])) {
      const auto& o = std::get<WheelTicks>(original.records[i]);
      const double before = o.right_ticks[0] + o.left_ticks[0];
      const double e = (t->right_ticks[0] + t->left_ticks[0] - before) / before;
      s += e * e;
      ++n;
    }
  }
  // ~4,000 ticks per record: rounding adds < 0.02 % to a 5 % sigma.
  EXPECT_NEAR(std::sqrt(s / n), 0.05, 0.002);
}

TEST(LogPerturbationTest, LostIntervalsHoldNoOdometryAndKeepTheTicks) {
  LogPerturbation p;
  p.odometry.lost = {{2.0, 3.5}, {10.0, 10.5}};
  Dataset poses = PoseLog(200);
  const Dataset original = poses;
  ApplyLogPerturbation(&poses, p, 1);
  std::size_t removed = 0;
  for (const Record& r : original.records) {
    const double t = SecondsBetween(RecordTime(r), RecordTime(original.records.front()));
    const bool inside = (t >= 2.0 && t <= 3.5) || (t >= 10.0 && t <= 10.5);
    removed += inside && std::holds_alternative<OdometryPose>(r);
  }
  EXPECT_GE(removed, 18u);
  EXPECT_EQ(Count<OdometryPose>(poses.records), Count<OdometryPose>(original.records) - removed);
  EXPECT_EQ(Count<LaserScan>(poses.records), Count<LaserScan>(original.records));
  for (const Record& r : poses.records) {
    if (!std::holds_alternative<OdometryPose>(r)) continue;
    const double t = SecondsBetween(RecordTime(r), RecordTime(poses.records.front()));
    EXPECT_FALSE(t >= 2.0 && t <= 3.5) << t;
    EXPECT_FALSE(t >= 10.0 && t <= 10.5) << t;
  }

  Dataset ticks = TicksLog(200);
  const Dataset original_ticks = ticks;
  ApplyLogPerturbation(&ticks, p, 1);
  long sum_before = 0, sum_after = 0;
  for (const Record& r : original_ticks.records)
    if (const auto* w = std::get_if<WheelTicks>(&r)) sum_before += w->right_ticks[0];
  for (const Record& r : ticks.records) {
    if (const auto* w = std::get_if<WheelTicks>(&r)) {
      sum_after += w->right_ticks[0];
      const double t = SecondsBetween(w->time, RecordTime(ticks.records.front()));
      EXPECT_FALSE(t >= 2.0 && t <= 3.5) << t;
    }
  }
  EXPECT_LT(Count<WheelTicks>(ticks.records), Count<WheelTicks>(original_ticks.records));
  EXPECT_EQ(sum_after, sum_before);
}

TEST(LogPerturbationTest, DroppedScansFollowTheFractionAndTakeTheirReference) {
  Dataset d = PoseLog(10000, 1);
  LogPerturbation p;
  p.scans.drop_fraction = 0.1;
  ApplyLogPerturbation(&d, p, 2);
  const double kept = static_cast<double>(Count<LaserScan>(d.records));
  // Binomial(10000, 0.1): sd 30 scans; 4.5 sd.
  EXPECT_NEAR(10000.0 - kept, 1000.0, 135.0);
  EXPECT_EQ(Count<OdometryPose>(d.records), 10000u);
  ASSERT_EQ(d.reference.size(), static_cast<std::size_t>(kept));
  std::size_t k = 0;
  for (const Record& r : d.records) {
    if (const auto* s = std::get_if<LaserScan>(&r)) {
      EXPECT_EQ(d.reference[k++].time, s->time);
    }
  }
}

TEST(LogPerturbationTest, EveryKthBeamIsInvalidAndTheOthersUntouched) {
  const Dataset original = PoseLog(20, 181);
  Dataset d = original;
  LogPerturbation p;
  p.beams.drop_every = 4;
  ApplyLogPerturbation(&d, p, 1);
  for (std::size_t r = 0; r < d.records.size(); ++r) {
    const auto* s = std::get_if<LaserScan>(&d.records[r]);
    if (s == nullptr) continue;
    const auto& o = std::get<LaserScan>(original.records[r]);
    for (std::size_t i = 0; i < s->ranges_m.size(); ++i) {
      if (i % 4 == 3) {
        EXPECT_FALSE(s->IsHit(i));
        EXPECT_LT(s->ranges_m[i], s->range_min_m);
      } else {
        EXPECT_EQ(s->ranges_m[i], o.ranges_m[i]);
      }
    }
  }
}

TEST(LogPerturbationTest, RandomBeamDropsFollowTheFraction) {
  Dataset d = PoseLog(100, 400);
  LogPerturbation p;
  p.beams.drop_fraction = 0.25;
  ApplyLogPerturbation(&d, p, 4);
  double dropped = 0.0, total = 0.0;
  for (const Record& r : d.records) {
    if (const auto* s = std::get_if<LaserScan>(&r)) {
      for (const float x : s->ranges_m) dropped += x == 0.0f;
      total += static_cast<double>(s->ranges_m.size());
    }
  }
  // Binomial(40000, 0.25): sd 87 beams.
  EXPECT_NEAR(dropped, 0.25 * total, 400.0);
}

TEST(LogPerturbationTest, RangeNoiseOnHitsOnlyAndShorterMaximumRange) {
  const Dataset original = PoseLog(400, 200);
  Dataset d = original;
  LogPerturbation p;
  p.range.noise_m = 0.03;
  p.range.max_m = 2.0;
  ApplyLogPerturbation(&d, p, 9);
  double s = 0.0;
  int hits = 0;
  for (std::size_t r = 0; r < d.records.size(); ++r) {
    const auto* scan = std::get_if<LaserScan>(&d.records[r]);
    if (scan == nullptr) continue;
    const auto& o = std::get<LaserScan>(original.records[r]);
    EXPECT_EQ(scan->range_max_m, 2.0);
    for (std::size_t i = 0; i < o.ranges_m.size(); ++i) {
      if (o.ranges_m[i] >= 2.0f) {
        EXPECT_EQ(scan->ranges_m[i], 2.0f);
        EXPECT_FALSE(scan->IsHit(i));
      } else if (o.ranges_m[i] < 1.85f) {  // far from the new maximum: unclamped noise
        const double e = scan->ranges_m[i] - o.ranges_m[i];
        s += e * e;
        ++hits;
      }
    }
  }
  ASSERT_GT(hits, 30000);
  EXPECT_NEAR(std::sqrt(s / hits), 0.03, 0.0006);
}

TEST(LogPerturbationTest, TheFileIsNeverChanged) {
  testing::TempDir dir;
  const std::string path = dir.File("log.carmen");
  {
    CarmenWriter writer(path);
    const Dataset d = PoseLog(30, 90);
    for (const Record& r : d.records) {
      if (const auto* o = std::get_if<OdometryPose>(&r)) writer.WriteOdometry(*o, 0.0, 0.0);
      if (const auto* s = std::get_if<LaserScan>(&r)) writer.WriteLaser(*s, Pose2());
    }
    writer.Commit();
  }
  auto bytes = [&] {
    std::ifstream in(path, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  };
  const std::string before = bytes();
  Dataset d = ReadLog(path);
  ApplyLogPerturbation(&d, Everything(), 1);
  EXPECT_EQ(bytes(), before);
  EXPECT_TRUE(SameRecords(ReadLog(path).records, ReadLog(path).records));
  EXPECT_FALSE(SameRecords(ReadLog(path).records, d.records));
}

std::string ErrorOf(const std::vector<std::string>& flags) {
  try {
    LogPerturbationFromFlags(flags);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(LogPerturbationTest, BadKeysAndValuesNameTheKeyInOneLine) {
  const std::string unknown = ErrorOf({"odometry.noise_per_mm=0.1"});
  EXPECT_NE(unknown.find("odometry.noise_per_mm"), std::string::npos) << unknown;
  const std::string fraction = ErrorOf({"scans.drop_fraction=1.5"});
  EXPECT_NE(fraction.find("scans.drop_fraction = 1.5; must be in [0, 1]"), std::string::npos)
      << fraction;
  const std::string every = ErrorOf({"beams.drop_every=1"});
  EXPECT_NE(every.find("beams.drop_every = 1"), std::string::npos) << every;
  const std::string lost = ErrorOf({"odometry.lost=[[5, 2]]"});
  EXPECT_NE(lost.find("odometry.lost[0]"), std::string::npos) << lost;
  const std::string text = ErrorOf({"range.noise_m=abc"});
  EXPECT_NE(text.find("range.noise_m"), std::string::npos) << text;
  EXPECT_NE(ErrorOf({"odometry"}).find("expected KEY=VALUE"), std::string::npos);
  for (const std::string& e : {unknown, fraction, every, lost, text})
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  const LogPerturbation ok =
      LogPerturbationFromFlags({"odometry.noise_per_m=0.1", "odometry.lost=[[1, 2], [4, 5]]"});
  EXPECT_EQ(ok.odometry.noise_per_m, 0.1);
  ASSERT_EQ(ok.odometry.lost.size(), 2u);
  EXPECT_EQ(ok.odometry.lost[1], Eigen::Vector2d(4, 5));
}

// Four odometry poses per scan: the noise is drawn per scan interval, so the increments between
// scans carry the requested sigma (independent draws per record would carry half of it).
TEST(LogPerturbationTest, NoisePerScanIntervalWhateverTheOdometryRate) {
  Dataset d;
  Pose2 pose;
  for (int k = 0; k < 20000; ++k) {
    const double t = 0.025 * k;
    pose = pose * Pose2(0.1, 0.0, 0.02 * std::sin(0.01 * k));
    d.records.push_back(OdometryPose{Time::FromSeconds(t), pose});
    if (k % 4 == 3) {
      d.records.push_back(MakeScan(t, 1));
      d.reference.push_back({Time::FromSeconds(t), pose});
    }
  }
  LogPerturbation p;
  p.odometry.noise_per_m = 0.05;
  ApplyLogPerturbation(&d, p, 6);
  ScanSyncOptions sync;
  sync.source = OdometrySource::kOdometryPoses;
  const OdometryNoiseMeasurement m = MeasureOdometryNoise(d, sync);
  EXPECT_NEAR(m.noise_per_m, 0.05, 0.002);
}

// The measurement recovers the noise ApplyLogPerturbation added to a noise-free log.
TEST(LogPerturbationTest, MeasurementRecoversAddedNoise) {
  Dataset d = PoseLog(5000, 2);
  ScanSyncOptions sync;
  sync.source = OdometrySource::kOdometryPoses;
  const OdometryNoiseMeasurement zero = MeasureOdometryNoise(d, sync);
  EXPECT_NEAR(zero.noise_per_m, 0.0, 1e-6);
  EXPECT_NEAR(zero.noise_per_rad, 0.0, 1e-6);
  LogPerturbation p;
  p.odometry.noise_per_m = 0.04;
  p.odometry.noise_per_rad = 0.1;
  p.odometry.scale = 1.05;
  ApplyLogPerturbation(&d, p, 3);
  const OdometryNoiseMeasurement m = MeasureOdometryNoise(d, sync);
  EXPECT_EQ(m.increments, 4999);
  EXPECT_NEAR(m.scale, 1.05, 0.003);
  EXPECT_NEAR(m.noise_per_rad, 0.1, 0.004);
  // The scale's own error (5 % of |t|, spread over both axes) adds to the noise.
  EXPECT_NEAR(m.noise_per_m, std::sqrt(0.04 * 0.04 + 0.05 * 0.05 / 2), 0.002);
}

// A log whose odometry turns 10 % too far and drifts 0.02 rad per metre: the fit splits the
// rotation error into its causes, and thinned scans compose the odometry between kept ones.
TEST(LogPerturbationTest, RotationErrorPerMetreAndPerRadianAndSpacing) {
  Dataset d;
  Pose2 truth, odometry;
  for (int k = 0; k < 4000; ++k) {
    const double t = 0.1 * k;
    // Alternately 20 steps straight (0.1 m) and 20 turning on the spot (0.05 rad).
    const bool turning = (k / 20) % 2 == 1;
    const Pose2 g = turning ? Pose2(0.0, 0.0, 0.05) : Pose2(0.1, 0.0, 0.0);
    truth = truth * g;
    odometry = odometry * Pose2(g.x(), g.y(), 1.1 * g.theta() + 0.02 * g.x());
    d.records.push_back(OdometryPose{Time::FromSeconds(t), odometry});
    d.records.push_back(MakeScan(t, 1));
    d.reference.push_back({Time::FromSeconds(t), truth});
  }
  ScanSyncOptions sync;
  sync.source = OdometrySource::kOdometryPoses;
  const OdometryNoiseMeasurement every = MeasureOdometryNoise(d, sync);
  EXPECT_EQ(every.increments, 3999);
  EXPECT_NEAR(every.rotation_scale, 1.1, 1e-9);
  EXPECT_NEAR(every.rotation_per_rad, 0.1, 1e-6);
  EXPECT_NEAR(every.rotation_per_m, 0.02, 1e-6);
  // One comparison per metre straight (10 steps) or per 0.5 rad turned (10 steps); the pair
  // that spans the first step mixes the two.
  const OdometryNoiseMeasurement spaced = MeasureOdometryNoise(d, sync, {0.95, 0.475});
  EXPECT_NEAR(spaced.increments, 400, 2);
  EXPECT_NEAR(spaced.path_m, every.path_m, 1e-6);
  EXPECT_NEAR(spaced.rotation_scale, 1.1, 1e-3);
  EXPECT_NEAR(spaced.rotation_per_rad, 0.1, 1e-3);
  EXPECT_NEAR(spaced.rotation_per_m, 0.02, 1e-3);
}

}  // namespace
}  // namespace slamrig::slam
