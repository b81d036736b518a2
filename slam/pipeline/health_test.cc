#include "slam/pipeline/health.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <random>

namespace slamrig::slam {
namespace {

Trajectory Stamped(const std::vector<double>& times_s) {
  Trajectory t;
  for (double s : times_s) t.Append(Time::FromSeconds(s), Pose2());
  return t;
}

TEST(HealthTest, LostIntervalsRunFromTheFirstLostScanToTheNextOneNotLost) {
  const Trajectory online = Stamped({0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0});
  const std::vector<LostInterval> intervals =
      LostIntervals(online, {false, true, true, false, true, false, true});
  ASSERT_EQ(intervals.size(), 3u);
  EXPECT_EQ(intervals[0].from, Time::FromSeconds(0.5));
  EXPECT_EQ(intervals[0].to, Time::FromSeconds(1.5));
  EXPECT_EQ(intervals[0].scans, 2);
  EXPECT_EQ(intervals[1].from, Time::FromSeconds(2.0));
  EXPECT_EQ(intervals[1].to, Time::FromSeconds(2.5));
  // Lost at the last scan: it ends there.
  EXPECT_EQ(intervals[2].from, Time::FromSeconds(3.0));
  EXPECT_EQ(intervals[2].to, Time::FromSeconds(3.0));
  EXPECT_DOUBLE_EQ(LostSeconds(intervals), 1.5);
  EXPECT_TRUE(LostIntervals(online, std::vector<bool>(7, false)).empty());
}

// Random flag sequences: the intervals cover exactly the lost scans, and HealthRecord counts
// them as the intervals do.
TEST(HealthTest, IntervalsAndRecordAgreeWithTheFlagsOnRandomRuns) {
  std::mt19937 random(7);
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 1 + static_cast<int>(random() % 40);
    std::vector<double> times;
    std::vector<bool> lost;
    HealthRecord record;
    double t = 0.0;
    for (int i = 0; i < n; ++i) {
      t += 0.1 + 0.01 * static_cast<double>(random() % 10);
      times.push_back(t);
      lost.push_back(random() % 3 == 0);
      record.Add(lost.back());
    }
    const std::vector<LostInterval> intervals = LostIntervals(Stamped(times), lost);
    int lost_scans = 0;
    for (const LostInterval& interval : intervals) {
      lost_scans += interval.scans;
      EXPECT_LE(interval.from, interval.to);
    }
    EXPECT_EQ(lost_scans, static_cast<int>(std::count(lost.begin(), lost.end(), true)));
    EXPECT_EQ(record.lost_scans(), lost_scans);
    EXPECT_EQ(record.losses(), static_cast<int>(intervals.size()));
    EXPECT_EQ(record.lost_at_end(), static_cast<bool>(lost.back()));
    EXPECT_EQ(record.Diverged(),
              lost.back() || lost_scans > kDivergedLostShare * static_cast<double>(n));
  }
}

TEST(HealthTest, RecoveredLossIsNotDivergence) {
  HealthRecord record;
  for (int i = 0; i < 100; ++i) record.Add(i >= 40 && i < 45);  // 5 % lost, recovered
  EXPECT_EQ(record.losses(), 1);
  EXPECT_FALSE(record.Diverged());
  record.Add(true);  // lost at the end
  EXPECT_TRUE(record.Diverged());
  HealthRecord long_loss;
  for (int i = 0; i < 100; ++i) long_loss.Add(i >= 10 && i < 30);  // 20 % lost
  EXPECT_TRUE(long_loss.Diverged());
}

TEST(HealthTest, QualityRatioFollowsTheRunsOwnLevel) {
  // Two runs at levels a factor 10 apart give the same ratios: no absolute threshold.
  QualityRatio low(0.5, 0.01, 5), high(0.5, 0.01, 5);
  EXPECT_DOUBLE_EQ(low.ratio(), 1.0);
  for (int i = 0; i < 50; ++i) {
    low.Add(0.07);
    high.Add(0.7);
  }
  EXPECT_NEAR(low.ratio(), 1.0, 1e-12);
  // A fall to a third: the short-term average follows within a few samples, the long-term one
  // barely moves.
  for (int i = 0; i < 6; ++i) {
    low.Add(0.07 / 3);
    high.Add(0.7 / 3);
  }
  EXPECT_NEAR(low.ratio(), high.ratio(), 1e-12);
  EXPECT_LT(low.ratio(), 0.4);
  EXPECT_GT(low.ratio(), 1.0 / 3);
  // Holding the long-term level: a long fall stays a fall.
  QualityRatio held(0.5, 0.05, 5, 0.5), unheld(0.5, 0.05, 5);
  for (int i = 0; i < 20; ++i) {
    held.Add(1.0);
    unheld.Add(1.0);
  }
  for (int i = 0; i < 200; ++i) {
    held.Add(0.2);
    unheld.Add(0.2);
  }
  EXPECT_NEAR(held.ratio(), 0.2, 1e-9);
  EXPECT_NEAR(unheld.ratio(), 1.0, 1e-3);
  // Not warm yet: 1.
  QualityRatio cold(0.5, 0.01, 5);
  cold.Add(1.0);
  EXPECT_DOUBLE_EQ(cold.Add(0.0), 1.0);
}

// The NIS of a consistent filter is chi-square: 3-dof draws stay inside the window's quantile
// nearly always; three times them do not.
TEST(HealthTest, NisWindowFlagsAnInconsistentFilterOnly) {
  std::mt19937 random(3);
  std::chi_squared_distribution<double> chi2(3.0);
  NisWindow consistent, inflated;
  int flagged = 0, inflated_flagged = 0;
  EXPECT_DOUBLE_EQ(consistent.ratio(), 0.0);
  for (int i = 0; i < 2000; ++i) {
    const double nis = chi2(random);
    consistent.Add(nis, 3);
    inflated.Add(3.0 * nis, 3);
    flagged += consistent.inconsistent();
    inflated_flagged += inflated.inconsistent();
  }
  EXPECT_LT(flagged, 20) << flagged;  // overlapping windows: a few times 0.1 % at most
  EXPECT_GT(inflated_flagged, 1800);  // the sum of ten is 90 on average, the bound 59.7
  // A full window only: nine wild updates are not yet a verdict.
  NisWindow short_window;
  for (int i = 0; i < NisWindow::kUpdates - 1; ++i) short_window.Add(1000.0, 3);
  EXPECT_FALSE(short_window.inconsistent());
  short_window.Add(1000.0, 3);
  EXPECT_TRUE(short_window.inconsistent());
}

IcpOdometryStep Step(IcpOdometryOutcome outcome, double score) {
  IcpOdometryStep step;
  step.outcome = outcome;
  step.score = score;
  step.covariance = Eigen::Matrix3d::Identity() * 1e-4;
  step.window = Eigen::Vector2d(0.3, 0.1);
  return step;
}

TEST(HealthTest, FrontEndIsLostOnAFailedMatchAndOnAFallingScore) {
  FrontEndHealth health;
  std::vector<TraceValue> trace;
  EXPECT_FALSE(health.Judge(Step(IcpOdometryOutcome::kFirstScan, 0.0), &trace));
  for (int i = 0; i < 30; ++i) {
    trace.clear();
    EXPECT_FALSE(health.Judge(Step(IcpOdometryOutcome::kMatched, 0.9), &trace)) << i;
  }
  // Its health values, every scan the same names.
  std::vector<std::string> names;
  for (const TraceValue& v : trace) names.push_back(v.name);
  EXPECT_EQ(names, (std::vector<std::string>{
                       "match_score", "match_score_ratio", "match_conditioning", "searched",
                       "search_widened", "correction_xy_of_window", "correction_yaw_of_window"}));
  EXPECT_DOUBLE_EQ(trace[2].value, 1.0);  // an isotropic covariance: well conditioned
  EXPECT_TRUE(health.Judge(Step(IcpOdometryOutcome::kMatchFailed, 0.0), &trace));
  EXPECT_TRUE(health.Judge(Step(IcpOdometryOutcome::kNoPoints, 0.0), &trace));
  EXPECT_FALSE(health.Judge(Step(IcpOdometryOutcome::kMatched, 0.9), &trace));
  // Matches at a third of the usual score: lost within a few scans, not at the first.
  EXPECT_FALSE(health.Judge(Step(IcpOdometryOutcome::kMatched, 0.3), &trace));
  bool lost = false;
  for (int i = 0; i < 5; ++i) lost = health.Judge(Step(IcpOdometryOutcome::kMatched, 0.3), &trace);
  EXPECT_TRUE(lost);
}

// Drives `steps` wheel increments of `step_m` on a random curvy path; the estimate moves by the
// wheels' increment times `scale`, plus jitter and a heading error (the estimate's own). The
// scans WheelAgreement flags.
std::vector<bool> Judged(WheelAgreement* agreement, std::mt19937* rng, int steps, double step_m,
                         double scale, double jitter_m) {
  std::normal_distribution<double> noise(0.0, 1.0);
  std::uniform_real_distribution<double> turn(-0.2, 0.2);
  std::vector<bool> flags;
  for (int i = 0; i < steps; ++i) {
    const Pose2 wheels(step_m, 0.0, turn(*rng));
    const double along = noise(*rng), across = noise(*rng), yaw = noise(*rng);
    const Pose2 moved(scale * step_m + jitter_m * along, jitter_m * across,
                      wheels.theta() + 0.01 * yaw);
    flags.push_back(agreement->Add(moved, wheels));
  }
  return flags;
}

TEST(HealthTest, WheelAgreementHoldsForAnEstimateThatFollowsTheRobot) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    WheelAgreement agreement;
    // Wheels 20 % off in scale, a centimetre of jitter per 0.1-0.5 m step: never flagged.
    const double step_m = 0.1 + 0.4 * (trial % 5) / 4.0;
    const double scale = 0.8 + 0.4 * (trial % 7) / 6.0;
    const std::vector<bool> flags = Judged(&agreement, &rng, 200, step_m, scale, 0.01);
    EXPECT_EQ(std::count(flags.begin(), flags.end(), true), 0) << trial;
    EXPECT_NEAR(agreement.ratio(), scale, 0.1) << trial;
    EXPECT_EQ(agreement.contradicted_m(), 0.0) << trial;
  }
}

