#include "sim/simulator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>

#include "sim/presets.h"
#include "sim/world_yaml.h"
#include "slam/types/trajectory.h"

namespace slamrig::sim {
namespace {

SimulatorOptions Office(std::uint64_t seed) {
  SimulatorOptions o;
  o.world = LoadWorldSpec(FindPresetFile("office", "worlds"));
  o.seed = seed;
  return o;
}

std::vector<StepResult> RunFor(Simulator* sim, double seconds) {
  std::vector<StepResult> steps;
  while (sim->time().seconds() < seconds - 1e-9) steps.push_back(sim->Step());
  return steps;
}

// FNV-1a over the bytes of every record field: any change of any bit shows.
class Hasher {
 public:
  template <typename T>
  void Add(const T& value) {
    unsigned char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    for (const unsigned char b : bytes) hash_ = (hash_ ^ b) * 0x100000001b3ULL;
  }
  void Add(const Record& record) {
    Add(RecordTime(record).ns);
    if (const auto* s = std::get_if<LaserScan>(&record)) {
      for (const float r : s->ranges_m) Add(r);
    } else if (const auto* t = std::get_if<WheelTicks>(&record)) {
      for (const auto v : t->right_ticks) Add(v);
      for (const auto v : t->left_ticks) Add(v);
    } else if (const auto* i = std::get_if<ImuSample>(&record)) {
      for (int k = 0; k < 3; ++k) Add(i->angular_velocity_rad_s[k]);
      for (int k = 0; k < 3; ++k) Add(i->linear_acceleration_m_s2[k]);
    }
  }
  void Add(const TruthSample& truth) {
    Add(truth.map_from_base.x());
    Add(truth.map_from_base.y());
    Add(truth.map_from_base.theta());
  }
  std::uint64_t hash() const { return hash_; }

