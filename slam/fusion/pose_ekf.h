// An error-state-free EKF for a planar robot with a gyro bias, predicted by wheel encoders and the
// gyro at their own rates and corrected by relative pose measurements (scan-match increments)
// through stochastic cloning (Roumeliotis and Burdick, "Stochastic cloning: a generalized
// framework for processing relative state measurements", ICRA 2002, Sec. III). The update uses the
// Joseph form (Bar-Shalom, Li and Kirubarajan, "Estimation with Applications to Tracking and
// Navigation", 2001, Eq. 5.2.3-18), which keeps the covariance symmetric positive semi-definite.
#pragma once

#include <Eigen/Core>
#include <optional>

#include "slam/fusion/pose_ekf_options.h"
#include "slam/types/pose2.h"

namespace slamrig::slam {

/// The Joseph-form covariance after a Kalman update with gain `k`, measurement Jacobian `h` and
/// measurement covariance `r`: (I - K H) P (I - K H)^T + K R K^T, symmetrised.
Eigen::MatrixXd JosephUpdate(const Eigen::MatrixXd& p, const Eigen::MatrixXd& k,
                             const Eigen::MatrixXd& h, const Eigen::MatrixXd& r);

/// What one Kalman update did.
struct EkfUpdate {
  double nis = 0.0;   ///< normalised innovation squared, nu^T S^-1 nu
  int dimension = 0;  ///< the measurement's dimension (the NIS's chi-square degrees of freedom)
  /// The factor the motion's covariance was scaled by before the update (1: none).
  double inflation = 1.0;
};

/// The filter. State: the clone c = (x, y, yaw) of the pose at the last clone, the current pose
/// (x, y, yaw), the gyro bias b (rad/s), the gyro's scale error s (the gyro reads (1 + s) times
/// the rate, plus b) and the matcher's frame m = matcher_from_filter (x, y, yaw): where a scan
/// matcher's own frame (its local map) sits, so that its absolute poses m * pose can be fused
/// with errors independent from match to match while m drifts slowly; 11 x 11 covariance. Poses
/// in one fixed frame. Deterministic; not thread-safe.
class PoseEkf {
 public:
  explicit PoseEkf(const PoseEkfOptions& options);

  /// Sets the current pose and the clone to `pose` with zero pose covariance; the bias and its
  /// variance stay (the estimator's frame starts here).
  void ResetPose(const Pose2& pose);
  /// The gyro z sample `rate_rad_s` held for `dt_s` seconds: yaw += (rate - s rate - b) dt.
  void PredictGyro(double rate_rad_s, double dt_s);
  /// One encoder interval: the wheels rolled `right_m` and `left_m`; `gyro_yaw_rad` is the yaw the
  /// gyro added since the previous interval (the translation follows the mean heading), or
  /// nullopt when no gyro sample came, and the yaw comes from the wheel difference; `slip_m2` is
  /// the wheel slip the gyro saw in the interval (WheelSlipStep::coherent_m2), position variance
  /// encoder_slip_share^2 times that.
  void PredictWheels(double right_m, double left_m, double track_width_m,
                     std::optional<double> gyro_yaw_rad, double slip_m2 = 0.0);
  /// A robot-frame increment from odometry poses, `distance_m` travelled and `turn_rad` turned.
  void PredictIncrement(const Pose2& increment, double distance_m, double turn_rad);
  /// Measures clone^-1 * pose = `z` with covariance `r` (x, y, yaw in the clone's frame). With
  /// `inflation_gate`, an NIS above it means the motion since the clone broke its model (wheel
  /// slip): the motion's covariance is scaled up until the NIS meets the gate, then the update.
  EkfUpdate UpdateRelativePose(const Pose2& z, const Eigen::Matrix3d& r,
                               std::optional<double> inflation_gate = std::nullopt);
  /// Anchors the matcher's frame: m = z * pose^-1 for a match `z` with covariance `r` (matcher
  /// frame), correlated with the pose through that relation. The match carries no information
  /// about the pose then; the next UpdateMatcherPose measures the motion since this one.
  void AnchorMatcherFrame(const Pose2& z, const Eigen::Matrix3d& r);
  /// Measures the pose in the matcher's frame, m * pose = `z`, with covariance `r` (matcher
  /// frame); `inflation_gate` as in UpdateRelativePose (the motion since the clone is inflated).
  EkfUpdate UpdateMatcherPose(const Pose2& z, const Eigen::Matrix3d& r,
                              std::optional<double> inflation_gate = std::nullopt);
  /// The matcher's frame drifts: its pose of the robot moves by a perturbation of covariance `q`
  /// (matcher frame, at the robot), as when a keyframe joins its map with an error.
  void DriftMatcherFrame(const Eigen::Matrix3d& q);
  /// A gyro sample taken at standstill measures the bias: b = rate.
  EkfUpdate UpdateZeroRate(double rate_rad_s);
  /// The clone becomes the current pose (the next relative measurement starts here).
  void Clone();

  Pose2 pose() const { return {x_(3), x_(4), x_(5)}; }
  Pose2 clone() const { return {x_(0), x_(1), x_(2)}; }
  double gyro_bias() const { return x_(6); }
  double gyro_bias_variance() const { return p_(6, 6); }
  double gyro_scale_error() const { return x_(7); }
  Pose2 matcher_frame() const { return {x_(8), x_(9), x_(10)}; }
  /// Covariance of (x, y, yaw) of pose().
  Eigen::Matrix3d PoseCovariance() const { return p_.block<3, 3>(3, 3); }
  static constexpr int kStateSize = 11;
  /// The whole covariance.
  const Eigen::Matrix<double, kStateSize, kStateSize>& covariance() const { return p_; }
  /// The whole state: clone (x, y, yaw), pose (x, y, yaw), gyro bias, gyro scale error, matcher
  /// frame (x, y, yaw).
  const Eigen::Matrix<double, kStateSize, 1>& state() const { return x_; }
  /// Replaces the state and its covariance: for a filter that carries this state inside a larger
  /// one (EKF-SLAM) and predicts through this one's motion model.
  void SetState(const Eigen::Matrix<double, kStateSize, 1>& x,
                const Eigen::Matrix<double, kStateSize, kStateSize>& p) {
    x_ = x;
    p_ = p;
  }

 private:
  EkfUpdate Update(const Eigen::VectorXd& innovation, const Eigen::MatrixXd& h,
                   const Eigen::MatrixXd& r);
  /// Scales the covariance of the motion since the clone (as process noise on the pose) by the
  /// smallest factor that brings the NIS of `innovation` with measurement Jacobian `h` and noise
  /// `r` down to `gate`; the factor (1: none needed).
  double InflateMotion(const Eigen::VectorXd& innovation, const Eigen::MatrixXd& h,
                       const Eigen::MatrixXd& r, double gate);
  /// d(m * pose)/d(m) and d(m * pose)/d(pose) at the current state, 3 x 3 each.
  Eigen::Matrix3d MatcherPoseJacobianFrame() const;
  Eigen::Matrix3d MatcherPoseJacobianPose() const;

  PoseEkfOptions options_;
  Eigen::Matrix<double, kStateSize, 1> x_ = Eigen::Matrix<double, kStateSize, 1>::Zero();
  Eigen::Matrix<double, kStateSize, kStateSize> p_ =
      Eigen::Matrix<double, kStateSize, kStateSize>::Zero();
};

}  // namespace slamrig::slam