TEST(HealthTest, WheelAgreementFlagsAnEstimateThatStopsOrRaces) {
  std::mt19937 rng(11);
  for (const double scale : {0.0, 0.3, 1.7, 3.0}) {
    WheelAgreement agreement;
    std::vector<bool> flags = Judged(&agreement, &rng, 20, 0.3, 1.0, 0.005);
    EXPECT_EQ(std::count(flags.begin(), flags.end(), true), 0);
    EXPECT_EQ(agreement.contradicted_m(), 0.0);
    // 20 steps of 0.3 m at `scale`: flagged once the window (2 m) is mostly that stretch.
    flags = Judged(&agreement, &rng, 20, 0.3, scale, 0.005);
    EXPECT_TRUE(flags.back()) << scale;
    EXPECT_NEAR(agreement.ratio(), scale, 0.15) << scale;
    // The estimate follows again: the flag clears once the window has left the stretch.
    flags = Judged(&agreement, &rng, 10, 0.3, 1.0, 0.005);
    EXPECT_FALSE(flags.back()) << scale;
    // The whole stretch's displacement against the wheels, the scans before the flag included.
    EXPECT_NEAR(agreement.contradicted_m(), 6.0 * std::abs(1.0 - scale), 0.05) << scale;
  }
  {
    // One jump of the estimate (a correction) is flagged while it is in the window, but it does
    // not persist: no contradiction.
    WheelAgreement agreement;
    Judged(&agreement, &rng, 20, 0.3, 1.0, 0.005);
    EXPECT_TRUE(agreement.Add(Pose2(-1.2, 0.0, 0.0), Pose2(0.3, 0.0, 0.0)));
    const std::vector<bool> flags = Judged(&agreement, &rng, 20, 0.3, 1.0, 0.005);
    EXPECT_GT(std::count(flags.begin(), flags.end(), true), 3);
    EXPECT_FALSE(flags.back());
    EXPECT_EQ(agreement.contradicted_m(), 0.0);
  }
  // Less than the window's wheel travel is never judged; a reset forgets the window.
  WheelAgreement agreement;
  std::vector<bool> flags = Judged(&agreement, &rng, 6, 0.3, 0.0, 0.0);  // 1.8 m
  EXPECT_EQ(std::count(flags.begin(), flags.end(), true), 0);
  EXPECT_DOUBLE_EQ(agreement.ratio(), 1.0);
  flags = Judged(&agreement, &rng, 2, 0.3, 0.0, 0.0);
  EXPECT_TRUE(flags.back());
  agreement.Reset();
  EXPECT_DOUBLE_EQ(agreement.ratio(), 1.0);
  EXPECT_FALSE(agreement.Add(Pose2(), Pose2(0.3, 0.0, 0.0)));
  EXPECT_DOUBLE_EQ(agreement.ratio(), 1.0);
}

