#include "slam/graph/graph_slam.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "slam/eval/loop_closure_score.h"
#include "slam/matching/testing/segment_world.h"
#include "slam/odometry/scan_sync.h"
#include "slam/pf/testing/synthetic_run.h"

namespace slamrig::slam {
namespace {

// RMSE of the positions of `poses` against `truth` expressed from its first pose (both start at
// the identity; no alignment, so drift counts in full).
double PositionRmse(const std::vector<Pose2>& poses, const std::vector<Pose2>& truth) {
  double sum = 0.0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    sum += (truth[0].Between(truth[i]).translation() - poses[i].translation()).squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(poses.size()));
}

// Truth at each scan, from the run's truth channel (one sample per scan, in order).
std::vector<Pose2> TruthAtScans(const testing::SyntheticRun& run) {
  std::vector<Pose2> truth;
  for (const GroundTruthPose& t : run.truth) truth.push_back(t.map_from_base);
  return truth;
}

// A 181-beam lidar over 270 degrees (1.5 degree steps), as the tests' scans are taken.
testing::RangeFinderSpec Lidar181() {
  testing::RangeFinderSpec lidar;
  lidar.num_beams = 181;
  lidar.angle_increment_rad = 1.5 * M_PI / 180.0;
  lidar.angle_min_rad = -M_PI / 2.0 * 1.5;
  return lidar;
}

// A 6 m x 4 m room with a desk and a pillar: enough structure for ICP in every direction.
testing::SegmentWorld RoomWithDeskAndPillar() {
  testing::SegmentWorld world({});
  world.AddBox(0.0, 0.0, 6.0, 4.0);
  world.AddBox(1.0, 2.5, 1.6, 3.1);
  world.AddBox(4.2, 0.8, 4.6, 1.4);
  return world;
}

TEST(GraphSlamTest, ClosesTheOfficeLoopAndBeatsOdometry) {
  testing::SyntheticRunOptions options;
  options.waypoints = testing::OfficeLoop();
  options.laps = 2;
  options.max_duration_s = 140.0;  // 70 m: one lap and a third
  options.scan_rate_hz = 10.0;
  options.lidar.num_beams = 181;
  options.lidar.angle_increment_rad = 1.5 * M_PI / 180.0;
  options.right_scale_error = 0.03;  // strong systematic drift
  const testing::SyntheticRun run =
      testing::MakeSyntheticRun(testing::SegmentWorld::Office(), options);
  const ScanSyncResult synced = SyncToScans(run.records, ScanSyncOptions{});
  const std::vector<Pose2> truth = TruthAtScans(run);
  ASSERT_EQ(truth.size(), synced.scans.size());

  GraphSlam slam{GraphSlamOptions{}};
  for (const SyncedScan& s : synced.scans) slam.Add(s.scan, s.increment);
  slam.Finish();
  const std::vector<Pose2> poses = slam.Poses();
  ASSERT_EQ(poses.size(), synced.scans.size());

  const double graph = PositionRmse(poses, truth);
  const double odometry = PositionRmse(DeadReckoningPoses(synced.scans), truth);
  EXPECT_GT(slam.counts().loop_closures, 0);
  EXPECT_GT(slam.counts().optimizations, 0);
  EXPECT_LT(graph, 0.1);
  EXPECT_LT(graph, 0.25 * odometry) << "odometry " << odometry;
  // The final solution passes the optimality check (a low-noise graph: the relaxation is tight).
  EXPECT_TRUE(slam.counts().certified);
  EXPECT_TRUE(std::isfinite(slam.counts().certificate_lambda_min));
  // A consistent graph: it does not call itself diverged.
  EXPECT_FALSE(slam.counts().diverged) << slam.counts().strained_edges << " strained edges";

  // Every accepted closure agrees with the truth.
  std::vector<Pose2> reference;
  for (const Pose2& t : truth) reference.push_back(truth[0].Between(t));
  const LoopClosureScore score = ScoreLoopClosures(slam.loop_closures(), reference);
  EXPECT_EQ(score.false_closures, 0);
  EXPECT_GE(score.recall, 0.8);
}

// The back end on a thread of its own beside the front end gives the very results of one thread:
// every online pose Add returns, every final pose, every count and closure, bit for bit.
TEST(GraphSlamTest, ABackEndOnItsOwnThreadGivesTheSameResults) {
  testing::SyntheticRunOptions options;
  options.waypoints = testing::OfficeLoop();
  options.laps = 2;
  options.max_duration_s = 140.0;  // one lap and a third: closures and optimisations
  options.scan_rate_hz = 10.0;
  options.lidar.num_beams = 181;
  options.lidar.angle_increment_rad = 1.5 * M_PI / 180.0;
  options.right_scale_error = 0.03;
  const testing::SyntheticRun run =
      testing::MakeSyntheticRun(testing::SegmentWorld::Office(), options);
  const ScanSyncResult synced = SyncToScans(run.records, ScanSyncOptions{});
  struct Result {
    std::vector<Pose2> online, poses;
    GraphSlamCounts counts;
    std::vector<LoopClosure> closures;
  };
  auto slam = [&](int threads) {
    GraphSlamOptions o;
    o.num_threads = threads;
    GraphSlam g{o};
    Result r;
    for (const SyncedScan& s : synced.scans) r.online.push_back(g.Add(s.scan, s.increment));
    g.Finish();
    r.poses = g.Poses();
    r.counts = g.counts();
    r.closures = g.loop_closures();
    return r;
  };
  const Result one = slam(1), two = slam(2);
  ASSERT_GT(one.counts.loop_closures, 0);
  ASSERT_GT(one.counts.optimizations, 0);
  auto same = [](const std::vector<Pose2>& a, const std::vector<Pose2>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (std::memcmp(&a[i], &b[i], sizeof(Pose2)) != 0) return false;
    }
    return true;
  };
  EXPECT_TRUE(same(one.online, two.online));
  EXPECT_TRUE(same(one.poses, two.poses));
  EXPECT_EQ(one.counts.keyframes, two.counts.keyframes);
  EXPECT_EQ(one.counts.loop_candidates, two.counts.loop_candidates);
  EXPECT_EQ(one.counts.loop_closures, two.counts.loop_closures);
  EXPECT_EQ(one.counts.optimizations, two.counts.optimizations);
  EXPECT_EQ(one.counts.final_chi2, two.counts.final_chi2);
  ASSERT_EQ(one.closures.size(), two.closures.size());
  for (std::size_t i = 0; i < one.closures.size(); ++i) {
    EXPECT_EQ(one.closures[i].from_scan, two.closures[i].from_scan);
    EXPECT_EQ(one.closures[i].to_scan, two.closures[i].to_scan);
  }
}

