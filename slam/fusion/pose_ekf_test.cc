#include "slam/fusion/pose_ekf.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>

#include "slam/fusion/consistency.h"

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

// A turn in place adds nothing through the distance terms; the skid term adds position variance
// k^2 |turned| per axis however the turn is split into encoder intervals (a random walk in the
// yaw turned), and nothing at all with k = 0.
TEST(PoseEkfTest, SkidNoiseGrowsWithTheYawTurnedNotWithTheIntervals) {
  const double k = 0.05;
  const double turn = 1.5 * M_PI;
  for (const int intervals : {3, 40}) {
    for (const double skid : {k, 0.0}) {
      PoseEkfOptions options;
      options.encoder_skid_sigma_m_per_sqrt_rad = skid;
      PoseEkf ekf(options);
      ekf.ResetPose(Pose2());
      const double wheel = 0.5 * 0.4 * turn / intervals;  // right forward, left back
      for (int i = 0; i < intervals; ++i) ekf.PredictWheels(wheel, -wheel, 0.4, turn / intervals);
      const Eigen::Matrix3d p = ekf.PoseCovariance();
      EXPECT_NEAR(p(0, 0), skid * skid * turn, 1e-15) << intervals;
      EXPECT_NEAR(p(1, 1), skid * skid * turn, 1e-15) << intervals;
      EXPECT_NEAR(p(0, 1), 0.0, 1e-15);
    }
  }
}

// The slip the gyro saw adds share^2 * slip_m2 to x and to y, on top of the distance terms, and
// nothing with share = 0.
TEST(PoseEkfTest, SlipAddsPositionVarianceInProportionToTheSlip) {
  for (const double sigma : {0.29, 0.0}) {
    PoseEkfOptions options;
    options.encoder_slip_share = sigma;
    PoseEkf with(options), without(options);
    with.ResetPose(Pose2());
    without.ResetPose(Pose2());
    for (int i = 0; i < 10; ++i) {
      with.PredictWheels(0.01, 0.01, 0.4, 0.0, 0.003);
      without.PredictWheels(0.01, 0.01, 0.4, 0.0, 0.0);
    }
    const Eigen::Matrix3d added = with.PoseCovariance() - without.PoseCovariance();
    EXPECT_NEAR(added(0, 0), sigma * sigma * 0.03, 1e-15);
    EXPECT_NEAR(added(1, 1), sigma * sigma * 0.03, 1e-15);
    EXPECT_NEAR(added(0, 1), 0.0, 1e-15);
    EXPECT_NEAR(added(2, 2), 0.0, 1e-15);
  }
}

TEST(PoseEkfOptionsTest, RejectsANegativeSkidNoiseByItsKey) {
  PoseEkfOptions options;
  options.encoder_skid_sigma_m_per_sqrt_rad = -0.1;
  const std::vector<std::string> errors = options.Validate();
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("encoder_skid_sigma_m_per_sqrt_rad"), std::string::npos) << errors[0];
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
    ASSERT_GT(MinEigenvalue(
                  p + 1e-15 * Eigen::MatrixXd::Identity(PoseEkf::kStateSize, PoseEkf::kStateSize)),
              0.0)
        << step;
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

// Anchored with an exact first match, the matcher's frame ties its poses to the filter's, so a
// second match m * pose = z2 measures the motion since the first: the same update as the relative
// one of z1^-1 z2 with z2's covariance turned into z1's frame.
TEST(PoseEkfTest, AnchoredMatcherPoseUpdateEqualsTheRelativeUpdate) {
  const Pose2 start(1.0, -2.0, 0.7);
  PoseEkf anchored{PoseEkfOptions{}};
  anchored.ResetPose(start);
  for (int i = 0; i < 5; ++i) anchored.PredictWheels(0.1, 0.09, 0.4, 0.02);
  anchored.Clone();
  const Pose2 z1(4.0, 3.0, -0.4);
  anchored.AnchorMatcherFrame(z1, Eigen::Matrix3d::Zero());
  PoseEkf relative = anchored;
  for (PoseEkf* ekf : {&anchored, &relative}) {
    for (int i = 0; i < 8; ++i) ekf->PredictWheels(0.1, 0.08, 0.4, std::nullopt);
  }
  const Pose2 motion = relative.clone().Between(relative.pose()) * Pose2(0.01, -0.02, 0.003);
  const Pose2 z2 = z1 * motion;
  Eigen::Matrix3d r;
  r << 4e-4, 1e-4, 2e-5, 1e-4, 2e-4, -1e-5, 2e-5, -1e-5, 1e-5;
  anchored.UpdateMatcherPose(z2, r);
  relative.UpdateRelativePose(motion, RotateCovariance(r, -z1.theta()));
  EXPECT_NEAR(anchored.pose().x(), relative.pose().x(), 1e-9);
  EXPECT_NEAR(anchored.pose().y(), relative.pose().y(), 1e-9);
  EXPECT_NEAR(anchored.pose().theta(), relative.pose().theta(), 1e-9);
  EXPECT_LT((anchored.PoseCovariance() - relative.PoseCovariance()).norm(),
            1e-9 * relative.PoseCovariance().norm());
}

