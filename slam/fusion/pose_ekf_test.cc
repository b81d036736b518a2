#include "slam/fusion/pose_ekf.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <random>

namespace slamrig::slam {
namespace {

double MinEigenvalue(const Eigen::MatrixXd& m) {
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(m).eigenvalues().minCoeff();
}

// The Joseph form with a deliberately poor (suboptimal) gain still gives a symmetric positive
// definite matrix, where the short form (I - K H) P does not.
TEST(JosephUpdateTest, KeepsCovarianceSymmetricPositiveDefiniteForAnyGain) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 200; ++trial) {
    Eigen::MatrixXd a(4, 4);
    for (int i = 0; i < 16; ++i) a(i / 4, i % 4) = normal(rng);
    const Eigen::MatrixXd p = a * a.transpose() + 1e-3 * Eigen::MatrixXd::Identity(4, 4);
    Eigen::MatrixXd h(2, 4), k(4, 2);
    for (int i = 0; i < 8; ++i) h(i / 4, i % 4) = normal(rng);
    for (int i = 0; i < 8; ++i) k(i / 2, i % 2) = 3.0 * normal(rng);
    const Eigen::MatrixXd r = 1e-2 * Eigen::MatrixXd::Identity(2, 2);
    const Eigen::MatrixXd updated = JosephUpdate(p, k, h, r);
    EXPECT_EQ((updated - updated.transpose()).norm(), 0.0);
    EXPECT_GT(MinEigenvalue(updated), 0.0);
  }
}

// With the optimal gain, the Joseph form equals the textbook (I - K H) P.
TEST(JosephUpdateTest, EqualsShortFormForOptimalGain) {
  Eigen::MatrixXd p(2, 2);
  p << 2.0, 0.3, 0.3, 1.0;
  Eigen::MatrixXd h(1, 2);
  h << 1.0, 0.5;
  Eigen::MatrixXd r(1, 1);
  r << 0.4;
  const Eigen::MatrixXd s = h * p * h.transpose() + r;
  const Eigen::MatrixXd k = p * h.transpose() * s.inverse();
  const Eigen::MatrixXd short_form = (Eigen::MatrixXd::Identity(2, 2) - k * h) * p;
  EXPECT_LT((JosephUpdate(p, k, h, r) - short_form).norm(), 1e-12);
}

// A slip the motion model cannot explain (0.3 m on a 1 m drive whose model allows 2 %): the
// motion's covariance is scaled until the NIS meets the gate exactly, so the match wins; an
// innovation within the gate leaves the model alone.
TEST(PoseEkfTest, InflatesTheMotionCovarianceUntilTheNisMeetsTheGate) {
  for (const double slip_m : {0.3, 0.0}) {
    PoseEkf ekf{PoseEkfOptions{}};
    ekf.ResetPose(Pose2());
    for (int i = 0; i < 10; ++i) ekf.PredictWheels(0.1, 0.1, 0.4, 0.0);
    const Eigen::Matrix3d r = Eigen::Vector3d(1e-4, 1e-4, 1e-6).asDiagonal();
    const Pose2 z(1.0 + slip_m, 0.0, 0.0);
    const double gate = 16.27;
    // The NIS without inflation, from the same state.
    PoseEkf plain = ekf;
    const EkfUpdate without = plain.UpdateRelativePose(z, r);
    const EkfUpdate with = ekf.UpdateRelativePose(z, r, gate);
    if (slip_m > 0.0) {
      EXPECT_GT(without.nis, gate);
      EXPECT_GT(with.inflation, 1.0);
      EXPECT_NEAR(with.nis, gate, 1e-3 * gate);
      EXPECT_NEAR(ekf.pose().x(), 1.0 + slip_m, 0.02);  // the match, not the wheels
    } else {
      EXPECT_EQ(with.inflation, 1.0);
      EXPECT_EQ(with.nis, without.nis);
    }
  }
}

TEST(PoseEkfTest, CovarianceStaysSymmetricPositiveDefiniteThroughAManyStepRun) {
  PoseEkf ekf{PoseEkfOptions{}};
  ekf.ResetPose(Pose2());
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal;
  for (int step = 0; step < 500; ++step) {
    for (int g = 0; g < 3; ++g) ekf.PredictGyro(0.2 + 0.01 * normal(rng), 0.01);
    ekf.PredictWheels(0.011, 0.009, 0.4, 0.006);
    if (step % 4 == 3) {
      const Pose2 z = ekf.clone().Between(ekf.pose()) * Pose2(0.002, -0.001, 0.001);
      ekf.UpdateRelativePose(z, Eigen::Vector3d(1e-6, 1e-6, 1e-8).asDiagonal());
      ekf.Clone();
    }
    const Eigen::MatrixXd p = ekf.covariance();
    ASSERT_EQ((p - p.transpose()).norm(), 0.0) << step;
    ASSERT_GT(MinEigenvalue(p + 1e-15 * Eigen::MatrixXd::Identity(8, 8)), 0.0) << step;
  }
}

// A relative measurement at a heading across the +-pi cut: the innovation is wrapped, so the
// update moves the yaw by the small true difference, not by ~2 pi.
TEST(PoseEkfTest, RelativeUpdateWrapsTheAngle) {
  PoseEkf ekf{PoseEkfOptions{}};
  ekf.ResetPose(Pose2(0.0, 0.0, 3.1));
  ekf.PredictIncrement(Pose2(1.0, 0.0, 0.08), 1.0, 0.08);  // yaw 3.18 -> wraps to -3.10
  const Pose2 z(1.0, 0.0, 0.1);
  ekf.UpdateRelativePose(z, Eigen::Vector3d(1e-4, 1e-4, 1e-6).asDiagonal());
  const double relative_yaw = NormalizeAngle(ekf.pose().theta() - 3.1);
  EXPECT_NEAR(relative_yaw, 0.1, 0.005);
}

// The gyro bias is not observable from the gyro alone, but a relative yaw measurement against
// the gyro's integral (or standstill samples) reveals it.
TEST(PoseEkfTest, EstimatesGyroBiasFromRelativeYawAndFromStandstill) {
  const double bias = 0.01;
  PoseEkf ekf{PoseEkfOptions{}};
  ekf.ResetPose(Pose2());
  for (int k = 0; k < 200; ++k) {
    for (int g = 0; g < 10; ++g) ekf.PredictGyro(0.1 + bias, 0.01);  // true rate 0.1 rad/s
    ekf.UpdateRelativePose(Pose2(0.0, 0.0, 0.01), Eigen::Vector3d(1e-6, 1e-6, 1e-6).asDiagonal());
    ekf.Clone();
  }
  EXPECT_NEAR(ekf.gyro_bias(), bias, 1e-3);

  PoseEkf still{PoseEkfOptions{}};
  for (int k = 0; k < 400; ++k) still.UpdateZeroRate(bias + (k % 2 == 0 ? 0.01 : -0.01));
  EXPECT_NEAR(still.gyro_bias(), bias, 1e-3);
}

}  // namespace
}  // namespace slamrig::slam
