#include "slam/pf/particle_filter.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "slam/odometry/gaussian.h"
#include "slam/odometry/scan_sync.h"
#include "slam/pf/testing/synthetic_run.h"
#include "slam/types/trajectory.h"

namespace slamrig::slam {
namespace {

using ShortRun = testing::ShortOfficeRun;
const ShortRun& GetShortRun() { return testing::GetShortOfficeRun(); }

double PositionRmse(const Trajectory& estimate, const std::vector<GroundTruthPose>& truth) {
  std::vector<Pose2> poses;
  for (const StampedPose& p : estimate.poses()) poses.push_back(p.pose);
  return testing::AnchoredPositionRmse(poses, truth);
}

// The filter over a whole run: best and mean particle per scan, the map, and clouds.
struct PfRun {
  Trajectory trajectory;
  Trajectory mean_trajectory;
  OccupancyGrid map{OccupancyGridOptions{}};
  std::vector<std::vector<Particle>> clouds;
};

PfRun RunParticleFilter(const std::vector<SyncedScan>& scans, const ParticleFilterOptions& options,
                        std::size_t cloud_every = 0) {
  PfRun run;
  ParticleFilter filter(options);
  for (std::size_t i = 0; i < scans.size(); ++i) {
    const ParticleFilterStep step = filter.AddScan(scans[i].scan, scans[i].increment);
    run.trajectory.Append(scans[i].scan.time, step.best_pose);
    run.mean_trajectory.Append(scans[i].scan.time, step.mean_pose);
    if (cloud_every > 0 && i % cloud_every == 0) run.clouds.push_back(filter.particles());
  }
  run.map = filter.map();
  return run;
}

Trajectory DeadReckoning(const std::vector<SyncedScan>& scans) {
  Trajectory trajectory;
  const std::vector<Pose2> poses = DeadReckoningPoses(scans);
  for (std::size_t i = 0; i < scans.size(); ++i) trajectory.Append(scans[i].scan.time, poses[i]);
  return trajectory;
}

ParticleFilterOptions FastOptions() {
  ParticleFilterOptions options;
  options.num_particles = 30;
  options.seed = 17;
  return options;
}

TEST(ParticleFilterTest, BeatsDeadReckoningOnASyntheticOfficeRun) {
  const ShortRun& run = GetShortRun();
  ASSERT_EQ(run.scans.size(), run.run.truth.size());
  const double dr = PositionRmse(DeadReckoning(run.scans), run.run.truth);
  const PfRun pf = RunParticleFilter(run.scans, FastOptions());
  const double pf_rmse = PositionRmse(pf.trajectory, run.run.truth);
  RecordProperty("dead_reckoning_rmse_m", std::to_string(dr));
  RecordProperty("pf_rmse_m", std::to_string(pf_rmse));
  EXPECT_GT(dr, 0.3);
  EXPECT_LT(pf_rmse, 0.1) << "dead reckoning " << dr;
  EXPECT_LT(pf_rmse, 0.5 * dr);
  EXPECT_LT(PositionRmse(pf.mean_trajectory, run.run.truth), 0.1);
}

TEST(ParticleFilterTest, ReportsPresetRunsAndTracks) {
  const ShortRun& run = GetShortRun();
  ParticleFilterOptions options = ParticleFilterOptions::ReportsPreset();
  options.num_particles = 30;
  const PfRun pf = RunParticleFilter(run.scans, options);
  EXPECT_LT(PositionRmse(pf.trajectory, run.run.truth), 0.3);
}

TEST(ParticleFilterTest, MapCorrelationWithoutRefinementTracks) {
  const ShortRun& run = GetShortRun();
  ParticleFilterOptions options = FastOptions();
  options.observation = ObservationModel::kMapCorrelation;
  options.correlation.value = CorrelationValue::kOccupiedIndicator;
  options.adaptive_sigma.enabled = false;  // no field to sharpen
  options.refine = false;
  options.observation_scale = 1.0;
  const PfRun pf = RunParticleFilter(run.scans, options);
  EXPECT_LT(PositionRmse(pf.trajectory, run.run.truth), 0.1);
}

TEST(ParticleFilterTest, SameSeedSameTrajectoryWhateverTheThreadCount) {
  const ShortRun& run = GetShortRun();
  std::vector<SyncedScan> scans(run.scans.begin(), run.scans.begin() + 90);
  ParticleFilterOptions options = FastOptions();
  const PfRun a = RunParticleFilter(scans, options, 50);
  const PfRun b = RunParticleFilter(scans, options);
  options.num_threads = 3;
  const PfRun c = RunParticleFilter(scans, options);
  ASSERT_EQ(a.trajectory.size(), scans.size());
  for (std::size_t i = 0; i < scans.size(); ++i) {
    ASSERT_EQ(a.trajectory[i].pose, b.trajectory[i].pose) << i;
    ASSERT_EQ(a.trajectory[i].pose, c.trajectory[i].pose) << i;
    ASSERT_EQ(a.mean_trajectory[i].pose, c.mean_trajectory[i].pose) << i;
  }
  EXPECT_EQ(a.map.DenseLogOdds(), c.map.DenseLogOdds());
  ASSERT_EQ(a.clouds.size(), 2u);
  EXPECT_EQ(a.clouds[1].size(), 30u);
  options.seed = 18;
  options.num_threads = 1;
  const PfRun d = RunParticleFilter(scans, options);
  EXPECT_NE(a.trajectory.poses().back().pose, d.trajectory.poses().back().pose);
}

// Between updates the particles stay put and the reported poses follow the odometry.
TEST(ParticleFilterTest, FiltersOnlyAfterEnoughMotion) {
  const ShortRun& run = GetShortRun();
  ParticleFilterOptions options = FastOptions();
  options.min_update_distance_m = 0.25;
  options.min_update_angle_rad = 10.0;
  ParticleFilter filter(options);
  filter.AddScan(run.scans[0].scan, Pose2());
  const std::vector<Particle> before = filter.particles();
  const ParticleFilterStep a = filter.AddScan(run.scans[1].scan, Pose2(0.1, 0.0, 0.05));
  const ParticleFilterStep b = filter.AddScan(run.scans[2].scan, Pose2(0.1, 0.0, 0.0));
  EXPECT_FALSE(a.updated);
  EXPECT_FALSE(b.updated);
  EXPECT_EQ(filter.particles()[7].pose, before[7].pose);
  const Pose2 expected = Pose2(0.1, 0.0, 0.05) * Pose2(0.1, 0.0, 0.0);
  EXPECT_NEAR(b.best_pose.x(), expected.x(), 1e-12);
  EXPECT_NEAR(b.best_pose.y(), expected.y(), 1e-12);
  const ParticleFilterStep c = filter.AddScan(run.scans[3].scan, Pose2(0.1, 0.0, 0.0));
  EXPECT_TRUE(c.updated);
  EXPECT_NE(filter.particles()[7].pose, before[7].pose);
}

// A kidnapping into the mapped part: the scans jump back to where the robot was 15 s earlier while
// the odometry says nothing. The filter must call itself lost at the jump, leave the map alone
// while lost, relocalise on the map and end where the truth is.
TEST(ParticleFilterTest, FindsItselfLostAfterAKidnappingAndRelocalises) {
  const ShortRun& run = GetShortRun();
  const std::size_t jump_at = 300, back_to = 100;
  ASSERT_GT(run.scans.size(), jump_at);
  ParticleFilterOptions options = FastOptions();
  // In this world of long bare walls a displaced scan still scores ~0.7 of its usual quality
  // (in the simulated office it drops to ~0.35): a stricter ratio than the default's 0.5.
  options.relocalisation.enabled = true;
  // That ratio is a level for the field's fixed 0.08 m: the sigma the map's sharpness gives
  // here (0.06 m) scores the run's last scan, turning into new ground, at 0.63 of the usual
  // quality, a false alarm in the last update that this test cannot see resolved. The kidnapping
  // scenario checks the defaults.
  options.relocalisation.lost_ratio = 0.7;
  options.adaptive_sigma.enabled = false;
  ParticleFilter filter(options);
  for (std::size_t i = 0; i < jump_at; ++i)
    filter.AddScan(run.scans[i].scan, run.scans[i].increment);
  ASSERT_EQ(filter.lost_count(), 0);
  int lost_at = -1, relocalised_at = -1;
  std::vector<float> map_while_lost;
  bool was_lost = false;
  ParticleFilterStep step;
  for (std::size_t i = back_to; i < run.scans.size(); ++i) {
    // The first scan after the jump comes with no motion at all.
    step = filter.AddScan(run.scans[i].scan, i == back_to ? Pose2() : run.scans[i].increment);
    const int k = static_cast<int>(i - back_to);
    if (step.lost && lost_at < 0) lost_at = k;
    if (step.lost && !was_lost) map_while_lost = filter.map().DenseLogOdds();
    was_lost = step.lost;
    if (step.lost) {
      EXPECT_EQ(filter.map().DenseLogOdds(), map_while_lost) << k;
    }
    if (step.relocalised && relocalised_at < 0) relocalised_at = k;
  }
  EXPECT_GE(lost_at, 0);
  EXPECT_LT(lost_at, 10);
  EXPECT_GT(relocalised_at, lost_at);
  EXPECT_LT(relocalised_at, 40);  // 4 s of data at 10 Hz
  EXPECT_GE(filter.relocalisation_count(), 1);
  EXPECT_EQ(filter.lost_count(), filter.relocalisation_count()) << "lost at the end";
  // Without relocalisation it ends ~10 m off (the next test); with it, about where the same
  // filter ends when nothing happened (~0.2 m here: along these bare walls it keeps the odometry).
  const auto end_error = [&](const Pose2& estimate) {
    return ((run.run.truth.front().map_from_base * estimate).translation() -
            run.run.truth.back().map_from_base.translation())
        .norm();
  };
  const double undisturbed =
      end_error(RunParticleFilter(run.scans, options).trajectory.poses().back().pose);
  RecordProperty("undisturbed_end_error_m", std::to_string(undisturbed));
  EXPECT_LT(end_error(step.best_pose), undisturbed + 0.1);
}

// A few scans that match nowhere (a crowd around the robot: every beam ends 0.5-1.5 m out)
// raise the alarm but are no kidnapping: nothing on the map fits them better than where the
// robot is, so once the scans are clean again tracking resumes from the cloud, with no
// relocalisation, and the run ends on the truth.
TEST(ParticleFilterTest, ABadScanIsNotAKidnapping) {
  const ShortRun& run = GetShortRun();
  ASSERT_GT(run.scans.size(), 330u);
  ParticleFilterOptions options = FastOptions();
  options.relocalisation.enabled = true;
  ParticleFilter filter(options);
  RandomEngine rng(5);
  ParticleFilterStep step;
  bool lost = false;
  for (std::size_t i = 0; i < run.scans.size(); ++i) {
    LaserScan scan = run.scans[i].scan;
    if (i >= 300 && i < 306) {
      for (float& r : scan.ranges_m) r = static_cast<float>(0.5 + Uniform01(rng));
    }
    step = filter.AddScan(scan, run.scans[i].increment);
    lost = lost || step.lost;
    EXPECT_FALSE(step.relocalised) << i;
  }
  EXPECT_TRUE(lost) << "the crowd should raise the alarm";
  EXPECT_GE(filter.lost_count(), 1);
  EXPECT_EQ(filter.resumed_count(), filter.lost_count());
  EXPECT_EQ(filter.relocalisation_count(), 0);
  EXPECT_FALSE(step.lost);
  const Pose2 end = run.run.truth.front().map_from_base * step.best_pose;
  EXPECT_LT((end.translation() - run.run.truth.back().map_from_base.translation()).norm(), 0.2);
}

// Without relocalisation the same filter stays where the jump left it.
TEST(ParticleFilterTest, WithoutRelocalisationAKidnappingIsNotUndone) {
  const ShortRun& run = GetShortRun();
  ParticleFilterOptions options = FastOptions();
  options.relocalisation.enabled = false;
  ParticleFilter filter(options);
  for (std::size_t i = 0; i < 250; ++i) filter.AddScan(run.scans[i].scan, run.scans[i].increment);
  ParticleFilterStep step;
  for (std::size_t i = 100; i < run.scans.size(); ++i) {
    step = filter.AddScan(run.scans[i].scan, i == 100 ? Pose2() : run.scans[i].increment);
    EXPECT_FALSE(step.lost);
  }
  const Pose2 end = run.run.truth.front().map_from_base * step.best_pose;
  EXPECT_GT((end.translation() - run.run.truth.back().map_from_base.translation()).norm(), 2.0);
}

// A false-relocalisation trap: a ring corridor that looks the same turned half a turn about its
// centre, so every place has a twin across the building, and the odometry between the twins'
// scans agrees too. On the first lap a cart stands against the inner wall and is mapped; on the
// second it is gone, so where the robot is the wall behind it is missing from the map and its
// twin fits the scans a little better. Just there a crowd hides the walls for half a second while
// the wheels spin, the odometry turning 0.4 rad that the robot did not: the filter calls itself
// lost and no longer fits where the odometry put it. The best place on the whole map is then the
// twin, 7 m away, but nothing says the robot left: it must not be put there, and it must end on
// the truth.
TEST(ParticleFilterTest, AnAliasedPlaceDoesNotTakeTheFilterAway) {
  testing::SegmentWorld world({});
  world.AddBox(0.0, 0.0, 12.0, 8.0);
  world.AddBox(3.0, 3.0, 9.0, 5.0);
  // Pillars along the corridor and their twins, point-reflected about the centre (6, 4).
  for (const Eigen::Vector2d& c : {Eigen::Vector2d(4.0, 0.4), Eigen::Vector2d(7.5, 2.6),
                                   Eigen::Vector2d(11.6, 2.0), Eigen::Vector2d(10.0, 5.6)}) {
    world.AddBox(c.x() - 0.2, c.y() - 0.2, c.x() + 0.2, c.y() + 0.2);
    world.AddBox(11.8 - c.x(), 7.8 - c.y(), 12.2 - c.x(), 8.2 - c.y());
  }
  testing::SegmentWorld with_cart = world;
  with_cart.AddBox(10.4, 2.4, 11.2, 2.95);
  testing::SyntheticRunOptions run_options;
  run_options.waypoints = {{1.5, 1.5}, {10.5, 1.5}, {10.5, 6.5}, {1.5, 6.5}};
  run_options.laps = 2;
  run_options.max_duration_s = 45.0;
  run_options.speed_m_s = 1.0;
  run_options.scan_rate_hz = 10.0;
  run_options.lidar.num_beams = 271;
  run_options.lidar.angle_increment_rad = 1.0 * 3.14159265358979 / 180.0;
  run_options.right_scale_error = 0.03;
  run_options.left_scale_error = -0.03;
  run_options.gyro_bias_rad_s = 0.01;
  const testing::SyntheticRun run = testing::MakeSyntheticRun(with_cart, run_options);
  std::vector<SyncedScan> scans = SyncToScans(run.records, ScanSyncOptions{}).scans;
  const std::size_t crowd_from = 380, crowd_to = 385, cart_gone = crowd_from;
  ASSERT_GT(scans.size(), crowd_to + 40);
  ASSERT_EQ(scans.size(), run.truth.size());
  RandomEngine rng(5);
  for (std::size_t i = cart_gone; i < scans.size(); ++i) {
    ASSERT_EQ(scans[i].scan.time, run.truth[i].time);
    scans[i].scan =
        world.Scan(run.truth[i].map_from_base, scans[i].scan.time, run_options.lidar, &rng);
  }

  ParticleFilter filter(FastOptions());
  ParticleFilterStep step;
  bool lost = false;
  for (std::size_t i = 0; i < scans.size(); ++i) {
    LaserScan scan = scans[i].scan;
    Pose2 increment = scans[i].increment;
    if (i >= crowd_from && i < crowd_to) {
      for (float& r : scan.ranges_m) r = static_cast<float>(0.5 + Uniform01(rng));
      if (i == crowd_from) increment = increment * Pose2(0.0, 0.0, 0.4);
    }
    step = filter.AddScan(scan, increment);
    lost = lost || step.lost;
    EXPECT_FALSE(step.relocalised) << i;
  }
  EXPECT_TRUE(lost) << "the crowd should raise the alarm";
  EXPECT_EQ(filter.relocalisation_count(), 0);
  EXPECT_EQ(filter.resumed_count(), filter.lost_count());
  const Pose2 end = run.truth.front().map_from_base * step.best_pose;
  EXPECT_LT((end.translation() - run.truth.back().map_from_base.translation()).norm(), 0.3);
}

// Kidnapped into a place with a twin: the ring corridor looks the same turned half a turn about
// its centre, but for a pillar in the east corridor that the twin lacks, hidden from the west
// half of the south corridor. The robot is carried from the west corridor back to the south
// corridor's west half, where on the first lap a box stood against the wall: gone now, so the
// twin across the building fits the first scans a little better than the true place. The filter
// must not relocalise on the twin, but wait until the scans tell the two apart (the pillar comes
// into view after ~2 m) and then relocalise on the true place.
TEST(ParticleFilterTest, AKidnappingIntoAnAliasedPlaceWaitsForTheScansToTellTheTwinsApart) {
  testing::SegmentWorld world({});
  world.AddBox(0.0, 0.0, 12.0, 8.0);
  world.AddBox(3.0, 3.0, 9.0, 5.0);
  for (const Eigen::Vector2d& c : {Eigen::Vector2d(4.0, 0.4), Eigen::Vector2d(7.5, 2.6),
                                   Eigen::Vector2d(11.6, 2.0), Eigen::Vector2d(10.0, 5.6)}) {
    world.AddBox(c.x() - 0.2, c.y() - 0.2, c.x() + 0.2, c.y() + 0.2);
    world.AddBox(11.8 - c.x(), 7.8 - c.y(), 12.2 - c.x(), 8.2 - c.y());
  }
  world.AddBox(11.4, 4.3, 11.8, 4.7);  // no twin at (0.4, 3.5)
  testing::SegmentWorld with_box = world;
  with_box.AddBox(5.0, 0.0, 5.4, 0.3);
  testing::SyntheticRunOptions run_options;
  run_options.waypoints = {{1.5, 1.5}, {10.5, 1.5}, {10.5, 6.5}, {1.5, 6.5}};
  run_options.laps = 2;
  run_options.max_duration_s = 40.0;
  run_options.speed_m_s = 1.0;
  run_options.scan_rate_hz = 10.0;
  run_options.lidar.num_beams = 271;
  run_options.lidar.angle_increment_rad = 1.0 * 3.14159265358979 / 180.0;
  run_options.right_scale_error = 0.03;
  run_options.left_scale_error = -0.03;
  run_options.gyro_bias_rad_s = 0.01;
  const testing::SyntheticRun run = testing::MakeSyntheticRun(with_box, run_options);
  const std::vector<SyncedScan> scans = SyncToScans(run.records, ScanSyncOptions{}).scans;
  const std::size_t jump_at = 380, back_to = 30, replay_to = 200;
  ASSERT_EQ(scans.size(), run.truth.size());
  ASSERT_GT(scans.size(), jump_at);
  const Pose2 at_jump = run.truth[jump_at].map_from_base;
  ASSERT_LT(at_jump.y(), 2.0) << "on the second lap in the south corridor at the jump";
  ASSERT_GT(at_jump.x(), 7.0);

  ParticleFilter filter(FastOptions());
  for (std::size_t i = 0; i < jump_at; ++i) filter.AddScan(scans[i].scan, scans[i].increment);
  ASSERT_EQ(filter.lost_count(), 0);
  RandomEngine rng(5);
  const Pose2 anchor = run.truth.front().map_from_base;
  ParticleFilterStep step;
  bool lost = false;
  for (std::size_t i = back_to; i < replay_to; ++i) {
    // The box is gone; the first scan after the jump comes with no motion.
    const LaserScan scan =
        world.Scan(run.truth[i].map_from_base, scans[i].scan.time, run_options.lidar, &rng);
    step = filter.AddScan(scan, i == back_to ? Pose2() : scans[i].increment);
    lost = lost || step.lost;
    if (step.relocalised) {
      const Eigen::Vector2d at = (anchor * step.best_pose).translation();
      EXPECT_LT((at - run.truth[i].map_from_base.translation()).norm(), 0.5)
          << "relocalised at scan " << i << " to " << at.transpose();
    }
  }
  EXPECT_TRUE(lost) << "the kidnapping should raise the alarm";
  EXPECT_FALSE(step.lost);
  const Pose2 end = anchor * step.best_pose;
  EXPECT_LT((end.translation() - run.truth[replay_to - 1].map_from_base.translation()).norm(), 0.3);
}

// A featureless corridor 60 m long, driven 25 m down its middle with the wheels 2 % long and a
// 10 m lidar, so that no scan sees an end wall: nothing but the odometry says how far the robot
// went. Along the axis the estimate must follow the odometry (solution remapping applied to the
// cloud as a whole), not drift by resampling or by the map's pull towards where it was written
// from; across it and in heading the scans keep the estimate on the truth.
TEST(ParticleFilterTest, AlongAFeaturelessCorridorTheEstimateFollowsTheOdometry) {
  testing::SegmentWorld world({});
  world.AddBox(0.0, -1.2, 60.0, 1.2);
  testing::SyntheticRunOptions run_options;
  run_options.waypoints = {{12.0, 0.0}, {58.0, 0.0}};
  run_options.laps = 1;
  run_options.max_duration_s = 50.0;
  run_options.speed_m_s = 0.5;
  run_options.scan_rate_hz = 10.0;
  run_options.lidar.num_beams = 271;
  run_options.lidar.angle_increment_rad = 1.0 * 3.14159265358979 / 180.0;
  run_options.lidar.range_max_m = 10.0;
  run_options.right_scale_error = 0.02;
  run_options.left_scale_error = 0.02;
  const testing::SyntheticRun run = testing::MakeSyntheticRun(world, run_options);
  const std::vector<SyncedScan> scans = SyncToScans(run.records, ScanSyncOptions{}).scans;
  ASSERT_EQ(scans.size(), run.truth.size());
  const PfRun pf = RunParticleFilter(scans, FastOptions());
  const std::vector<Pose2> odometry = DeadReckoningPoses(scans);
  const Pose2 start = run.truth.front().map_from_base;
  double worst_along = 0.0, worst_across = 0.0;
  for (std::size_t i = 0; i < scans.size(); ++i) {
    const Pose2 estimate = start * pf.trajectory.poses()[i].pose;
    const Pose2 odometry_pose = start * odometry[i];
    const Pose2& truth = run.truth[i].map_from_base;
    worst_along = std::max(worst_along, std::abs(estimate.x() - odometry_pose.x()));
    worst_across = std::max(worst_across, std::abs(estimate.y() - truth.y()));
  }
  const double travelled = run.truth.back().map_from_base.x() - start.x();
  ASSERT_GT(travelled, 20.0);
  // The wheels' 2 % is there in both, and nowhere else to be seen.
  EXPECT_NEAR(start.x() + odometry.back().x() - run.truth.back().map_from_base.x(),
              0.02 * travelled, 0.1);
  EXPECT_LT(worst_along, 0.1);
  EXPECT_LT(worst_across, 0.05);
}

// A gap in the log while the robot turns: the scans and odometry of a turn are missing, and the
// scan after it comes with no motion and the odometry's silence (SyncedScan::odometry_gap_s).
// The update after the gap searches near by at every heading and puts the cloud where the scan
// fits; without that search (odometry_gap_s 0) the filter goes on from the wrong heading.
TEST(ParticleFilterTest, AfterAGapInTheOdometryTheFilterFindsTheTurnItMissed) {
  const ShortRun& run = GetShortRun();
  const std::vector<GroundTruthPose>& truth = run.run.truth;
  ASSERT_EQ(run.scans.size(), truth.size());
  // The first stretch, well after the start, over which the robot turns by more than 1 rad
  // within 3 s (what neither the filter's shift search nor its slip search could follow).
  const testing::Stretch turn = testing::FirstTurn(truth, 1.0, 30, 30);
  ASSERT_GT(turn.to, turn.from) << "no turn in the run";
  const std::vector<SyncedScan> scans = testing::WithOdometryGap(run.scans, turn);
  // The final pose's errors, and the corrections the gap search made.
  struct Outcome {
    testing::EndError end;
    int corrections = 0;
  };
  auto run_with = [&](const ParticleFilterOptions& options) {
    ParticleFilter filter(options);
    ParticleFilterStep step;
    for (const SyncedScan& s : scans) step = filter.AddScan(s.scan, s.increment, s.odometry_gap_s);
    return Outcome{testing::EndPoseError(step.best_pose, truth), filter.gap_correction_count()};
  };
  ParticleFilterOptions options = FastOptions();
  const Outcome searched = run_with(options);
  EXPECT_LT(searched.end.position_m, 0.1);
  EXPECT_LT(searched.end.heading_rad, 0.05);
  EXPECT_EQ(searched.corrections, 1);
  options.relocalisation.odometry_gap_s = 0.0;
  const Outcome not_searched = run_with(options);
  EXPECT_GT(not_searched.end.heading_rad, 0.5);
  EXPECT_EQ(not_searched.corrections, 0);
}

// The simulated office's walls are mapped sharply (a 1 cm range noise, scans 0.25 m apart): the
// field's sigma follows the median wall distance down from its 0.08 m start, and the filter
// tracks as before. Off, the sigma stays.
TEST(ParticleFilterTest, TheFieldSigmaFollowsHowSharpTheMapIs) {
  const ShortRun& run = GetShortRun();
  ParticleFilterOptions options = FastOptions();
  options.adaptive_sigma.enabled = true;
  options.adaptive_sigma.min_m = 0.02;
  options.adaptive_sigma.max_m = 0.2;
  options.adaptive_sigma.window_m = 0.06;
  ParticleFilter filter(options);
  std::vector<Pose2> poses;
  for (const SyncedScan& scan : run.scans) {
    poses.push_back(filter.AddScan(scan.scan, scan.increment).best_pose);
  }
  const double wall = filter.wall_distance_m();
  EXPECT_GT(wall, 0.005);
  EXPECT_LT(wall, 0.025);
  EXPECT_LT(filter.field_sigma_m(), 0.06);
  // Within the change ratio of its target.
  EXPECT_NEAR(filter.field_sigma_m(), options.adaptive_sigma.residual_factor * wall,
              options.adaptive_sigma.change_ratio * filter.field_sigma_m() + 1e-9);
  EXPECT_LT(testing::AnchoredPositionRmse(poses, run.run.truth), 0.1);

  ParticleFilterOptions off = FastOptions();
  off.adaptive_sigma.enabled = false;
  ParticleFilter fixed(off);
  for (const SyncedScan& scan : run.scans) fixed.AddScan(scan.scan, scan.increment);
  EXPECT_EQ(fixed.field_sigma_m(), FastOptions().likelihood_field.sigma_m);
  EXPECT_EQ(fixed.wall_distance_m(), 0.0);
}

TEST(ParticleFilterTest, AdaptiveSigmaNeedsItsWindowInsideTheFieldsReach) {
  ParticleFilterOptions options;
  options.adaptive_sigma.enabled = true;
  options.adaptive_sigma.min_m = 0.04;  // reach 3 x 0.04 = 0.12 < window 0.15
  EXPECT_THAT(options.Validate(),
              ::testing::ElementsAre("adaptive_sigma.window_m = 0.15; must be <= "
                                     "likelihood_field.cutoff_sigmas x adaptive_sigma.min_m"));
  options.adaptive_sigma.max_m = 0.03;
  EXPECT_THAT(options.Validate(),
              ::testing::Contains("adaptive_sigma.max_m = 0.03; must be >= min_m"));
  // The correlation model has no field to adapt: the reports' preset turns it off, and asking
  // for both is refused.
  ParticleFilterOptions reports = ParticleFilterOptions::ReportsPreset();
  EXPECT_THAT(reports.Validate(), ::testing::IsEmpty());
  reports.adaptive_sigma.enabled = true;
  EXPECT_THAT(reports.Validate(),
              ::testing::ElementsAre("adaptive_sigma.enabled = true; needs observation = "
                                     "likelihood_field (or set it false)"));
}

TEST(ParticleFilterTest, ValidateNamesFieldValueAndRule) {
  ParticleFilterOptions options;
  options.num_particles = 0;
  options.correlation.xy_half_width_cells = 20;
  EXPECT_THAT(options.Validate(),
              ::testing::ElementsAre("particles = 0; must be > 0",
                                     "correlation.xy_half_width_cells = 20; must be in [0, 15]"));
  EXPECT_TRUE(ParticleFilterOptions{}.Validate().empty());
  EXPECT_TRUE(ParticleFilterOptions::ReportsPreset().Validate().empty());
}

TEST(ParticleFilterTest, WeightedMeanAveragesYawOnTheCircle) {
  const std::vector<Particle> particles = {{Pose2(0, 0, 3.1), 0.5}, {Pose2(2, 0, -3.1), 0.5}};
  const Pose2 mean = WeightedMeanPose(particles);
  EXPECT_NEAR(mean.x(), 1.0, 1e-12);
  EXPECT_NEAR(std::abs(mean.theta()), 3.14159265358979, 1e-9);
}

}  // namespace
}  // namespace slamrig::slam

