#include "slam/eval/recovery_time.h"

#include <gtest/gtest.h>

#include <cmath>

namespace slamrig::slam {
namespace {

// One pair per 0.1 s over 0-100 s; the estimate is `error(t)` metres east of the truth.
template <typename F>
std::vector<PosePair> Pairs(F error) {
  std::vector<PosePair> pairs;
  for (int k = 0; k <= 1000; ++k) {
    const double t = 0.1 * k;
    const Pose2 truth(0.05 * k, 1.0, 0.3);
    pairs.push_back({Time::FromSeconds(t), Pose2(truth.x() + error(t), truth.y(), 0.3), truth});
  }
  return pairs;
}

TEST(RecoveryTimeTest, TimeFromTheEventUntilTheErrorStaysWithinTheBound) {
  // Thrown 12 m off at 60 s, back within 0.3 m at 75 s (0.05 m from then on).
  const auto pairs = Pairs([](double t) { return t < 60.0 ? 0.02 : t < 75.0 ? 12.0 : 0.05; });
  EXPECT_NEAR(RecoveryTime(pairs, Time::FromSeconds(60.0), std::nullopt, 0.3), 15.0, 1e-9);
}

TEST(RecoveryTimeTest, ABriefReturnThatDoesNotLastIsNotARecovery) {
  // Crosses the truth at 65 s on its way elsewhere, then settles at 80 s.
  const auto pairs = Pairs([](double t) {
    if (t < 60.0) return 0.0;
    if (t >= 64.95 && t < 65.05) return 0.1;
    return t < 80.0 ? 3.0 : 0.2;
  });
  EXPECT_NEAR(RecoveryTime(pairs, Time::FromSeconds(60.0), std::nullopt, 0.3), 20.0, 1e-9);
}

TEST(RecoveryTimeTest, NeverBackIsNaNAndNeverOffIsZero) {
  const auto lost = Pairs([](double t) { return t < 60.0 ? 0.0 : 12.0; });
  EXPECT_TRUE(std::isnan(RecoveryTime(lost, Time::FromSeconds(60.0), std::nullopt, 0.3)));
  // Off again in the last pose only: not recovered at the end of the run.
  const auto relapse = Pairs([](double t) { return t > 99.95 ? 1.0 : 0.0; });
  EXPECT_TRUE(std::isnan(RecoveryTime(relapse, Time::FromSeconds(60.0), std::nullopt, 0.3)));
  const auto fine = Pairs([](double) { return 0.1; });
  EXPECT_EQ(RecoveryTime(fine, Time::FromSeconds(60.0), std::nullopt, 0.3), 0.0);
  // No pair after the event.
  EXPECT_TRUE(std::isnan(RecoveryTime(fine, Time::FromSeconds(200.0), std::nullopt, 0.3)));
}

TEST(RecoveryTimeTest, EachEventIsJudgedUntilTheNextAndTheWorstCounts) {
  // Kidnapped at 20 s (back at 25 s) and at 50 s (back at 70 s): the error between 50 s and the
  // second recovery does not count against the first event.
  const auto pairs = Pairs([](double t) {
    if (t >= 20.0 && t < 25.0) return 5.0;
    if (t >= 50.0 && t < 70.0) return 8.0;
    return 0.0;
  });
  EXPECT_NEAR(RecoveryTime(pairs, Time::FromSeconds(20.0), Time::FromSeconds(50.0), 0.3), 5.0,
              1e-9);
  // The events in any order.
  EXPECT_NEAR(WorstRecoveryTime(pairs, {Time::FromSeconds(50.0), Time::FromSeconds(20.0)}, 0.3),
              20.0, 1e-9);
  EXPECT_TRUE(std::isnan(WorstRecoveryTime(pairs, {}, 0.3)));
}

}  // namespace
}  // namespace slamrig::slam