struct IdenticalRoomsRun {
  GraphSlamCounts counts;
  std::vector<LoopClosure> closures;
  LoopClosureScore score;
  std::vector<LoopClosure> rejected;
};

// Two identical rooms 8 m apart. The robot circles room A twice, moves to room B (honest
// odometry) and circles it twice. The loop search is made generous (a 10 m radius and window), so
// room B's nodes are matched against room A's submaps and the correlative search finds the
// aliased pose 8 m away.
IdenticalRoomsRun RunIdenticalRooms(GraphSlamOptions options) {
  testing::SegmentWorld world({});
  for (const double x0 : {0.0, 8.0}) {
    world.AddBox(x0, 0.0, x0 + 4.0, 4.0);
    world.AddBox(x0 + 1.0, 2.5, x0 + 1.6, 3.1);  // the same desk in each
    world.AddBox(x0 + 2.8, 0.8, x0 + 3.2, 1.2);  // and the same pillar
  }
  const testing::RangeFinderSpec lidar = Lidar181();
  RandomEngine rng(3);
  // A circle in a room, 40 poses, then (without scans) a jump to the other room.
  std::vector<Pose2> truth;
  for (const double x0 : {0.0, 8.0}) {
    for (int lap = 0; lap < 2; ++lap) {
      for (int k = 0; k < 40; ++k) {
        const double a = 2.0 * M_PI * k / 40.0;
        truth.emplace_back(x0 + 2.0 + 0.8 * std::cos(a), 2.0 + 0.8 * std::sin(a), a + M_PI / 2.0);
      }
    }
  }
  options.loop_skip_keyframes = 10;
  options.loop_search_radius_m = 10.0;
  options.loop_max_search_radius_m = 10.0;
  options.correlative.linear_window_m = 10.0;
  options.loop_max_candidates = 3;
  GraphSlam slam{options};
  Pose2 previous = truth[0];
  for (std::size_t i = 0; i < truth.size(); ++i) {
    Pose2 increment = previous.Between(truth[i]);
    slam.Add(world.Scan(truth[i], Time{static_cast<std::int64_t>(i) * 100'000'000}, lidar, &rng),
             increment);
    previous = truth[i];
  }
  slam.Finish();
  std::vector<Pose2> reference;
  for (const Pose2& t : truth) reference.push_back(truth[0].Between(t));
  return {slam.counts(), slam.loop_closures(), ScoreLoopClosures(slam.loop_closures(), reference),
          slam.rejected_closures()};
}