// Monte Carlo against the filter's own model: a robot drives a circle with encoder and gyro noise
// drawn as PoseEkfOptions states them, a matcher reports m * pose with white noise while its
// frame m drifts per keyframe; the filter's ANEES of the final pose over the runs lies in the
// two-sided 95 % chi-square region, and the NIS averages its dimension.
TEST(PoseEkfTest, MatcherPoseUpdatesAreConsistentOverMonteCarloRuns) {
  const PoseEkfOptions options;
  const double dt = 0.01;
  const Eigen::Matrix3d r = Eigen::Vector3d(4e-6, 2e-6, 1e-7).asDiagonal();
  const Eigen::Matrix3d q = 0.09 * r;  // the frame's drift per keyframe
  const int runs = 200;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal;
  const auto draw = [&](const Eigen::Matrix3d& cov) {
    const Eigen::Matrix3d l = cov.llt().matrixL();
    const double z = normal(rng), y = normal(rng), x = normal(rng);  // sequenced, z first
    return Eigen::Vector3d(l * Eigen::Vector3d(x, y, z));
  };
  // `pose` moved by an additive (x, y, yaw) perturbation: the measurement model's noise.
  const auto plus = [](const Pose2& pose, const Eigen::Vector3d& d) {
    return Pose2(pose.x() + d.x(), pose.y() + d.y(), pose.theta() + d.z());
  };
  double nees_sum = 0.0, nis_sum = 0.0;
  int updates = 0;
  for (int run = 0; run < runs; ++run) {
    PoseEkf ekf(options);
    ekf.ResetPose(Pose2());
    ekf.AnchorMatcherFrame(Pose2(), Eigen::Matrix3d::Zero());
    Pose2 truth;
    Pose2 frame;  // the matcher's true frame
    const double bias = options.gyro_bias_sigma_rad_s * normal(rng);
    const double scale = options.gyro_scale_sigma * normal(rng);
    for (int step = 0; step < 400; ++step) {
      // 0.4 m/s on a circle of 2 m radius; four gyro samples per encoder interval.
      const double rate = 0.2, speed = 0.4;
      double turned = 0.0, gyro_turned = 0.0;
      for (int g = 0; g < 4; ++g) {
        const double reading = (rate + bias + options.gyro_sigma_rad_s * normal(rng)) / (1 - scale);
        // The filter integrates the reading with its bias and scale estimates; the truth turns at
        // `rate`.
        gyro_turned += (reading - ekf.gyro_bias()) * dt;
        turned += rate * dt;
        ekf.PredictGyro(reading, dt);
      }
      const double distance = speed * 4 * dt;
      const double lateral = distance * options.encoder_lateral_sigma_rel * normal(rng);
      const Eigen::Vector2d move(distance * (1.0 + options.encoder_sigma_rel * normal(rng)),
                                 lateral);
      // The translation follows the mean heading of the interval, as the filter's model says.
      const double heading = truth.theta() + 0.5 * turned;
      const Eigen::Vector2d world = Eigen::Rotation2Dd(heading) * move;
      truth = Pose2(truth.x() + world.x(), truth.y() + world.y(), truth.theta() + turned);
      ekf.PredictWheels(distance, distance, 0.4, gyro_turned);
      if (step % 10 == 9) {
        const Pose2 z = plus(frame * truth, draw(r));
        nis_sum += ekf.UpdateMatcherPose(z, r).nis;
        ++updates;
        frame = plus(frame * truth, draw(q)) * truth.Inverse();
        ekf.DriftMatcherFrame(q);
        ekf.Clone();
      }
    }
    nees_sum += PoseNees(truth, ekf.pose(), ekf.PoseCovariance());
  }
  const NeesBounds bounds = AneesBounds(3, runs);
  EXPECT_GT(nees_sum / runs, bounds.lower);
  EXPECT_LT(nees_sum / runs, bounds.upper);
  EXPECT_NEAR(nis_sum / updates, 3.0, 0.3);
}

}  // namespace
}  // namespace slamrig::slam