 private:
  std::uint64_t hash_ = 0xcbf29ce484222325ULL;
};

std::uint64_t HashRun(const SimulatorOptions& options, double seconds) {
  Simulator sim(options);
  Hasher hasher;
  for (const StepResult& step : RunFor(&sim, seconds)) {
    for (const Record& r : step.records) hasher.Add(r);
    for (const TruthSample& t : step.truth) hasher.Add(t);
  }
  return hasher.hash();
}

TEST(SimulatorTest, RecordsComeOutInTimeOrderEachWithItsTruth) {
  Simulator sim(Office(1));
  std::map<std::size_t, int> counts;
  Time last;
  for (const StepResult& step : RunFor(&sim, 3.0)) {
    ASSERT_EQ(step.records.size(), step.truth.size());
    for (std::size_t i = 0; i < step.records.size(); ++i) {
      const Time t = RecordTime(step.records[i]);
      EXPECT_GE(t, last);
      EXPECT_LE(t, step.time);
      EXPECT_EQ(step.truth[i].time, t);
      last = t;
      ++counts[step.records[i].index()];
    }
  }
  // 3 s of 40 Hz scans, 100 Hz IMU, 40 Hz encoders; the samples at exactly 3 s wait for the
  // scan that starts then (it will be stamped 3 s too), and Flush() releases them.
  EXPECT_EQ(counts[0], 120);
  EXPECT_EQ(counts[3], 299);
  EXPECT_EQ(counts[2], 119);
  EXPECT_EQ(sim.Flush().records.size(), 2u);
}

TEST(SimulatorTest, SameSeedSameBitsPinnedByAHash) {
  const std::uint64_t a = HashRun(Office(42), 2.0);
  EXPECT_EQ(a, HashRun(Office(42), 2.0));
  // Box2D, the tyre solver and every noise stream are deterministic; this constant changes only
  // when the simulation itself changes (then review the change and update it).
  EXPECT_EQ(a, 9263988676501613351ULL);
}

TEST(SimulatorTest, OtherSeedOtherNoiseSamePhysics) {
  Simulator a(Office(1)), b(Office(2));
  const auto steps_a = RunFor(&a, 1.0), steps_b = RunFor(&b, 1.0);
  int scans_differ = 0, imu_differ = 0;
  for (std::size_t s = 0; s < steps_a.size(); ++s) {
    ASSERT_EQ(steps_a[s].records.size(), steps_b[s].records.size());
    for (std::size_t i = 0; i < steps_a[s].records.size(); ++i) {
      EXPECT_EQ(steps_a[s].truth[i].map_from_base, steps_b[s].truth[i].map_from_base);
      if (const auto* scan = std::get_if<LaserScan>(&steps_a[s].records[i])) {
        scans_differ += scan->ranges_m != std::get<LaserScan>(steps_b[s].records[i]).ranges_m;
      }
      if (const auto* imu = std::get_if<ImuSample>(&steps_a[s].records[i])) {
        imu_differ += imu->angular_velocity_rad_s !=
                      std::get<ImuSample>(steps_b[s].records[i]).angular_velocity_rad_s;
      }
    }
  }
  EXPECT_EQ(scans_differ, 40);
  EXPECT_EQ(imu_differ, 99);
}

TEST(SimulatorTest, RemovingTheLidarChangesNoOtherSensor) {
  SimulatorOptions without_lidar = Office(5);
  without_lidar.robot.lidar.enabled = false;
  Simulator a(Office(5)), b(without_lidar);
  std::vector<Record> records_a, records_b;
  for (const StepResult& s : RunFor(&a, 2.0)) {
    for (const Record& r : s.records) {
      if (!std::holds_alternative<LaserScan>(r)) records_a.push_back(r);
    }
  }
  for (const StepResult& s : RunFor(&b, 2.0))
    records_b.insert(records_b.end(), s.records.begin(), s.records.end());
  // Without a lidar nothing is held back for a scan, so b has the last samples already.
  ASSERT_EQ(records_a.size() + 2, records_b.size());
  for (std::size_t i = 0; i < records_a.size(); ++i) {
    if (const auto* imu = std::get_if<ImuSample>(&records_a[i])) {
      EXPECT_EQ(imu->angular_velocity_rad_s,
                std::get<ImuSample>(records_b[i]).angular_velocity_rad_s);
      EXPECT_EQ(imu->linear_acceleration_m_s2,
                std::get<ImuSample>(records_b[i]).linear_acceleration_m_s2);
    } else {
      EXPECT_EQ(std::get<WheelTicks>(records_a[i]).right_ticks,
                std::get<WheelTicks>(records_b[i]).right_ticks);
    }
  }
}

TEST(SimulatorTest, EachBeamIsCastFromThePoseAtItsOwnTime) {
  // A robot spinning on the spot in the middle of a square room, lidar noise off: every beam must
  // match the room seen from the pose at that beam's time; a scan cast from its start pose would
  // be off by metres at the far end of the sweep.
  SimulatorOptions o;
  o.robot = WithoutNoise(RobotSpec{});
  o.world.spawn = Pose2(0.0, 0.0, 0.0);
  for (const auto& [cx, cy, sx, sy] :
       {std::array{0.0, 5.1, 10.4, 0.2}, std::array{0.0, -5.1, 10.4, 0.2},
        std::array{5.1, 0.0, 0.2, 10.4}, std::array{-5.1, 0.0, 0.2, 10.4}}) {
    ShapeSpec wall;
    wall.center_m = {cx, cy};
    wall.size_m = {sx, sy};
    o.world.walls.push_back(wall);
  }
  o.world.drive.mode = DriveMode::kSchedule;
  o.world.drive.schedule = {{10.0, 0.0, 1.5}};
  Simulator sim(o);
  Trajectory truth;
  truth.Append(sim.time(), sim.Truth().map_from_base);
  std::vector<LaserScan> scans;
  while (sim.time().seconds() < 3.0) {
    for (const Record& r : sim.Step().records) {
      if (const auto* scan = std::get_if<LaserScan>(&r)) scans.push_back(*scan);
    }
    truth.Append(sim.time(), sim.Truth().map_from_base);
  }
  const LaserScan& scan = scans.back();
  double max_error = 0.0, skew_effect = 0.0;
  for (std::size_t i = 0; i < scan.ranges_m.size(); ++i) {
    const Time t = AddSeconds(scan.time, static_cast<double>(i) * scan.time_increment_s);
    const Pose2 laser = *truth.Interpolate(t) * scan.base_from_laser;
    const Pose2 laser_at_start = *truth.Interpolate(scan.time) * scan.base_from_laser;
    auto room_range = [&](const Pose2& from) {
      const double a = from.theta() + scan.BeamAngle(i);
      const double dx = std::cos(a), dy = std::sin(a);
      double best = 1e9;
      if (dx > 1e-12) best = std::min(best, (5.0 - from.x()) / dx);
      if (dx < -1e-12) best = std::min(best, (-5.0 - from.x()) / dx);
      if (dy > 1e-12) best = std::min(best, (5.0 - from.y()) / dy);
      if (dy < -1e-12) best = std::min(best, (-5.0 - from.y()) / dy);
      return best;
    };
    const double expected = room_range(laser);
    if (std::abs(expected - room_range(laser_at_start)) > skew_effect) {
      skew_effect = std::abs(expected - room_range(laser_at_start));
    }
    max_error = std::max(max_error, std::abs(scan.ranges_m[i] - expected));
  }
  EXPECT_LT(max_error, 1e-4);
  EXPECT_GT(skew_effect, 0.03);
}

// Distance from `from` along beam `i` of `scan` to the inner faces of the 10 m square room
// centred on the origin.
double SquareRoomRange(const LaserScan& scan, std::size_t i, const Pose2& from) {
  const double a = from.theta() + scan.BeamAngle(i);
  const double dx = std::cos(a), dy = std::sin(a);
  double best = 1e9;
  if (dx > 1e-12) best = std::min(best, (5.0 - from.x()) / dx);
  if (dx < -1e-12) best = std::min(best, (-5.0 - from.x()) / dx);
  if (dy > 1e-12) best = std::min(best, (5.0 - from.y()) / dy);
  if (dy < -1e-12) best = std::min(best, (-5.0 - from.y()) / dy);
  return best;
}

TEST(SimulatorTest, TeleportMovesTheRobotWithoutSweepingAcrossTheJump) {
  SimulatorOptions o;
  o.robot = WithoutNoise(RobotSpec{});
  for (const auto& [cx, cy, sx, sy] :
       {std::array{0.0, 5.1, 10.4, 0.2}, std::array{0.0, -5.1, 10.4, 0.2},
        std::array{5.1, 0.0, 0.2, 10.4}, std::array{-5.1, 0.0, 0.2, 10.4}}) {
    ShapeSpec wall;
    wall.center_m = {cx, cy};
    wall.size_m = {sx, sy};
    o.world.walls.push_back(wall);
  }
  Simulator sim(o);
  const Pose2 target(2.0, 1.0, 0.5);
  std::vector<LaserScan> scans;
  std::vector<TruthSample> truths;
  while (sim.time().seconds() < 1.5) {
    // 1.01 s is in the middle of the scan that starts at 1.0 s.
    if (sim.time() == Time::FromSeconds(1.01)) sim.Teleport(target);
    const StepResult step = sim.Step();
    for (std::size_t i = 0; i < step.records.size(); ++i) {
      if (const auto* scan = std::get_if<LaserScan>(&step.records[i])) scans.push_back(*scan);
      truths.push_back(step.truth[i]);
    }
  }
  for (const TruthSample& t : truths) {
    const Pose2 expected = t.time <= Time::FromSeconds(1.01) ? Pose2() : target;
    EXPECT_NEAR(t.map_from_base.x(), expected.x(), 0.01) << t.time.seconds();
    EXPECT_NEAR(t.map_from_base.theta(), expected.theta(), 0.01) << t.time.seconds();
  }
  const LaserScan& split = scans[40];  // the scan starting at 1.0 s
  ASSERT_EQ(split.time, Time::FromSeconds(1.0));
  for (std::size_t i = 0; i < split.ranges_m.size(); ++i) {
    const Time t = AddSeconds(split.time, static_cast<double>(i) * split.time_increment_s);
    const Pose2 base = t <= Time::FromSeconds(1.01) ? Pose2() : target;
    EXPECT_NEAR(split.ranges_m[i], SquareRoomRange(split, i, base * split.base_from_laser), 2e-3)
        << "beam " << i;
  }
}

TEST(SimulatorTest, TheLidarSeesAMovingObstacleWhereItIs) {
  // A standing robot looks along +x; a 1 m wide trolley crosses 4 m ahead, and beyond it a wall.
  SimulatorOptions o;
  o.robot = WithoutNoise(RobotSpec{});
  ShapeSpec wall;
  wall.center_m = {8.0, 0.0};
  wall.size_m = {0.2, 20.0};
  o.world.walls.push_back(wall);
  ObstacleSpec trolley;
  trolley.shape.size_m = {0.6, 1.0};
  trolley.path_m = {{4.3, -3.0}, {4.3, 3.0}};
  trolley.speed_m_s = 1.0;
  trolley.loop = false;
  o.world.obstacles.push_back(trolley);
  Simulator sim(o);
  const double laser_x = o.robot.lidar.mount.x_m;
  int blocked = 0, clear = 0;
  while (sim.time().seconds() < 6.0) {
    const StepResult step = sim.Step();
    for (const Record& r : step.records) {
      const auto* scan = std::get_if<LaserScan>(&r);
      if (scan == nullptr) continue;
      const std::size_t ahead = scan->ranges_m.size() / 2;  // beam 540 points along +x
      // The trolley's centre when this beam was taken; it moves 2 cm during one scan.
      const Time t = AddSeconds(scan->time, static_cast<double>(ahead) * scan->time_increment_s);
      const double y = sim.world().ObstaclePositionAt(0, t).y();
      if (std::abs(y) < 0.45) {
        EXPECT_NEAR(scan->ranges_m[ahead], 4.0 - laser_x, 1e-3) << "t = " << t.seconds();
        ++blocked;
      } else if (std::abs(y) > 0.55) {
        EXPECT_NEAR(scan->ranges_m[ahead], 7.9 - laser_x, 1e-3) << "t = " << t.seconds();
        ++clear;
      }
    }
  }
  EXPECT_GT(blocked, 20);
  EXPECT_GT(clear, 100);
}

}  // namespace
}  // namespace slamrig::sim
