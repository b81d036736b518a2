#include "slam/fusion/wheel_slip.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace slamrig::slam {
namespace {

constexpr double kTrack = 0.4;
constexpr double kTick = 0.0022;

// A skid-steered base driven at `rate_hz` encoder intervals: it turns at `yaw_rate` for
// `turn_s`, its wheels rolling `ratio` times the turn's differential, plus `slip_m_s` of extra
// right-wheel travel from `slip_from_s` on. The wheels' travel is counted in whole ticks (the
// cumulative count, so quantisation does not accumulate); the gyro is exact. Returns the slip
// the detector reported from `slip_from_s` on.
double Drive(WheelSlipDetector& detector, double rate_hz, double turn_s, double yaw_rate,
             double ratio, double slip_from_s, double slip_m_s) {
  const double dt = 1.0 / rate_hz;
  const int steps = static_cast<int>(std::lround(turn_s * rate_hz));
  double right = 0.0, left = 0.0;  // true cumulative travel
  long right_ticks = 0, left_ticks = 0;
  double reported = 0.0;
  for (int i = 0; i < steps; ++i) {
    const double t = i * dt;
    const double forward = 0.3 * dt;
    const double half_differential = 0.5 * ratio * kTrack * yaw_rate * dt;
    right += forward + half_differential + (t >= slip_from_s ? slip_m_s * dt : 0.0);
    left += forward - half_differential;
    const long r = std::lround(right / kTick), l = std::lround(left / kTick);
    const double slip = detector
                            .Add(static_cast<double>(r - right_ticks) * kTick,
                                 static_cast<double>(l - left_ticks) * kTick, yaw_rate * dt, dt)
                            .slip_m;
    if (t >= slip_from_s) reported += slip;
    right_ticks = r;
    left_ticks = l;
  }
  return reported;
}

// The skid ratio is learnt from the turns, at the same pace per radian whatever the encoder
// rate, and once it is, ticked turns report no slip: quantisation stays inside the dead zone.
TEST(WheelSlipDetectorTest, LearnsTheSkidRatioAndReportsNoSlipInOrdinaryTurns) {
  for (const double rate_hz : {10.0, 40.0, 100.0}) {
    WheelSlipDetector detector(kTrack, kTick);
    EXPECT_EQ(detector.skid_ratio(), 1.0);
    Drive(detector, rate_hz, 10.0, 0.5, 2.4, 1e9, 0.0);  // learning: 5 rad turned
    EXPECT_NEAR(detector.skid_ratio(), 2.4, 0.05) << rate_hz;
    const double before = detector.total_slip_m();
    const double reported = Drive(detector, rate_hz, 20.0, -0.4, 2.4, 0.0, 0.0);
    EXPECT_LT(reported, 1e-3) << rate_hz;
    EXPECT_NEAR(detector.total_slip_m() - before, reported, 1e-12);
    EXPECT_NEAR(detector.skid_ratio(), 2.4, 0.05) << rate_hz;
  }
}

// Slip at a steady rate (one wheel spinning on a straight) is reported as that rate times its
// duration, less the window's lag at the start, whatever the encoder rate; the ratio stays where
// the turns put it. (A steady slip in a steady turn is a different skid ratio to any sensor
// here: the ratio absorbs it.)
TEST(WheelSlipDetectorTest, ReportsASteadySlipAsItsDistanceAtAnyEncoderRate) {
  const double slip_m_s = 0.08, duration_s = 3.0;
  for (const double rate_hz : {10.0, 40.0, 100.0}) {
    WheelSlipDetector detector(kTrack, kTick);
    Drive(detector, rate_hz, 8.0, 0.5, 2.4, 1e9, 0.0);
    const double reported = Drive(detector, rate_hz, duration_s, 0.0, 2.4, 0.0, slip_m_s);
    // The window fills over kWindowS: the first window's slip comes late (its lag is the
    // window's length), and the dead zone holds back two ticks' worth per window length.
    const double window = WheelSlipDetector::kWindowS;
    const double expected =
        slip_m_s * (duration_s - window) - 2.0 * kTick * (duration_s - window) / window;
    EXPECT_NEAR(reported, expected, 0.1 * expected) << rate_hz;
    EXPECT_NEAR(detector.skid_ratio(), 2.4, 0.05) << rate_hz;
  }
}

// Without an interval length (the first ticks) nothing is reported.
TEST(WheelSlipDetectorTest, ReportsNothingWithoutAnInterval) {
  WheelSlipDetector detector(kTrack, kTick);
  EXPECT_EQ(detector.Add(0.1, -0.1, 0.0, 0.0).slip_m, 0.0);
  EXPECT_EQ(detector.Add(0.1, -0.1, 0.0, 0.0).coherent_m2, 0.0);
  EXPECT_EQ(detector.total_slip_m(), 0.0);
}

}  // namespace
}  // namespace slamrig::slam
