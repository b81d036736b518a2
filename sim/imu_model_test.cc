#include "sim/imu_model.h"

#include <gtest/gtest.h>

#include <cmath>

namespace slamrig::sim {
namespace {

TEST(ImuModelTest, WithoutNoiseReportsTheTruth) {
  ImuOptions o;
  o.gyro = ImuNoise{};
  o.accel = ImuNoise{};
  ImuModel imu(o, 1);
  const ImuSample s = imu.Measure(Time::FromSeconds(1.0), {0.1, 0.2, 0.3}, {1.0, 2.0, 9.8});
  EXPECT_EQ(s.angular_velocity_rad_s, Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_EQ(s.linear_acceleration_m_s2, Eigen::Vector3d(1.0, 2.0, 9.8));
}

TEST(ImuModelTest, ScaleBiasAndSaturation) {
  ImuOptions o;
  o.gyro = ImuNoise{0.0, 0.0, 0.01, 0.0, 0.02, 1.0};
  ImuModel imu(o, 1);
  const ImuSample s = imu.Measure(Time{}, {0.0, 0.5, 3.0}, {0.0, 0.0, 9.8});
  EXPECT_NEAR(s.angular_velocity_rad_s.x(), 0.01, 1e-15);
  EXPECT_NEAR(s.angular_velocity_rad_s.y(), 1.02 * 0.5 + 0.01, 1e-15);
  EXPECT_EQ(s.angular_velocity_rad_s.z(), 1.0);
}

TEST(ImuModelTest, WhiteNoiseAndRandomWalkFollowTheirDensities) {
  ImuOptions o;
  o.rate_hz = 100.0;
  o.gyro = ImuNoise{1e-3, 0.0, 0.0, 0.0, 0.0, 0.0};
  o.accel = ImuNoise{0.0, 1e-2, 0.0, 0.0, 0.0, 0.0};
  ImuModel imu(o, 5);
  // White: discrete stddev density * sqrt(rate). Walk: after T seconds, stddev walk * sqrt(T).
  constexpr int kSamples = 40000;  // 400 s
  double sum2 = 0.0;
  Eigen::Vector3d last_accel;
  for (int i = 0; i < kSamples; ++i) {
    const ImuSample s =
        imu.Measure(Time::FromSeconds(i * 0.01), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
    sum2 += s.angular_velocity_rad_s.squaredNorm() / 3.0;
    last_accel = s.linear_acceleration_m_s2;
  }
  EXPECT_NEAR(std::sqrt(sum2 / kSamples), 1e-3 * std::sqrt(100.0), 2e-4);
  // One draw of a walk: only its order of magnitude is testable (1e-2 * sqrt(400) = 0.2).
  EXPECT_LT(last_accel.cwiseAbs().maxCoeff(), 1.0);
  EXPECT_GT(last_accel.cwiseAbs().maxCoeff(), 0.01);
}

TEST(ImuModelTest, ValidateNamesTheTriad) {
  ImuOptions o;
  o.gyro.noise_density = -1.0;
  ASSERT_EQ(o.Validate().size(), 1u);
  EXPECT_EQ(o.Validate()[0], "gyro.noise_density = -1; must be >= 0");
}

}  // namespace
}  // namespace slamrig::sim
