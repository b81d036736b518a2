#include "slam/pf/rbpf.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>

#include "slam/odometry/scan_sync.h"
#include "slam/pf/testing/rbpf_run.h"
#include "slam/pf/testing/synthetic_run.h"

namespace slamrig::slam {
namespace {

using namespace rbpf_testing;  // NOLINT(build/namespaces): the shared fixtures

// Right odometry down a featureless corridor seen only 8 m ahead: the second scan, 3 m on, reaches
// past the stretch the first one mapped, so at the odometry's pose many of its points fall on
// unknown cells, while a pose 3 m back along the axis matches them all. The scan cannot place the
// robot along the axis (a degenerate direction), so the check must keep the odometry; trusting
// every direction of the window's match, it moved the robot back along the corridor (as on intel,
// where the path jumped 1.3 m along a corridor and came back).
TEST(RbpfTest, OdometryCheckKeepsRightOdometryAlongACorridor) {
  const testing::SegmentWorld world(
      {{{-100.0, -1.0}, {100.0, -1.0}}, {{-100.0, 1.0}, {100.0, 1.0}}});
  testing::RangeFinderSpec lidar;
  lidar.num_beams = 271;
  lidar.angle_increment_rad = 1.0 * 3.14159265358979 / 180.0;
  lidar.range_max_m = 8.0;
  auto rejections = [&](double ratio) {
    RandomEngine noise(3);
    RbpfOptions options = FastOptions();
    options.odometry_degenerate_ratio = ratio;
    Rbpf filter(options);
    const Pose2 step(3.0, 0.0, 0.0);
    filter.AddScan(world.Scan(Pose2(), Time(), lidar, &noise), Pose2());
    filter.AddScan(world.Scan(step, Time(), lidar, &noise), step);
    return filter.odometry_rejections();
  };
  const int trusted = rejections(0.0);
  RecordProperty("rejections_every_direction_trusted", std::to_string(trusted));
  EXPECT_EQ(rejections(RbpfOptions().odometry_degenerate_ratio), 0);
  // The case is one the check gets wrong when it trusts every direction of the match.
  EXPECT_EQ(trusted, 1);
}

// Tempering from the independent points scales every particle's log-weight increment by one
// factor, min(1, independent / points) for the scan: the proposals (same seed) and the particles'
// order by weight are those of the untempered filter, and the factor is the one counted
// independently from the scan's match points.
TEST(RbpfTest, IndependentPointTemperingScalesEveryWeightAlike) {
  const ShortRun& run = GetShortRun();
  RbpfOptions options = FastOptions();
  options.resample_neff_ratio = 0.0;  // no resampling: the particles stay in step
  options.weight_correlation_length_m = 0.0;
  Rbpf full(options);
  options.weight_correlation_length_m = 0.1;
  Rbpf tempered(options);
  int updates = 0;
  for (const SyncedScan& s : run.scans) {
    const RbpfStep a = full.AddScan(s.scan, s.increment);
    const RbpfStep b = tempered.AddScan(s.scan, s.increment);
    if (!a.updated || updates++ == 0) continue;  // the first scan only starts the maps
    const std::vector<MatchPoint> points =
        MakeMatchPoints(s.scan, options.points, options.map.resolution_m);
    const double expected = std::min(1.0, static_cast<double>(CountIndependentPoints(points, 0.1)) /
                                              static_cast<double>(points.size()));
    EXPECT_DOUBLE_EQ(b.weight_exponent, expected);
    EXPECT_DOUBLE_EQ(a.weight_exponent, 1.0);
    // The office's walls are sampled densely: tempered, but not to nothing.
    EXPECT_LT(b.weight_exponent, 0.9);
    EXPECT_GT(b.weight_exponent, 0.1);
    const std::vector<RbpfParticle>& pa = full.particles();
    const std::vector<RbpfParticle>& pb = tempered.particles();
    ASSERT_EQ(pa.size(), pb.size());
    for (std::size_t i = 0; i < pa.size(); ++i) {
      EXPECT_EQ(pa[i].pose.x(), pb[i].pose.x());
      EXPECT_EQ(pa[i].pose.theta(), pb[i].pose.theta());
      for (std::size_t j = 0; j < pa.size(); ++j) {
        // The normalised log-weights differ by a constant: their differences scale by the factor.
        EXPECT_NEAR(pb[i].log_weight - pb[j].log_weight,
                    expected * (pa[i].log_weight - pa[j].log_weight),
                    1e-9 * (1.0 + std::abs(pa[i].log_weight - pa[j].log_weight)));
        EXPECT_EQ(pa[i].log_weight < pa[j].log_weight, pb[i].log_weight < pb[j].log_weight);
      }
    }
    break;  // one update: later ones add increments with different factors
  }
  EXPECT_EQ(updates, 2);
}

// proposal_spread scales the draw around the proposal's mean and nothing else: the same seed gives
// the same climb and the same Gaussian, so the half-spread pose lies halfway between the mean
// (spread 0) and the full draw (spread 1), particle for particle.
TEST(RbpfTest, ProposalSpreadScalesTheDrawAroundTheProposalMean) {
  const ShortRun& run = GetShortRun();
  auto first_update = [&](double spread) {
    RbpfOptions options = FastOptions();
    options.proposal_spread = spread;
    options.resample_neff_ratio = 0.0;  // keeps particle i in slot i
    Rbpf filter(options);
    filter.AddScan(run.scans[0].scan, Pose2());
    Pose2 motion;
    for (std::size_t i = 1; i < run.scans.size(); ++i) {
      motion = motion * run.scans[i].increment;
      if (filter.AddScan(run.scans[i].scan, run.scans[i].increment).updated) break;
    }
    EXPECT_EQ(filter.update_count(), 2);
    std::vector<Pose2> poses;
    for (const RbpfParticle& p : filter.particles()) poses.push_back(p.pose);
    return poses;
  };
  const std::vector<Pose2> mean = first_update(0.0);
  const std::vector<Pose2> half = first_update(0.5);
  const std::vector<Pose2> full = first_update(1.0);
  ASSERT_EQ(mean.size(), full.size());
  double largest_draw = 0.0;
  for (std::size_t i = 0; i < mean.size(); ++i) {
    EXPECT_NEAR(half[i].x(), 0.5 * (mean[i].x() + full[i].x()), 1e-9) << i;
    EXPECT_NEAR(half[i].y(), 0.5 * (mean[i].y() + full[i].y()), 1e-9) << i;
    EXPECT_NEAR(half[i].theta(), 0.5 * (mean[i].theta() + full[i].theta()), 1e-9) << i;
    largest_draw = std::max(largest_draw, (full[i].translation() - mean[i].translation()).norm());
  }
  // The draw is not degenerate: at full spread the particles leave their means.
  EXPECT_GT(largest_draw, 1e-4);
}

// The path is one node per update, shared between particles with a common past, and the best
// particle's path ends at the pose the filter reports.
TEST(RbpfTest, ParticlesShareTheirPastAndTheirMapTiles) {
  const ShortRun& run = GetShortRun();
  RbpfOptions options = FastOptions();
  // Untempered weights resample often, so that 120 scans show the sharing clearly.
  options.weight_exponent = 1.0;
  Rbpf filter(options);
  RbpfStep step;
  for (std::size_t i = 0; i < 120; ++i)
    step = filter.AddScan(run.scans[i].scan, run.scans[i].increment);
  const std::vector<Pose2> path = filter.BestUpdatePoses();
  ASSERT_EQ(static_cast<int>(path.size()), filter.update_count());
  EXPECT_EQ(path.front(), Pose2());
  if (step.updated) {
    EXPECT_EQ(path.back(), step.best_pose);
  }
  ASSERT_GT(filter.resample_count(), 0);

  // Every path reaches back to the one root; after resampling, paths share their older nodes.
  const RbpfPoseNode* root = nullptr;
  int shared_with_best = 0;
  for (const RbpfParticle& p : filter.particles()) {
    const RbpfPoseNode* node = p.history.get();
    while (node->parent) node = node->parent.get();
    if (!root) root = node;
    EXPECT_EQ(node, root);
    // Particles whose parent node is the best's parent share everything before the last update.
    shared_with_best += p.history->parent == filter.best().history->parent;
  }
  EXPECT_GT(shared_with_best, 0);

  // The maps share tiles: fewer distinct tiles than particles times tiles per map.
  const int per_map = filter.best().map.num_tiles();
  ASSERT_GT(per_map, 10);
  EXPECT_LT(filter.DistinctTiles(), options.num_particles * per_map * 3 / 4);
  EXPECT_GE(filter.DistinctTiles(), per_map);
  int shared = 0;
  for (const RbpfParticle& p : filter.particles()) shared += p.map.SharedTiles(filter.best().map);
  EXPECT_GT(shared, per_map);  // some tile of the best map is held by another particle too
}

TEST(RbpfTest, FiltersOnlyAfterEnoughMotion) {
  const ShortRun& run = GetShortRun();
  RbpfOptions options = FastOptions();
  options.min_update_distance_m = 0.25;
  options.min_update_angle_rad = 10.0;
  Rbpf filter(options);
  filter.AddScan(run.scans[0].scan, Pose2());
  const RbpfStep a = filter.AddScan(run.scans[1].scan, Pose2(0.1, 0.0, 0.05));
  const RbpfStep b = filter.AddScan(run.scans[2].scan, Pose2(0.1, 0.0, 0.0));
  EXPECT_FALSE(a.updated);
  EXPECT_FALSE(b.updated);
  EXPECT_EQ(filter.update_count(), 1);
  const Pose2 expected = Pose2(0.1, 0.0, 0.05) * Pose2(0.1, 0.0, 0.0);
  EXPECT_NEAR(b.best_pose.x(), expected.x(), 1e-12);
  EXPECT_NEAR(b.best_pose.y(), expected.y(), 1e-12);
  const RbpfStep c = filter.AddScan(run.scans[3].scan, Pose2(0.1, 0.0, 0.0));
  EXPECT_TRUE(c.updated);
  EXPECT_EQ(filter.update_count(), 2);
}

// Feeds `scans` (with their odometry gaps) to `filter`; the last pose's error against `truth`.
slam::testing::EndError EndErrorAfter(Rbpf& filter, const std::vector<SyncedScan>& scans,
                                      const std::vector<GroundTruthPose>& truth) {
  RbpfStep step;
  for (const SyncedScan& s : scans) step = filter.AddScan(s.scan, s.increment, s.odometry_gap_s);
  return slam::testing::EndPoseError(step.best_pose, truth);
}

// A gap in the log while the robot turns by more than 1 rad: the scans and odometry of the turn
// are missing and the scan after it comes with no motion and the odometry's silence. The update
// after the gap matches at every heading near by and takes the most likely match as the
// increment; without that search (odometry_gap_s 0) the filter goes on from the wrong heading.
TEST(RbpfTest, AfterAGapInTheOdometryTheFilterFindsTheTurnItMissed) {
  const ShortRun& run = GetShortRun();
  const std::vector<GroundTruthPose>& truth = run.run.truth;
  ASSERT_EQ(run.scans.size(), truth.size());
  const slam::testing::Stretch turn = slam::testing::FirstTurn(truth, 1.0, 30, 30);
  ASSERT_GT(turn.to, turn.from) << "no turn in the run";
  const std::vector<SyncedScan> scans = slam::testing::WithOdometryGap(run.scans, turn);
  struct Outcome {
    slam::testing::EndError end;
    int corrections = 0;
  };
  auto run_with = [&](const RbpfOptions& options) {
    Rbpf filter(options);
    const slam::testing::EndError end = EndErrorAfter(filter, scans, truth);
    return Outcome{end, filter.gap_corrections()};
  };
  RbpfOptions options = FastOptions();
  options.num_particles = 5;  // the search is the best particle's: a few keep the test fast
  const Outcome searched = run_with(options);
  // The filter on this short run ends a few centimetres and hundredths of a radian off.
  EXPECT_LT(searched.end.position_m, 0.15);
  EXPECT_LT(searched.end.heading_rad, 0.1);
  EXPECT_EQ(searched.corrections, 1);
  options.odometry_gap_s = 0.0;
  const Outcome not_searched = run_with(options);
  EXPECT_GT(not_searched.end.heading_rad, 0.5);
  EXPECT_EQ(not_searched.corrections, 0);
}

// `scans` with the turn over `stretch` missed by the wheels, its scans dropped: scan `stretch.to`
// comes with the stretch's translation and no rotation. Not a gap: the odometry was heard
// throughout (a turn on the spot the encoders missed, on a log with a few seconds between scans).
std::vector<SyncedScan> WithMissedTurn(const std::vector<SyncedScan>& scans,
                                       slam::testing::Stretch stretch) {
  std::vector<SyncedScan> out(scans.begin(), scans.begin() + stretch.from + 1);
  Pose2 total;
  for (std::size_t i = stretch.from + 1; i <= stretch.to; ++i) total = total * scans[i].increment;
  SyncedScan last = scans[stretch.to];
  last.increment = Pose2(total.x(), total.y(), 0.0);
  out.push_back(last);
  out.insert(out.end(), scans.begin() + stretch.to + 1, scans.end());
  return out;
}

// The closed form of RingOffsetRms against the circle's points themselves, over random pose
// pairs (turns up to a half turn, shifts of metres) and radii.
TEST(RbpfTest, RingOffsetIsTheRootMeanSquareOfTheCirclesDisplacement) {
  RandomEngine rng(11);
  std::uniform_real_distribution<double> shift(-3.0, 3.0);
  std::uniform_real_distribution<double> turn(-3.1, 3.1);
  std::uniform_real_distribution<double> radius(0.0, 5.0);
  constexpr int kPoints = 360;
  for (int trial = 0; trial < 200; ++trial) {
    std::array<double, 7> draws;  // drawn in order: one seed, one case
    for (int k = 0; k < 6; ++k) draws[k] = k % 3 == 2 ? turn(rng) : shift(rng);
    draws[6] = radius(rng);
    const Pose2 a(draws[0], draws[1], draws[2]);
    const Pose2 b(draws[3], draws[4], draws[5]);
    const double r = draws[6];
    double sum = 0.0;
    for (int k = 0; k < kPoints; ++k) {
      const double angle = 2.0 * std::numbers::pi * k / kPoints;
      const Eigen::Vector2d p(r * std::cos(angle), r * std::sin(angle));
      sum += ((a * p) - (b * p)).squaredNorm();
    }
    EXPECT_NEAR(RingOffsetRms(a, b, r), std::sqrt(sum / kPoints), 1e-9) << "trial " << trial;
    EXPECT_DOUBLE_EQ(RingOffsetRms(a, a, r), 0.0);
  }
  // Radius 0: the positions alone; a pure turn: the chord it sweeps.
  EXPECT_DOUBLE_EQ(RingOffsetRms(Pose2(1.0, 2.0, 0.3), Pose2(4.0, 6.0, -1.0), 0.0), 5.0);
  EXPECT_NEAR(RingOffsetRms(Pose2(0.0, 0.0, 0.5), Pose2(0.0, 0.0, -0.5), 2.0),
              2.0 * 2.0 * std::sin(0.5), 1e-12);
}

TEST(RbpfTest, TheTurnCheckFindsATurnTheWheelsMissed) {
  const ShortRun& run = GetShortRun();
  const std::vector<GroundTruthPose>& truth = run.run.truth;
  const slam::testing::Stretch turn = slam::testing::FirstTurn(truth, 1.0, 30, 30);
  ASSERT_GT(turn.to, turn.from) << "no turn in the run";
  const std::vector<SyncedScan> scans = WithMissedTurn(run.scans, turn);
  auto run_with = [&](bool turn_check, int* rejections) {
    RbpfOptions options = FastOptions();
    options.num_particles = 5;  // the check is the best particle's: a few keep the test fast
    options.odometry_turn_check = turn_check;
    Rbpf filter(options);
    const slam::testing::EndError end = EndErrorAfter(filter, scans, truth);
    *rejections = filter.odometry_rejections();
    return end;
  };
  int checked_rejections = 0;
  const slam::testing::EndError checked = run_with(true, &checked_rejections);
  EXPECT_LT(checked.position_m, 0.15);
  EXPECT_LT(checked.heading_rad, 0.1);
  EXPECT_GE(checked_rejections, 1);
  // Without it the particles' own climbs, from draws of the Gaussian, never reach the turn.
  int unchecked_rejections = 0;
  const slam::testing::EndError unchecked = run_with(false, &unchecked_rejections);
  EXPECT_GT(unchecked.heading_rad, 0.5);
  RecordProperty("turn_rad", std::to_string(truth[turn.to].map_from_base.theta() -
                                            truth[turn.from].map_from_base.theta()));
}

// The map check judges the same missed turn without moving anything: the filter without the
// turn check goes on from the wrong heading (as above), and the scan after the turn, which its
// map holds at the right heading, is its witness, the scan's points placed metres from where the
// map holds them. On the run as recorded the best path agrees with its map wherever it looked.
TEST(RbpfTest, TheMapCheckSaysWhereThePathContradictsItsMap) {
  const ShortRun& run = GetShortRun();
  const std::vector<GroundTruthPose>& truth = run.run.truth;
  const slam::testing::Stretch turn = slam::testing::FirstTurn(truth, 1.0, 30, 30);
  ASSERT_GT(turn.to, turn.from) << "no turn in the run";
  struct Judged {
    slam::testing::EndError end;
    std::size_t witnesses;
    double contradiction_m;
  };
  auto judge = [&](const std::vector<SyncedScan>& scans, double window_m) {
    RbpfOptions options = FastOptions();
    options.num_particles = 5;  // the check is the best particle's: a few keep the test fast
    options.map_check_window_m = window_m;
    Rbpf filter(options);
    const slam::testing::EndError end = EndErrorAfter(filter, scans, truth);
    return Judged{end, filter.map_witnesses().size(), filter.MapContradictionM()};
  };
  const std::vector<SyncedScan> missed = WithMissedTurn(run.scans, turn);
  const Judged wrong = judge(missed, RbpfOptions().map_check_window_m);
  EXPECT_GT(wrong.end.heading_rad, 0.5);
  EXPECT_GE(wrong.witnesses, 1u);
  EXPECT_GT(wrong.contradiction_m, 1.0);
  const Judged right = judge(run.scans, RbpfOptions().map_check_window_m);
  EXPECT_LT(right.end.heading_rad, 0.1);
  EXPECT_LT(right.contradiction_m, 0.2);
  // The check only judges: the same path without it, and no witness.
  const Judged unchecked = judge(missed, 0.0);
  EXPECT_EQ(unchecked.witnesses, 0u);
  EXPECT_EQ(unchecked.contradiction_m, 0.0);
  EXPECT_EQ(unchecked.end.position_m, wrong.end.position_m);
  EXPECT_EQ(unchecked.end.heading_rad, wrong.end.heading_rad);
  RecordProperty("contradiction_m", std::to_string(wrong.contradiction_m));
}

// Without odometry the increments are scan matches, and the prior's failure is an alias of its
// local map: one increment a metre off (a door spacing along a corridor, a room's other wall), the
// next ones right again from the wrong pose. The update that takes it matches the best
// particle's map poorly; the map holds the place the scan came from, and the search there at
// every heading finds it. Told that its increments are wheels', the filter follows the alias.
TEST(RbpfTest, AScanMatchedIncrementsAliasIsFoundInTheBestMap) {
  const ShortRun& run = GetShortRun();
  const std::vector<GroundTruthPose>& truth = run.run.truth;
  std::vector<SyncedScan> scans = run.scans;
  const std::size_t alias = scans.size() * 2 / 3;
  scans[alias].increment = scans[alias].increment * Pose2(-1.0, 0.6, 0.0);
  auto run_with = [&](bool scan_matched, int* corrections) {
    RbpfOptions options = FastOptions();
    options.num_particles = 5;  // the search is the best particle's: a few keep the test fast
    Rbpf filter(options);
    filter.SetScanMatchedIncrements(scan_matched);
    const slam::testing::EndError end = EndErrorAfter(filter, scans, truth);
    *corrections = filter.gap_corrections();
    return end;
  };
  int corrections = 0;
  const slam::testing::EndError searched = run_with(true, &corrections);
  EXPECT_LT(searched.position_m, 0.15);
  EXPECT_LT(searched.heading_rad, 0.1);
  EXPECT_GE(corrections, 1);
  int wheel_corrections = 0;
  const slam::testing::EndError followed = run_with(false, &wheel_corrections);
  EXPECT_GT(followed.position_m, 0.8);
  EXPECT_EQ(wheel_corrections, 0);
  RecordProperty("scans", std::to_string(scans.size()));
}

TEST(RbpfTest, ValidateNamesFieldValueAndRule) {
  RbpfOptions options;
  options.num_particles = 0;
  options.matcher.kernel_cells = -1;
  options.motion.min_xy_m = 0.0;
  options.weight_exponent = 0.0;
  EXPECT_THAT(options.Validate(), ::testing::ElementsAre("particles = 0; must be > 0",
                                                         "matcher.kernel_cells = -1; must be >= 0",
                                                         "motion.min_xy_m = 0; must be > 0",
                                                         "weight_exponent = 0; must be in (0, 1]"));
  EXPECT_TRUE(RbpfOptions{}.Validate().empty());
}

// The particles' tiled maps write every hit to its end cell: the plain grid's range-noise model
// (map.range_stddev_m) is refused rather than silently ignored.
TEST(RbpfTest, RefusesTheMapRangeNoiseItDoesNotImplement) {
  RbpfOptions options;
  options.map.range_stddev_m = 0.01;
  EXPECT_THAT(options.Validate(),
              ::testing::ElementsAre("map.range_stddev_m = 0.01; must be 0 for the rbpf"));
}

}  // namespace
}  // namespace slamrig::slam