TEST(HealthTest, WheelAgreementComparesTurnsBeyondTheWheelsDriftAndSkid) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  // An estimate that follows the robot while the wheels drift up to 1.4 degrees per metre on the
  // straight (42 over the long window) and skid by up to 45 % of every turn (fast turns, 1 rad per
  // metre): never flagged.
  for (int trial = 0; trial < 200; ++trial) {
    WheelAgreement agreement;
    const double drift_rad_per_m = (2.0 * unit(rng) - 1.0) * 1.4 * M_PI / 180.0;
    const double skid = 1.0 + (2.0 * unit(rng) - 1.0) * 0.45;
    const double curvature = (trial % 4) * 0.33;  // rad per metre
    for (int i = 0; i < 300; ++i) {
      const double step_m = 0.1 + 0.2 * unit(rng);
      const double turn = (i / 20 % 2 == 0 ? 1.0 : -1.0) * curvature * step_m;
      const Pose2 wheels(step_m, 0.0, turn * skid + drift_rad_per_m * step_m);
      ASSERT_FALSE(agreement.Add(Pose2(step_m, 0.0, turn), wheels)) << trial << " " << i;
    }
    EXPECT_EQ(agreement.heading_contradicted_rad(), 0.0);
  }
  // An estimate that turns 13 degrees per metre while the robot drives straight for 12 m (steps
  // of 0.25 m, exact in binary): flagged once the short window is full, holding 130 degrees of
  // it, and the long window all 156, until the long window has left the stretch.
  WheelAgreement agreement;
  const double rate = 13.0 * M_PI / 180.0;
  int first = -1;
  for (int i = 0; i < 48; ++i) {  // 12 m
    if (agreement.Add(Pose2(0.25, 0.0, rate * 0.25), Pose2(0.25, 0.0, 0.0)) && first < 0) {
      first = i;
    }
  }
  EXPECT_EQ(first, 39);  // 10 m
  EXPECT_NEAR(agreement.turn_difference_rad(), rate * 10.0, 1e-9);
  bool flagged = true;
  int cleared = -1;
  for (int i = 0; i < 150 && cleared < 0; ++i) {
    flagged = agreement.Add(Pose2(0.25, 0.0, 0.0), Pose2(0.25, 0.0, 0.0));
    if (!flagged) cleared = i;
  }
  // 45 degrees is 3.46 m of the stretch: the long window (the last 120 steps) holds 3.5 m of it
  // after 106 straight steps (45.5 degrees, flagged), 3.25 m after 107 (cleared).
  EXPECT_EQ(cleared, 106);
  EXPECT_NEAR(agreement.heading_contradicted_rad(), rate * 12.0, 1e-9);
  // The distance was right throughout: no distance contradiction.
  EXPECT_EQ(agreement.contradicted_m(), 0.0);
  // A slow runaway, 2.8 degrees per metre on the straight: 28 degrees over the short window, 45
  // after 16.07 m, flagged by the long window from the first scan past that (16.25 m).
  WheelAgreement slow;
  const double slow_rate = 2.8 * M_PI / 180.0;
  first = -1;
  for (int i = 0; i < 120 && first < 0; ++i) {
    if (slow.Add(Pose2(0.25, 0.0, slow_rate * 0.25), Pose2(0.25, 0.0, 0.0))) first = i;
  }
  EXPECT_EQ(first, 64);
  EXPECT_NEAR(slow.turn_difference_rad(), slow_rate * 10.0, 1e-9);
  EXPECT_NEAR(slow.heading_contradicted_rad(), slow_rate * 16.25, 1e-9);
}