// The chi2 gate must reject the aliased closures, as they disagree with the graph by far more
// than the graph's uncertainty.
TEST(GraphSlamTest, IdenticalRoomsYieldNoFalseClosure) {
  const IdenticalRoomsRun run = RunIdenticalRooms(GraphSlamOptions{});
  EXPECT_GT(run.counts.loop_closures, 0);  // within each room
  EXPECT_GT(run.counts.rejected, 0);       // room B was searched against room A
  EXPECT_EQ(run.score.false_closures, 0);
  for (const LoopClosure& c : run.closures) {
    EXPECT_EQ(c.from_scan < 80, c.to_scan < 80) << c.from_scan << " -> " << c.to_scan;
  }
  // Every rejected candidate is reported, older scan first; room B against room A among them.
  ASSERT_EQ(static_cast<int>(run.rejected.size()), run.counts.rejected);
  bool aliased = false;
  for (const LoopClosure& c : run.rejected) {
    EXPECT_LT(c.from_scan, c.to_scan);
    aliased = aliased || (c.from_scan < 80 && c.to_scan >= 80);
  }
  EXPECT_TRUE(aliased);
}

// With the chi2 gate against the graph opened wide, the aliased closures get through on their
// own without pairwise consistency; with it (the default) they are rejected (room B's closures to
// room A contradict room B's own closures through the odometry) and the true ones kept. Without
// either, the final check still takes them out: the optimum leaves them strained.
TEST(GraphSlamTest, PairwiseConsistencyRejectsAliasedClosuresWithoutTheGate) {
  GraphSlamOptions options;
  EXPECT_EQ(options.loop_consistency, LoopConsistency::kPairwise);
  EXPECT_TRUE(options.loop_drop_strained);
  options.loop_chi2_gate = 1e9;
  options.loop_consistency = LoopConsistency::kNone;
  options.loop_drop_strained = false;
  const IdenticalRoomsRun open = RunIdenticalRooms(options);
  ASSERT_GT(open.score.false_closures, 0);  // the gate was what kept them out
  // The false closures pull room B onto room A against the odometry: the graph says so.
  EXPECT_GT(open.counts.strained_edges, 0);
  EXPECT_TRUE(open.counts.diverged) << open.counts.strained_edges << " strained edges";

  options.loop_drop_strained = true;
  const IdenticalRoomsRun dropped = RunIdenticalRooms(options);
  EXPECT_EQ(dropped.score.false_closures, 0);
  EXPECT_GE(dropped.counts.dropped_strained, open.score.false_closures);
  EXPECT_GE(dropped.score.recall, 0.8);
  EXPECT_EQ(dropped.counts.strained_edges, 0);
  EXPECT_FALSE(dropped.counts.diverged);
  options.loop_drop_strained = false;

  options.loop_consistency = LoopConsistency::kPairwise;
  const IdenticalRoomsRun pairwise = RunIdenticalRooms(options);
  EXPECT_EQ(pairwise.score.false_closures, 0);
  EXPECT_GT(pairwise.counts.inconsistent, 0);
  EXPECT_GE(pairwise.score.recall, 0.8);
  for (const LoopClosure& c : pairwise.closures) {
    EXPECT_EQ(c.from_scan < 80, c.to_scan < 80) << c.from_scan << " -> " << c.to_scan;
  }
}