namespace slamrig::slam {
namespace {

// The synthetic robot's wheels are miscalibrated (testing::ShortOfficeRun): the odometry's heading
// error per metre, measured against the truth, is what the online calibration must find from the
// filter's own corrections.
TEST(ParticleFilterTest, OdometryCalibrationFindsTheWheelsHeadingDrift) {
  const ShortRun& run = GetShortRun();
  ASSERT_EQ(run.scans.size(), run.run.truth.size());
  double sum_error = 0.0, sum_distance = 0.0;
  for (std::size_t i = 1; i < run.scans.size(); ++i) {
    const Pose2 truth =
        run.run.truth[i - 1].map_from_base.Inverse() * run.run.truth[i].map_from_base;
    sum_error += NormalizeAngle(truth.theta() - run.scans[i].increment.theta());
    sum_distance += run.scans[i].increment.translation().norm();
  }
  const double true_drift = sum_error / sum_distance;
  ASSERT_GT(std::abs(true_drift), 0.005) << "the run's odometry should drift";
  ParticleFilterOptions options = FastOptions();
  options.odometry_calibration.enabled = true;
  options.odometry_calibration.memory_m = 1e6;  // the whole run, as the truth's ratio above
  options.odometry_calibration.prior_m = 0.5;
  ParticleFilter filter(options);
  for (const SyncedScan& s : run.scans) filter.AddScan(s.scan, s.increment);
  RecordProperty("true_drift_rad_per_m", std::to_string(true_drift));
  RecordProperty("fitted_drift_rad_per_m", std::to_string(filter.odometry_drift_rad_per_m()));
  EXPECT_NEAR(filter.odometry_drift_rad_per_m(), true_drift, 0.25 * std::abs(true_drift));
}

}  // namespace
}  // namespace slamrig::slam
