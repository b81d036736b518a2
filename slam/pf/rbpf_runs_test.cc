// The RBPF's longer synthetic runs (a few seconds each): whole filters over the short office run
// and its variants, too slow for the unit label.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "slam/odometry/scan_sync.h"
#include "slam/pf/rbpf.h"
#include "slam/pf/testing/rbpf_run.h"
#include "slam/pf/testing/synthetic_run.h"

namespace slamrig::slam {
namespace {

using namespace rbpf_testing;  // NOLINT(build/namespaces): the shared fixtures

TEST(RbpfTest, BeatsDeadReckoningOnASyntheticOfficeRun) {
  const ShortRun& run = GetShortRun();
  const double dr = PositionRmse(DeadReckoningPoses(run.scans), run.run.truth);
  const RbpfRun rbpf = RunFilter(run.scans, FastOptions());
  const double rmse = PositionRmse(rbpf.online, run.run.truth);
  RecordProperty("dead_reckoning_rmse_m", std::to_string(dr));
  RecordProperty("rbpf_rmse_m", std::to_string(rmse));
  EXPECT_GT(dr, 0.3);
  EXPECT_LT(rmse, 0.1) << "dead reckoning " << dr;
  EXPECT_LT(rmse, 0.3 * dr);
  EXPECT_GT(rbpf.resamples, 0);
  // Good odometry: the check never replaces it.
  EXPECT_EQ(rbpf.odometry_rejections, 0);
}

// Odometry that reports 3 s of driving round the corner as reversing (freiburg-079's odometry does
// the opposite: it counts reversals as forward motion): the odometry check follows the scans,
// while a filter that trusts the odometry as a Gaussian is dragged off by twice the distance.
TEST(RbpfTest, OdometryCheckFollowsTheScansWhenTheOdometryReversesItsSign) {
  const ShortRun& run = GetShortRun();
  std::vector<SyncedScan> scans = run.scans;
  for (std::size_t i = 320; i < 350 && i < scans.size(); ++i) {
    const Pose2& u = scans[i].increment;
    scans[i].increment = Pose2(-u.x(), -u.y(), u.theta());
  }
  RbpfOptions options = FastOptions();
  const RbpfRun with_check = RunFilter(scans, options);
  options.odometry_failure_probability = 0.0;
  const RbpfRun without_check = RunFilter(scans, options);
  const double rmse = PositionRmse(with_check.online, run.run.truth);
  const double rmse_without = PositionRmse(without_check.online, run.run.truth);
  RecordProperty("rmse_with_check_m", std::to_string(rmse));
  RecordProperty("rmse_without_check_m", std::to_string(rmse_without));
  EXPECT_LT(rmse, 0.1) << "without the check " << rmse_without;
  EXPECT_GT(rmse_without, 3.0 * rmse);
  EXPECT_GT(with_check.odometry_rejections, 0);
}

// Tempered weights (weight_exponent < 1) keep the effective sample size up, so the filter resamples
// less often and keeps more lineages alive, without losing the track.
TEST(RbpfTest, TemperedWeightsResampleLessOften) {
  const ShortRun& run = GetShortRun();
  RbpfOptions options = FastOptions();
  options.weight_correlation_length_m = 0.0;  // the uniform exponent alone
  options.weight_exponent = 1.0;
  const RbpfRun full = RunFilter(run.scans, options);
  options.weight_exponent = 0.25;
  const RbpfRun tempered = RunFilter(run.scans, options);
  RecordProperty("resamples_full", std::to_string(full.resamples));
  RecordProperty("resamples_tempered", std::to_string(tempered.resamples));
  EXPECT_GT(full.resamples, 0);
  EXPECT_LT(tempered.resamples, full.resamples * 3 / 4) << "full " << full.resamples;
  EXPECT_LT(PositionRmse(tempered.online, run.run.truth), 0.1);
}

// Per-point tempering changes the weights only: with the same seed the first update draws the
// untempered filter's poses, the reported exponent is the mean of the scan's independence weights
// (computed here from the match points), and over the run the flatter weights resample less.
TEST(RbpfTest, PerPointTemperingKeepsTheProposalAndFlattensTheWeights) {
  const ShortRun& run = GetShortRun();
  RbpfOptions options = FastOptions();
  options.weight_correlation_length_m = 0.0;
  const RbpfRun full = RunFilter(run.scans, options);
  Rbpf untempered_filter(options);
  options.weight_correlation_length_m = 0.1;
  options.weight_correlation_per_point = true;
  const RbpfRun tempered = RunFilter(run.scans, options);
  Rbpf filter(options);
  int updates = 0;
  for (const SyncedScan& s : run.scans) {
    const RbpfStep a = untempered_filter.AddScan(s.scan, s.increment);
    const RbpfStep b = filter.AddScan(s.scan, s.increment);
    if (!a.updated || updates++ == 0) continue;
    std::vector<MatchPoint> points =
        MakeMatchPoints(s.scan, options.points, options.map.resolution_m);
    AssignIndependenceWeights(points, 0.1);
    double mean = 0.0;
    for (const MatchPoint& p : points) mean += p.weight / static_cast<double>(points.size());
    EXPECT_NEAR(b.weight_exponent, mean, 1e-12);
    EXPECT_LT(b.weight_exponent, 0.9);
    EXPECT_GT(b.weight_exponent, 0.05);
    for (std::size_t i = 0; i < filter.particles().size(); ++i) {
      EXPECT_EQ(filter.particles()[i].pose.x(), untempered_filter.particles()[i].pose.x());
      EXPECT_EQ(filter.particles()[i].pose.theta(), untempered_filter.particles()[i].pose.theta());
    }
    break;
  }
  EXPECT_EQ(updates, 2);
  RecordProperty("resamples_full", std::to_string(full.resamples));
  RecordProperty("resamples_per_point", std::to_string(tempered.resamples));
  EXPECT_LT(tempered.resamples, full.resamples) << "full " << full.resamples;
  EXPECT_LT(PositionRmse(tempered.online, run.run.truth), 0.1);
}

TEST(RbpfTest, SameSeedSameTrajectoryWhateverTheThreadCount) {
  const ShortRun& run = GetShortRun();
  const std::vector<SyncedScan> scans(run.scans.begin(), run.scans.begin() + 80);
  RbpfOptions options = FastOptions();
  const RbpfRun a = RunFilter(scans, options);
  options.num_threads = 3;
  const RbpfRun b = RunFilter(scans, options);
  ASSERT_EQ(a.online.size(), scans.size());
  EXPECT_EQ(a.online, b.online);
  EXPECT_EQ(a.updates, b.updates);
  options.seed = 6;
  const RbpfRun c = RunFilter(scans, options);
  EXPECT_NE(a.online.back(), c.online.back());
}

}  // namespace
}  // namespace slamrig::slam