// One odometry increment 0.3 rad off (a turn logged late), with ICP odometry's correction gate too
// tight to fix it and its search off (its prior stands, as when ICP falls into a local minimum):
// the odometry check re-matches the node against the last nodes and repairs the edge; without it
// the heading error stays.
TEST(GraphSlamTest, OdometryCheckRepairsAWrongOdometryEdge) {
  const testing::SegmentWorld world = RoomWithDeskAndPillar();
  const testing::RangeFinderSpec lidar = Lidar181();
  std::vector<Pose2> truth;
  for (int k = 0; k < 30; ++k) truth.emplace_back(1.0 + 0.13 * k, 1.5, 0.02 * k);
  const int wrong = 15;
  auto run = [&](int check_nodes) {
    GraphSlamOptions options;
    options.keyframe_distance_m = 0.1;
    options.odometry.max_correction_m = 0.02;
    options.odometry.max_correction_rad = 0.02;
    options.odometry.search.sigmas = 0.0;
    options.loop_max_candidates = 0;
    options.odometry_check_nodes = check_nodes;
    GraphSlam slam{options};
    RandomEngine rng(4);
    for (std::size_t i = 0; i < truth.size(); ++i) {
      Pose2 increment = i == 0 ? Pose2() : truth[i - 1].Between(truth[i]);
      if (static_cast<int>(i) == wrong) increment = increment * Pose2(0.0, 0.0, 0.3);
      slam.Add(world.Scan(truth[i], Time{static_cast<std::int64_t>(i) * 100'000'000}, lidar, &rng),
               increment);
    }
    slam.Finish();
    const Pose2 error = truth[0].Between(truth.back()).Between(slam.Poses().back());
    return std::pair{slam.counts().odometry_rematched, error};
  };
  const auto [rematched_off, error_off] = run(0);
  const auto [rematched_on, error_on] = run(3);
  EXPECT_EQ(rematched_off, 0);
  EXPECT_GT(std::abs(error_off.theta()), 0.2);
  EXPECT_GE(rematched_on, 1);
  EXPECT_LT(std::abs(error_on.theta()), 0.03);
  EXPECT_LT(error_on.translation().norm(), 0.05);
}

// The wheel odometry misses a turn altogether (a gap in its messages while the robot turned
// 1.2 rad in place), far beyond ICP's convergence basin and the odometry check's local window:
// ICP odometry's match fails there, and the widened check (every heading) at the next node finds
// the turn; without it the heading error stays.
TEST(GraphSlamTest, WideOdometryCheckRecoversAMissedTurn) {
  const testing::SegmentWorld world = RoomWithDeskAndPillar();
  const testing::RangeFinderSpec lidar = Lidar181();
  constexpr int kTurn = 12;
  constexpr double kTurnRad = 1.2;
  std::vector<Pose2> truth;
  Pose2 pose(1.0, 1.2, 0.0);
  for (int k = 0; k < 30; ++k) {
    if (k == kTurn) pose = pose * Pose2(0.0, 0.0, kTurnRad);
    truth.push_back(pose);
    pose = pose * Pose2(0.1, 0.0, 0.0);
  }
  auto run = [&](double wide_below) {
    GraphSlamOptions options;
    options.keyframe_distance_m = 0.3;
    options.loop_max_candidates = 0;
    options.odometry_check_wide_below = wide_below;
    GraphSlam slam{options};
    RandomEngine rng(5);
    for (std::size_t i = 0; i < truth.size(); ++i) {
      Pose2 increment = i == 0 ? Pose2() : truth[i - 1].Between(truth[i]);
      if (static_cast<int>(i) == kTurn) increment = increment * Pose2(0.0, 0.0, -kTurnRad);
      slam.Add(world.Scan(truth[i], Time{static_cast<std::int64_t>(i) * 100'000'000}, lidar, &rng),
               increment);
    }
    slam.Finish();
    return truth[0].Between(truth.back()).Between(slam.Poses().back());
  };
  const Pose2 error_off = run(0.0);
  const Pose2 error_on = run(GraphSlamOptions{}.odometry_check_wide_below);
  EXPECT_GT(std::abs(error_off.theta()), 0.5);
  EXPECT_LT(std::abs(error_on.theta()), 0.03);
  EXPECT_LT(error_on.translation().norm(), 0.05);
}