TEST(HealthTest, WheelAgreementLearnsTheWheelsSteadyDriftBeforeJudgingTheLongWindow) {
  // Wheels that drift 1.2 degrees per metre on the straight (36 over the long window, as the
  // generated campus's Pioneer profile) and an estimate that follows the robot, with a 25 degree
  // heading glitch at 150 m taken back 2 m later: 61 degrees over the long window, of which 36
  // are the wheels' own bias, learnt by then. Never flagged.
  const double drift = 1.2 * M_PI / 180.0 * 0.25;  // per 0.25 m step
  const double glitch = 25.0 * M_PI / 180.0;
  WheelAgreement agreement;
  for (int i = 0; i < 800; ++i) {  // 200 m
    const double estimate_turn = i == 600 ? glitch : (i == 608 ? -glitch : 0.0);
    ASSERT_FALSE(agreement.Add(Pose2(0.25, 0.0, estimate_turn), Pose2(0.25, 0.0, drift))) << i;
  }
  EXPECT_EQ(agreement.heading_contradicted_rad(), 0.0);
  // The reported difference is the judged one, net of the learnt drift (the raw one is -12
  // degrees: -0.209 rad), to the drift histogram's bin (0.0005 rad/m, over 10 m).
  EXPECT_NEAR(agreement.turn_difference_rad(), 0.0, 0.0025);
  // The same wheels with a slow runaway of the estimate (3 degrees per metre) from 150 m on: the
  // learnt bias does not hide it. Flagged once the long window holds 45 degrees beyond the bias
  // plus half the wheels' own turning there (their 36 degrees of drift count as turning): 63
  // degrees, 21 m of the runaway.
  WheelAgreement runaway;
  int first = -1;
  for (int i = 0; i < 800 && first < 0; ++i) {
    const double estimate_turn = i >= 600 ? 3.0 * M_PI / 180.0 * 0.25 : 0.0;
    if (runaway.Add(Pose2(0.25, 0.0, estimate_turn), Pose2(0.25, 0.0, drift))) first = i;
  }
  EXPECT_EQ(first, 600 + 83);
}

