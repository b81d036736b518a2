#include "slam/odometry/odometry_calibration.h"

#include <gtest/gtest.h>

#include <cmath>

#include "slam/odometry/gaussian.h"

namespace slamrig::slam {
namespace {

// The closed form of the forgotten sums after n equal steps of d metres, each with heading error
// e: both are geometric series with ratio exp(-d / memory).
double ExpectedDrift(const OdometryCalibrationOptions& o, int n, double d, double e) {
  const double k = std::exp(-d / o.memory_m);
  const double series = (1.0 - std::pow(k, n)) / (1.0 - k);
  return e * series / (d * series + o.prior_m);
}

OdometryCalibrationOptions Enabled() {
  OdometryCalibrationOptions o;
  o.enabled = true;
  return o;
}

TEST(OdometryCalibrationTest, FitMatchesTheClosedFormOfTheForgottenSums) {
  const OdometryCalibrationOptions o = Enabled();
  OdometryCalibration c(o);
  const double d = 0.25, drift = 0.057;
  for (int n = 1; n <= 4000; ++n) {
    const Pose2 raw(d, 0.0, 0.0);
    // The estimate turned drift x d more than the odometry said.
    ASSERT_TRUE(c.Observe(raw, Pose2(d, 0.0, drift * d)));
    if (n % 500 == 0) {
      EXPECT_NEAR(c.drift_rad_per_m(), ExpectedDrift(o, n, d, drift * d), 1e-12);
    }
  }
  // After 20 memories the evidence is d / (1 - k) metres, about the memory: the prior's share of
  // the fit is prior / (that + prior).
  const double evidence_m = d / (1.0 - std::exp(-d / o.memory_m));
  EXPECT_NEAR(evidence_m, o.memory_m, d);
  EXPECT_NEAR(c.drift_rad_per_m(), drift * evidence_m / (evidence_m + o.prior_m), 1e-9);
}

TEST(OdometryCalibrationTest, RecoversADriftFromNoisyCorrections) {
  // Random steps and turns, corrections = drift x distance + zero-mean matcher noise.
  OdometryCalibrationOptions o = Enabled();
  o.prior_m = 1.0;
  o.memory_m = 1e6;  // no forgetting: the fit is then a plain ratio of sums
  OdometryCalibration c(o);
  RandomEngine rng(7);
  const double drift = -0.03;
  double sum_e = 0.0, sum_d = 0.0;
  for (int i = 0; i < 4000; ++i) {
    const double d = 0.25 + 0.2 * std::abs(StandardNormal(rng));
    const double turn = 0.3 * StandardNormal(rng);
    const Pose2 raw(d * std::cos(0.5 * turn), d * std::sin(0.5 * turn), turn);
    const double e = drift * d + 0.01 * StandardNormal(rng);
    ASSERT_TRUE(c.Observe(raw, Pose2(raw.x(), raw.y(), raw.theta() + e)));
    sum_e += e;
    sum_d += d;
  }
  EXPECT_NEAR(c.drift_rad_per_m(), sum_e / (sum_d + o.prior_m), 1e-6);
  EXPECT_NEAR(c.drift_rad_per_m(), drift, 0.002);
}

TEST(OdometryCalibrationTest, OutliersStandingStillAndDisabledAreLeftOut) {
  OdometryCalibrationOptions o = Enabled();
  OdometryCalibration c(o);
  EXPECT_FALSE(c.Observe(Pose2(0.3, 0.0, 0.0), Pose2(0.3, 0.0, 0.2)));   // > max_error_rad
  EXPECT_FALSE(c.Observe(Pose2(0.0, 0.0, 0.1), Pose2(0.0, 0.0, 0.12)));  // turn on the spot
  EXPECT_EQ(c.drift_rad_per_m(), 0.0);
  const Pose2 raw(0.4, 0.1, 0.05);
  EXPECT_EQ(c.Correct(raw).x(), raw.x());
  EXPECT_EQ(c.Correct(raw).theta(), raw.theta());

  o.enabled = false;
  OdometryCalibration off(o);
  EXPECT_FALSE(off.Observe(Pose2(0.3, 0.0, 0.0), Pose2(0.3, 0.0, 0.01)));
  EXPECT_EQ(off.drift_rad_per_m(), 0.0);
}

TEST(OdometryCalibrationTest, ClampsTheDrift) {
  OdometryCalibrationOptions o = Enabled();
  o.max_drift_rad_per_m = 0.02;
  OdometryCalibration c(o);
  for (int i = 0; i < 1000; ++i) c.Observe(Pose2(0.25, 0.0, 0.0), Pose2(0.25, 0.0, 0.1));
  EXPECT_EQ(c.drift_rad_per_m(), 0.02);
}

TEST(OdometryCalibrationTest, CorrectionIsAConstantTurnRateAlongTheStep) {
  // A fitted drift a turns a straight step of length d into the chord of an arc of angle a d:
  // heading + a d, the translation turned by half of it.
  OdometryCalibrationOptions o = Enabled();
  o.min_significance = 0.0;  // one observation has no scatter to judge by
  o.prior_m = 1e-9;
  o.memory_m = 1e9;
  OdometryCalibration c(o);
  ASSERT_TRUE(c.Observe(Pose2(1.0, 0.0, 0.0), Pose2(1.0, 0.0, 0.08)));
  const double a = c.drift_rad_per_m();
  ASSERT_NEAR(a, 0.08, 1e-7);
  const Pose2 raw(0.5, 0.0, 0.1);
  const Pose2 fixed = c.Correct(raw);
  EXPECT_NEAR(fixed.theta(), 0.1 + a * 0.5, 1e-9);
  EXPECT_NEAR(fixed.x(), 0.5 * std::cos(0.5 * a * 0.5), 1e-9);
  EXPECT_NEAR(fixed.y(), 0.5 * std::sin(0.5 * a * 0.5), 1e-9);
  // Four quarter steps compose to the same arc as one whole step, to first order in the turn.
  Pose2 quarters;
  for (int i = 0; i < 4; ++i) quarters = quarters * c.Correct(Pose2(0.25, 0.0, 0.0));
  const Pose2 whole = c.Correct(Pose2(1.0, 0.0, 0.0));
  EXPECT_NEAR(quarters.theta(), whole.theta(), 1e-12);
  EXPECT_NEAR(quarters.x(), whole.x(), 1e-3);
  EXPECT_NEAR(quarters.y(), whole.y(), 1e-3);
}

// The standard error is the spread the fit really has: over many independent runs of the same
// noisy drive, the fits scatter by about the standard error each run reports.
TEST(OdometryCalibrationTest, StandardErrorMatchesTheSpreadOverRuns) {
  OdometryCalibrationOptions o = Enabled();
  RandomEngine rng(11);
  const double drift = 0.02, noise = 0.015;
  double sum = 0.0, sum_sq = 0.0, sum_se = 0.0;
  const int runs = 400;
  for (int r = 0; r < runs; ++r) {
    OdometryCalibration c(o);
    for (int i = 0; i < 300; ++i) {
      const double d = 0.25 + 0.1 * Uniform01(rng);
      c.Observe(Pose2(d, 0.0, 0.0), Pose2(d, 0.0, drift * d + noise * StandardNormal(rng)));
    }
    sum += c.drift_rad_per_m();
    sum_sq += c.drift_rad_per_m() * c.drift_rad_per_m();
    sum_se += c.standard_error_rad_per_m();
  }
  const double mean = sum / runs;
  const double spread = std::sqrt(sum_sq / runs - mean * mean);
  EXPECT_NEAR(sum_se / runs, spread, 0.15 * spread);
}

// The corrections are serially correlated: the estimate's heading error at an update enters that
// update's correction and, with the opposite sign, the next one's (intel-corrected's residuals have
// a lag-1 autocorrelation of -0.10). The sum then telescopes, so the fit scatters less than
// independent residuals suggest: the standard error from them errs on the safe side, and a robot
// without drift is not corrected.
TEST(OdometryCalibrationTest, StandardErrorIsConservativeForAnEstimatesHeadingNoise) {
  OdometryCalibrationOptions o = Enabled();
  RandomEngine rng(19);
  const double estimate_noise = 0.01, matcher_noise = 0.005;
  double sum = 0.0, sum_sq = 0.0, sum_se = 0.0;
  int applied = 0;
  const int runs = 400;
  for (int r = 0; r < runs; ++r) {
    OdometryCalibration c(o);
    double previous = estimate_noise * StandardNormal(rng);
    for (int i = 0; i < 300; ++i) {
      const double d = 0.25 + 0.1 * Uniform01(rng);
      const double current = estimate_noise * StandardNormal(rng);
      const double error = current - previous + matcher_noise * StandardNormal(rng);
      previous = current;
      c.Observe(Pose2(d, 0.0, 0.0), Pose2(d, 0.0, error));
    }
    sum += c.drift_rad_per_m();
    sum_sq += c.drift_rad_per_m() * c.drift_rad_per_m();
    sum_se += c.standard_error_rad_per_m();
    if (c.applied_drift_rad_per_m() != 0.0) ++applied;
  }
  const double mean = sum / runs;
  const double spread = std::sqrt(sum_sq / runs - mean * mean);
  EXPECT_GT(sum_se / runs, spread);
  EXPECT_EQ(applied, 0);
}

// A drift well clear of its standard error is applied; the matcher's noise about zero is not.
TEST(OdometryCalibrationTest, OnlyASignificantDriftIsApplied) {
  const OdometryCalibrationOptions o = Enabled();
  RandomEngine rng(3);
  OdometryCalibration none(o), some(o);
  for (int i = 0; i < 400; ++i) {
    const double d = 0.25;
    const double n = 0.015 * StandardNormal(rng);
    none.Observe(Pose2(d, 0.0, 0.0), Pose2(d, 0.0, n));
    some.Observe(Pose2(d, 0.0, 0.0), Pose2(d, 0.0, 0.05 * d + n));
  }
  EXPECT_NE(none.drift_rad_per_m(), 0.0);
  EXPECT_LT(std::abs(none.drift_rad_per_m()), 3.0 * none.standard_error_rad_per_m());
  EXPECT_EQ(none.applied_drift_rad_per_m(), 0.0);
  EXPECT_EQ(none.Correct(Pose2(0.25, 0.0, 0.0)).theta(), 0.0);
  EXPECT_GT(some.drift_rad_per_m(), 10.0 * some.standard_error_rad_per_m());
  EXPECT_EQ(some.applied_drift_rad_per_m(), some.drift_rad_per_m());
  EXPECT_NEAR(some.Correct(Pose2(0.25, 0.0, 0.0)).theta(), 0.25 * some.drift_rad_per_m(), 1e-12);
}

}  // namespace
}  // namespace slamrig::slam
