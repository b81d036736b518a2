#include "slam/pipeline/health.h"

#include <gtest/gtest.h>

#include <algorithm>
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

}  // namespace
}  // namespace slamrig::slam