TEST(HealthTest, WheelAgreementAllowsTheWheelsMeasuredHeadingNoise) {
  // Wheels whose heading scatters by 60 % of every turn (Gaussian, per turn of the robot: twice
  // a noisy log's odometry), on a route that turns half a radian every 2 m, and an estimate that
  // follows the robot. Judged by the fixed tolerance the wheels themselves contradict it on some
  // runs; told their noise (5 sigma of the window's sum), never.
  std::mt19937 rng(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  int fixed_flagged = 0;
  for (int trial = 0; trial < 200; ++trial) {
    WheelAgreement fixed, told;
    for (int i = 0; i < 400; ++i) {  // 100 m in 0.25 m steps
      const double turn = i % 8 == 0 ? (i % 16 == 0 ? 0.5 : -0.5) : 0.0;
      const double sigma = 0.6 * std::abs(turn);
      const Pose2 wheels(0.25, 0.0, turn + sigma * normal(rng));
      fixed.Add(Pose2(0.25, 0.0, turn), wheels, 1.0);
      ASSERT_FALSE(told.Add(Pose2(0.25, 0.0, turn), wheels, 1.0, sigma)) << trial << " " << i;
    }
    fixed_flagged += fixed.heading_contradicted_rad() > 0.0;
    EXPECT_EQ(told.heading_contradicted_rad(), 0.0);
  }
  EXPECT_GE(fixed_flagged, 10);  // 20 of 200: the fixed tolerance is not what holds them
  // Told the same noise, a turn the robot did not make is still seen: the estimate turns half a
  // turn more than the wheels where the robot turned half a radian (sigma 0.3 rad), pi against 5
  // sigma, 1.5 rad.
  WheelAgreement wrong;
  for (int i = 0; i < 40; ++i) {  // 10 m, straight and exact
    ASSERT_FALSE(wrong.Add(Pose2(0.25, 0.0, 0.0), Pose2(0.25, 0.0, 0.0), 1.0, 0.002));
  }
  EXPECT_TRUE(wrong.Add(Pose2(0.25, 0.0, 0.5 + M_PI), Pose2(0.25, 0.0, 0.5), 1.0, 0.3));
  EXPECT_NEAR(wrong.heading_contradicted_rad(), M_PI, 1e-9);
}

// Points every 5 cm along the segment from a to b.
void Wall(const Eigen::Vector2d& a, const Eigen::Vector2d& b, std::vector<Eigen::Vector2d>* out) {
  const int n = static_cast<int>((b - a).norm() / 0.05);
  for (int i = 0; i <= n; ++i) out->push_back(a + (b - a) * (static_cast<double>(i) / n));
}

TEST(HealthTest, ObservabilityIsLowOnlyAlongACorridorsAxis) {
  std::vector<Eigen::Vector2d> corridor;
  Wall({-8.0, 1.0}, {8.0, 1.0}, &corridor);
  Wall({8.0, -1.0}, {-8.0, -1.0}, &corridor);
  EXPECT_LT(Observability(ScanGeometry(corridor), {1.0, 0.0}), 0.01);
  EXPECT_NEAR(Observability(ScanGeometry(corridor), {0.0, -2.0}), 1.0, 1e-9);
  // At 45 degrees to the axis: half the across-axis information.
  EXPECT_NEAR(Observability(ScanGeometry(corridor), {1.0, 1.0}), 0.5, 0.01);
  std::vector<Eigen::Vector2d> room;
  Wall({-2.0, -2.0}, {2.0, -2.0}, &room);
  Wall({2.0, -2.0}, {2.0, 2.0}, &room);
  Wall({2.0, 2.0}, {-2.0, 2.0}, &room);
  Wall({-2.0, 2.0}, {-2.0, -2.0}, &room);
  EXPECT_NEAR(Observability(ScanGeometry(room), {1.0, 0.0}), 1.0, 0.05);
  EXPECT_EQ(Observability(ScanGeometry({}), {1.0, 0.0}), 0.0);
  EXPECT_EQ(Observability(ScanGeometry(room), {0.0, 0.0}), 0.0);
  // Scans that observe the motion are not judged: a stopped estimate there is the scan's word.
  WheelAgreement agreement;
  for (int i = 0; i < 20; ++i) {
    EXPECT_FALSE(agreement.Add(Pose2(), Pose2(0.3, 0.0, 0.0),
                               Observability(ScanGeometry(room), {1.0, 0.0})));
  }
  EXPECT_DOUBLE_EQ(agreement.ratio(), 1.0);
  bool flagged = false;
  for (int i = 0; i < 20; ++i) {
    flagged = agreement.Add(Pose2(), Pose2(0.3, 0.0, 0.0),
                            Observability(ScanGeometry(corridor), {1.0, 0.0}));
  }
  EXPECT_TRUE(flagged);
}

TEST(HealthTest, BlindStretchBoundMatchesTheClosedFormOnAStraightLine) {
  // N steps of d straight ahead. Translation noise alone: variance N sx^2 along and across.
  const int n = 40;
  const double d = 0.25, sx = 0.01, syaw = 0.004;
  const double q99 = 9.2103403719761836;  // chi-square, 2 dof, 0.99
  BlindStretchBound bound;
  bound.Start();
  for (int i = 0; i < n; ++i) bound.Add(Pose2(d, 0.0, 0.0), {sx, 0.0});
  EXPECT_NEAR(bound.bound_m(), std::sqrt(q99 * n * sx * sx), 1e-9);
  // Yaw noise alone: step i's yaw error moves the n - i steps after it across the line.
  bound.Start();
  for (int i = 0; i < n; ++i) bound.Add(Pose2(d, 0.0, 0.0), {0.0, syaw});
  double across = 0.0;
  for (int i = 1; i <= n; ++i) across += std::pow((n - i) * d * syaw, 2);
  EXPECT_NEAR(bound.bound_m(), std::sqrt(q99 * across), 1e-9);
  bound.Start();
  EXPECT_EQ(bound.bound_m(), 0.0);
}

TEST(HealthTest, BlindStretchBoundAgreesWithSampledPathsOnACurve) {
  // A curve of 60 steps; the bound's covariance against 4000 sampled noisy paths.
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 1.0);
  const Pose2 step(0.2, 0.0, 0.03);
  const Eigen::Vector2d sigmas(0.01, 0.005);
  BlindStretchBound bound;
  bound.Start();
  Pose2 truth;
  for (int i = 0; i < 60; ++i) {
    bound.Add(step, sigmas);
    truth = truth * step;
  }
  Eigen::Matrix2d sampled = Eigen::Matrix2d::Zero();
  const int samples = 4000;
  for (int k = 0; k < samples; ++k) {
    Pose2 pose;
    for (int i = 0; i < 60; ++i) {
      const double nx = noise(rng), ny = noise(rng), nt = noise(rng);
      pose = pose * Pose2(step.x() + sigmas.x() * nx, step.y() + sigmas.x() * ny,
                          step.theta() + sigmas.y() * nt);
    }
    const Eigen::Vector2d e = pose.translation() - truth.translation();
    sampled += e * e.transpose() / samples;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(sampled);
  const double sampled_bound = std::sqrt(9.2103403719761836 * eig.eigenvalues()[1]);
  EXPECT_NEAR(bound.bound_m(), sampled_bound, 0.06 * sampled_bound);
}

// A door mapped closed and seen open, crossed from one place for many updates: the same metre of
// wall.
TEST(HealthTest, WallCrossingsCountADoorOnce) {
  WallCrossings crossings;
  std::vector<Eigen::Vector2d> door;
  for (double x = 0.01; x < 1.0; x += 0.02) door.emplace_back(5.0 + x, 2.05);
  for (int update = 0; update < 100; ++update) {
    crossings.Add(door);
    EXPECT_NEAR(crossings.extent_m(), 1.0, 1e-9) << update;  // five 0.2 m squares
  }
}

// A revisit beside the first visit crosses a new metre of the first copy's walls at every
// update: the extent grows by a metre an update up to the window's length; the window forgets
// it kUpdates updates later, the worst extent does not.
TEST(HealthTest, WallCrossingsGrowAlongAWholeCopyCrossed) {
  WallCrossings crossings;
  for (int update = 0; update < 2 * WallCrossings::kUpdates; ++update) {
    std::vector<Eigen::Vector2d> wall;
    for (double x = 0.01; x < 1.0; x += 0.02) wall.emplace_back(update + x, 3.1);
    crossings.Add(wall);
    EXPECT_NEAR(crossings.extent_m(), std::min(update + 1, WallCrossings::kUpdates), 1e-9);
  }
  for (int update = 0; update < WallCrossings::kUpdates; ++update) crossings.Add({});
  EXPECT_EQ(crossings.extent_m(), 0.0);
  EXPECT_NEAR(crossings.worst_m(), WallCrossings::kUpdates, 1e-9);
}

// The extent is the distinct squares crossed over the last kUpdates updates, counted afresh.
TEST(HealthTest, WallCrossingsAreTheWindowsDistinctSquaresOnRandomRuns) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> coordinate(-3.0, 3.0);
  std::uniform_int_distribution<int> count(0, 30);
  for (int run = 0; run < 8; ++run) {
    WallCrossings crossings;
    std::vector<std::vector<Eigen::Vector2d>> updates;
    double worst = 0.0;
    for (int update = 0; update < 120; ++update) {
      std::vector<Eigen::Vector2d> points(static_cast<std::size_t>(count(rng)));
      for (auto& p : points) {
        p.x() = coordinate(rng);
        p.y() = coordinate(rng);
      }
      crossings.Add(points);
      updates.push_back(points);
      std::vector<std::pair<long, long>> squares;
      const std::size_t from =
          updates.size() > WallCrossings::kUpdates ? updates.size() - WallCrossings::kUpdates : 0;
      for (std::size_t u = from; u < updates.size(); ++u) {
        for (const auto& p : updates[u]) {
          squares.emplace_back(std::lround(std::floor(p.x() / WallCrossings::kBinM)),
                               std::lround(std::floor(p.y() / WallCrossings::kBinM)));
        }
      }
      std::sort(squares.begin(), squares.end());
      const auto distinct = std::unique(squares.begin(), squares.end()) - squares.begin();
      const double expected = static_cast<double>(distinct) * WallCrossings::kBinM;
      worst = std::max(worst, expected);
      ASSERT_NEAR(crossings.extent_m(), expected, 1e-9) << run << " " << update;
      ASSERT_NEAR(crossings.worst_m(), worst, 1e-9);
    }
  }
}

}  // namespace
}  // namespace slamrig::slam