// A wide corridor whose far end (14-20 m ahead) is all that fixes the position along it, and a
// patch that moves with the robot (a glass facade answers only at normal incidence: its returns
// stay beside the robot, as on the generated campus): the odometry check's re-match fits the last
// nodes better by standing still, a node spacing back, and the graph comes out a metre short.
// The wheels' distance rules those re-matches out.
TEST(GraphSlamTest, OdometryCheckKeepsToTheWheelsWhereTheScansCannotSee) {
  testing::SegmentWorld world(
      {{{-20.0, -4.0}, {20.0, -4.0}}, {{-20.0, 4.0}, {20.0, 4.0}}, {{20.0, -4.0}, {20.0, 4.0}}});
  const testing::RangeFinderSpec lidar = Lidar181();
  std::vector<Pose2> truth;
  for (int k = 0; k < 60; ++k) truth.emplace_back(0.1 * k, 0.0, 0.0);
  auto run = [&](double wheel_confidence) {
    GraphSlamOptions options;
    options.loop_max_candidates = 0;
    options.odometry_check_wheel_confidence = wheel_confidence;
    GraphSlam slam{options};
    RandomEngine rng(5);
    for (std::size_t i = 0; i < truth.size(); ++i) {
      LaserScan scan =
          world.Scan(truth[i], Time{static_cast<std::int64_t>(i) * 100'000'000}, lidar, &rng);
      // The patch: 3 m away, 80 to 100 degrees to the left, wherever the robot is.
      for (std::size_t b = 0; b < scan.ranges_m.size(); ++b) {
        const double angle = scan.BeamAngle(b);
        if (angle > 80.0 * M_PI / 180.0 && angle < 100.0 * M_PI / 180.0) scan.ranges_m[b] = 3.0f;
      }
      slam.Add(scan, i == 0 ? Pose2() : truth[i - 1].Between(truth[i]));
    }
    slam.Finish();
    return std::pair{slam.counts().odometry_rematched,
                     truth[0].Between(truth.back()).Between(slam.Poses().back())};
  };
  const auto [rematched_free, error_free] = run(1.0);
  const auto [rematched, error] = run(GraphSlamOptions{}.odometry_check_wheel_confidence);
  EXPECT_GT(rematched_free, 0);
  EXPECT_GT(error_free.translation().norm(), 0.5);
  EXPECT_EQ(rematched, 0);
  EXPECT_LT(error.translation().norm(), 0.05);
}

// A stretch where the lidar returns nothing (every beam at its maximum range: scans without
// points, so no node either): the odometry stands in, and the edge over it carries at least the
// odometry's noise model, whose heading drift per metre is four times the graph's own; with the
// option off, and on every matched edge, the graph's model holds.
TEST(GraphSlamTest, AnEdgeOverABlindStretchCarriesTheOdometrysNoise) {
  const testing::SegmentWorld world = RoomWithDeskAndPillar();
  const testing::RangeFinderSpec lidar = Lidar181();
  auto run = [&](bool blind_noise) {
    GraphSlamOptions options;
    options.keyframe_distance_m = 0.3;
    options.loop_max_candidates = 0;
    options.blind_edge_odometry_noise = blind_noise;
    GraphSlam slam{options};
    RandomEngine rng(7);
    Pose2 pose(1.0, 1.2, 0.0);
    for (int k = 0; k < 40; ++k) {
      LaserScan scan =
          world.Scan(pose, Time{static_cast<std::int64_t>(k) * 100'000'000}, lidar, &rng);
      if (k >= 15 && k < 25) {
        std::fill(scan.ranges_m.begin(), scan.ranges_m.end(), scan.range_max_m);
      }
      slam.Add(scan, k == 0 ? Pose2() : Pose2(0.1, 0.0, 0.0));
      pose = pose * Pose2(0.1, 0.0, 0.0);
    }
    slam.Finish();
    // Each odometry edge's heading sigma over the graph model's for its length and turn.
    std::vector<double> ratios;
    for (const PoseGraphEdge& e : slam.graph().edges()) {
      if (e.kind != EdgeKind::kOdometry) continue;
      const double d = e.measurement.translation().norm();
      const double model = options.edge_sigma_yaw_per_rad * std::abs(e.measurement.theta()) +
                           options.edge_sigma_yaw_per_m * d + options.edge_sigma_yaw_floor_rad;
      ratios.push_back(1.0 / std::sqrt(e.information(2, 2)) / model);
    }
    return ratios;
  };
  const std::vector<double> on = run(true), off = run(false);
  ASSERT_GE(on.size(), 8u);
  // The edges before the stretch matched (the model); the one over it (about 1.2 m) is the
  // odometry's: (0.02 * 1.2 + 0.002) / (0.005 * 1.2 + 0.002) = 3.25 times, at least.
  for (std::size_t i = 0; i < 4; ++i) EXPECT_NEAR(on[i], 1.0, 1e-9) << i;
  EXPECT_GT(*std::max_element(on.begin(), on.end()), 3.0);
  for (std::size_t i = 0; i < off.size(); ++i) EXPECT_NEAR(off[i], 1.0, 1e-9) << i;
}

}  // namespace
}  // namespace slamrig::slam
