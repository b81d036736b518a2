#include "slam/odometry/diff_drive_model.h"

#include <gtest/gtest.h>

#include <cmath>

namespace slamrig::slam {
namespace {

// Constant v and omega: the exact-arc model lands on the circle whatever the step count, Euler's
// error shrinks in proportion to the step (first order).
TEST(DiffDriveModelTest, ExactArcIsStepIndependentEulerIsFirstOrder) {
  const double v = 0.8, omega = 0.5, duration = 4.0;
  const Pose2 truth(v / omega * std::sin(omega * duration),
                    v / omega * (1.0 - std::cos(omega * duration)), omega * duration);
  double previous_euler_error = 0.0;
  for (const int steps : {10, 20, 40, 80}) {
    const double tau = duration / steps;
    Pose2 exact, euler;
    for (int i = 0; i < steps; ++i) {
      exact = IntegrateDiffDrive(exact, v * tau, omega * tau, DiffDriveIntegration::kExactArc);
      euler = IntegrateDiffDrive(euler, v * tau, omega * tau, DiffDriveIntegration::kEuler);
    }
    EXPECT_NEAR(exact.x(), truth.x(), 1e-12);
    EXPECT_NEAR(exact.y(), truth.y(), 1e-12);
    EXPECT_NEAR(exact.theta(), truth.theta(), 1e-12);
    const double euler_error = (euler.translation() - truth.translation()).norm();
    EXPECT_GT(euler_error, 1e-3);
    if (previous_euler_error > 0.0) {
      EXPECT_NEAR(previous_euler_error / euler_error, 2.0, 0.05);
    }
    previous_euler_error = euler_error;
  }
}

// Wang's Eq. 6 in the world frame: x += v tau sinc(w tau / 2) cos(theta + w tau / 2), etc.
TEST(DiffDriveModelTest, MatchesEquationSixOfTheReport) {
  const Pose2 start(1.0, -2.0, 0.7);
  const double v_tau = 0.3, w_tau = -0.4;
  const Pose2 p = IntegrateDiffDrive(start, v_tau, w_tau);
  const double half = 0.5 * w_tau;
  EXPECT_NEAR(p.x(), 1.0 + v_tau * std::sin(half) / half * std::cos(0.7 + half), 1e-12);
  EXPECT_NEAR(p.y(), -2.0 + v_tau * std::sin(half) / half * std::sin(0.7 + half), 1e-12);
  EXPECT_NEAR(p.theta(), 0.7 + w_tau, 1e-12);
  EXPECT_NEAR(Sinc(1e-6), 1.0, 1e-12);
  EXPECT_NEAR(Sinc(0.5), std::sin(0.5) / 0.5, 1e-15);
}

}  // namespace
}  // namespace slamrig::slam
