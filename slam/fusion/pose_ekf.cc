#include "slam/fusion/pose_ekf.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>

#include "slam/types/check.h"

namespace slamrig::slam {
namespace {

constexpr int kN = PoseEkf::kStateSize;
constexpr int kYaw = 5;
constexpr int kBias = 6;
constexpr int kScale = 7;
constexpr int kFrame = 8;  // the matcher's frame: x, y, yaw at 8, 9, 10

double Squared(double v) { return v * v; }

// d(R(yaw) p)/d(yaw) = R(yaw + pi/2) p.
Eigen::Vector2d RotatedDerivative(double yaw, const Eigen::Vector2d& p) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  return {-s * p.x() - c * p.y(), c * p.x() - s * p.y()};
}

}  // namespace

Eigen::MatrixXd JosephUpdate(const Eigen::MatrixXd& p, const Eigen::MatrixXd& k,
                             const Eigen::MatrixXd& h, const Eigen::MatrixXd& r) {
  const Eigen::MatrixXd a = Eigen::MatrixXd::Identity(p.rows(), p.cols()) - k * h;
  const Eigen::MatrixXd updated = a * p * a.transpose() + k * r * k.transpose();
  return 0.5 * (updated + updated.transpose());
}

PoseEkf::PoseEkf(const PoseEkfOptions& options) : options_(options) {
  SLAMRIG_CHECK_VALID(options, "PoseEkfOptions");
  p_(kBias, kBias) = Squared(options.gyro_bias_sigma_rad_s);
  p_(kScale, kScale) = Squared(options.gyro_scale_sigma);
}

void PoseEkf::ResetPose(const Pose2& pose) {
  const Eigen::Matrix2d gyro = p_.block<2, 2>(kBias, kBias);
  p_.setZero();
  p_.block<2, 2>(kBias, kBias) = gyro;
  x_.head<3>() << pose.x(), pose.y(), pose.theta();
  x_.segment<3>(3) = x_.head<3>();
  x_.segment<3>(kFrame).setZero();
}

void PoseEkf::PredictGyro(double rate_rad_s, double dt_s) {
  if (!(dt_s > 0.0)) return;
  // yaw' = yaw + (rate - s rate - b) dt: F is the identity but for d yaw / d b = -dt and
  // d yaw / d s = -rate dt.
  x_(kYaw) = NormalizeAngle(x_(kYaw) + (rate_rad_s - x_(kScale) * rate_rad_s - x_(kBias)) * dt_s);
  Eigen::Matrix<double, kN, kN> f = Eigen::Matrix<double, kN, kN>::Identity();
  f(kYaw, kBias) = -dt_s;
  f(kYaw, kScale) = -rate_rad_s * dt_s;
  p_ = f * p_ * f.transpose();
  p_(kYaw, kYaw) += Squared(options_.gyro_sigma_rad_s * dt_s);
  p_(kBias, kBias) += Squared(options_.gyro_bias_walk_rad_s_sqrt_s) * dt_s;
}

void PoseEkf::PredictWheels(double right_m, double left_m, double track_width_m,
                            std::optional<double> gyro_yaw_rad, double slip_m2) {
  const double distance = 0.5 * (right_m + left_m);
  double encoder_yaw = 0.0;
  if (!gyro_yaw_rad) {
    encoder_yaw = (right_m - left_m) / track_width_m;
    x_(kYaw) = NormalizeAngle(x_(kYaw) + encoder_yaw);
  }
  // The mean heading of the interval: the yaw now minus half of what this interval turned.
  const double turned = gyro_yaw_rad ? *gyro_yaw_rad : encoder_yaw;
  const double heading = x_(kYaw) - 0.5 * turned;
  const double c = std::cos(heading), s = std::sin(heading);
  x_(3) += distance * c;
  x_(4) += distance * s;
  Eigen::Matrix<double, kN, kN> f = Eigen::Matrix<double, kN, kN>::Identity();
  f(3, kYaw) = -distance * s;
  f(4, kYaw) = distance * c;
  p_ = f * p_ * f.transpose();
  // Along-track and lateral noise, rotated into the fixed frame.
  const double along = Squared(options_.encoder_sigma_rel * distance);
  const double lateral = Squared(options_.encoder_lateral_sigma_rel * distance);
  p_(3, 3) += c * c * along + s * s * lateral;
  p_(4, 4) += s * s * along + c * c * lateral;
  p_(3, 4) += c * s * (along - lateral);
  p_(4, 3) = p_(3, 4);
  const double skid = Squared(options_.encoder_skid_sigma_m_per_sqrt_rad) * std::abs(turned);
  // Slip moves the base by an unknown share of it, in any direction (a slipping turn in place
  // drifts sideways as much as along).
  const double slip = Squared(options_.encoder_slip_share) * std::max(0.0, slip_m2);
  p_(3, 3) += skid + slip;
  p_(4, 4) += skid + slip;
  if (!gyro_yaw_rad) {
    p_(kYaw, kYaw) += Squared(options_.encoder_yaw_sigma_rel *
                              (std::abs(right_m) + std::abs(left_m)) / track_width_m);
  }
}

void PoseEkf::PredictIncrement(const Pose2& increment, double distance_m, double turn_rad) {
  const Pose2 before = pose();
  const Pose2 after = before * increment;
  x_.segment<3>(3) << after.x(), after.y(), after.theta();
  const double c = std::cos(before.theta()), s = std::sin(before.theta());
  // d(after)/d(before): translation rotates with the heading.
  Eigen::Matrix<double, kN, kN> f = Eigen::Matrix<double, kN, kN>::Identity();
  f(3, kYaw) = -s * increment.x() - c * increment.y();
  f(4, kYaw) = c * increment.x() - s * increment.y();
  p_ = f * p_ * f.transpose();
  const double distance = std::abs(distance_m);
  const double sxy =
      options_.increment_sigma_xy_per_m * distance + options_.increment_sigma_xy_floor_m;
  const double syaw = options_.increment_sigma_yaw_per_rad * std::abs(turn_rad) +
                      options_.increment_sigma_yaw_per_m * distance +
                      options_.increment_sigma_yaw_floor_rad;
  p_(3, 3) += sxy * sxy;
  p_(4, 4) += sxy * sxy;
  p_(kYaw, kYaw) += syaw * syaw;
}

EkfUpdate PoseEkf::UpdateRelativePose(const Pose2& z, const Eigen::Matrix3d& r,
                                      std::optional<double> inflation_gate) {
  const Pose2 predicted = clone().Between(pose());
  const double c = std::cos(x_(2)), s = std::sin(x_(2));
  const Eigen::Vector2d d = x_.segment<2>(3) - x_.head<2>();
  // h = (R(c)^T (p - c_xy), yaw - c_yaw); its Jacobian with respect to (clone, pose, bias).
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(3, kN);
  h(0, 0) = -c;
  h(0, 1) = -s;
  h(1, 0) = s;
  h(1, 1) = -c;
  h(0, 2) = -s * d.x() + c * d.y();
  h(1, 2) = -c * d.x() - s * d.y();
  h(0, 3) = c;
  h(0, 4) = s;
  h(1, 3) = -s;
  h(1, 4) = c;
  h(2, 2) = -1.0;
  h(2, kYaw) = 1.0;
  Eigen::VectorXd innovation(3);
  innovation << z.x() - predicted.x(), z.y() - predicted.y(),
      NormalizeAngle(z.theta() - predicted.theta());
  const double inflation = inflation_gate ? InflateMotion(innovation, h, r, *inflation_gate) : 1.0;
  EkfUpdate update = Update(innovation, h, r);
  update.inflation = inflation;
  return update;
}

double PoseEkf::InflateMotion(const Eigen::VectorXd& innovation, const Eigen::MatrixXd& h,
                              const Eigen::MatrixXd& r, double gate) {
  const Eigen::MatrixXd s0 = h * p_ * h.transpose() + r;
  if (innovation.dot(s0.ldlt().solve(innovation)) <= gate) return 1.0;
  // The motion's covariance since the clone, in the clone's frame, rotated into the fixed frame:
  // the pose's own noise since the clone.
  const double c = std::cos(x_(2)), s = std::sin(x_(2));
  const Eigen::Vector2d d = x_.segment<2>(3) - x_.head<2>();
  Eigen::Matrix<double, 3, kN> relative = Eigen::Matrix<double, 3, kN>::Zero();
  relative.block<2, 2>(0, 0) << -c, -s, s, -c;
  relative(0, 2) = -s * d.x() + c * d.y();
  relative(1, 2) = -c * d.x() - s * d.y();
  relative.block<2, 2>(0, 3) << c, s, -s, c;
  relative(2, 2) = -1.0;
  relative(2, kYaw) = 1.0;
  const Eigen::Matrix3d motion = relative * p_ * relative.transpose();
  const Eigen::Matrix3d added = RotateCovariance(motion, x_(2));
  // What a unit of extra motion noise adds to the innovation's covariance.
  const Eigen::MatrixXd h_pose = h.middleCols<3>(3);
  const Eigen::MatrixXd a = h_pose * added * h_pose.transpose();
  const auto nis = [&](double scale) {
    return innovation.dot((s0 + (scale - 1.0) * a).ldlt().solve(innovation));
  };
  // The motion model failed (a wheel slipped): the smallest scale of the motion's covariance
  // that brings the NIS down to the gate (it falls monotonically with the scale), by bisection
  // on a log scale, added as process noise on the current pose alone (Mehra 1972's
  // innovation-based adaptation, one step at a time).
  double lo = 1.0, hi = 1e6;
  if (nis(hi) <= gate) {
    for (int i = 0; i < 40; ++i) {
      const double mid = std::sqrt(lo * hi);
      (nis(mid) > gate ? lo : hi) = mid;
    }
  }
  p_.block<3, 3>(3, 3) += (hi - 1.0) * added;
  return hi;
}

Eigen::Matrix3d PoseEkf::MatcherPoseJacobianFrame() const {
  // m * pose = (m_xy + R(m_yaw) pose_xy, m_yaw + pose_yaw).
  Eigen::Matrix3d j = Eigen::Matrix3d::Identity();
  j.block<2, 1>(0, 2) = RotatedDerivative(x_(kFrame + 2), x_.segment<2>(3));
  return j;
}

Eigen::Matrix3d PoseEkf::MatcherPoseJacobianPose() const {
  Eigen::Matrix3d j = Eigen::Matrix3d::Identity();
  j.topLeftCorner<2, 2>() = RotationMatrix(x_(kFrame + 2));
  return j;
}

void PoseEkf::AnchorMatcherFrame(const Pose2& z, const Eigen::Matrix3d& r) {
  const Pose2 frame = z * pose().Inverse();
  x_.segment<3>(kFrame) << frame.x(), frame.y(), frame.theta();
  // m = z * pose^-1: m_yaw = z_yaw - pose_yaw, m_xy = z_xy - R(m_yaw) pose_xy. Its Jacobians with
  // respect to the pose and to z; m's rows become that function of the pose's (its old
  // correlations are dropped) plus the match's own noise.
  const Eigen::Vector2d lever = RotatedDerivative(frame.theta(), x_.segment<2>(3));
  Eigen::Matrix3d j_pose = -Eigen::Matrix3d::Identity();
  j_pose.topLeftCorner<2, 2>() = -frame.Rotation();
  j_pose.block<2, 1>(0, 2) = lever;
  Eigen::Matrix3d j_z = Eigen::Matrix3d::Identity();
  j_z.block<2, 1>(0, 2) = -lever;
  Eigen::Matrix<double, 3, kN> j = Eigen::Matrix<double, 3, kN>::Zero();
  j.middleCols<3>(3) = j_pose;
  const Eigen::Matrix<double, 3, kN> cross = j * p_;
  p_.middleRows<3>(kFrame) = cross;
  p_.middleCols<3>(kFrame) = cross.transpose();
  p_.block<3, 3>(kFrame, kFrame) =
      j_pose * p_.block<3, 3>(3, 3) * j_pose.transpose() + j_z * r * j_z.transpose();
  p_ = 0.5 * (p_ + p_.transpose()).eval();
}

EkfUpdate PoseEkf::UpdateMatcherPose(const Pose2& z, const Eigen::Matrix3d& r,
                                     std::optional<double> inflation_gate) {
  const Pose2 predicted = matcher_frame() * pose();
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(3, kN);
  h.middleCols<3>(3) = MatcherPoseJacobianPose();
  h.middleCols<3>(kFrame) = MatcherPoseJacobianFrame();
  Eigen::VectorXd innovation(3);
  innovation << z.x() - predicted.x(), z.y() - predicted.y(),
      NormalizeAngle(z.theta() - predicted.theta());
  const double inflation = inflation_gate ? InflateMotion(innovation, h, r, *inflation_gate) : 1.0;
  EkfUpdate update = Update(innovation, h, r);
  update.inflation = inflation;
  return update;
}

void PoseEkf::DriftMatcherFrame(const Eigen::Matrix3d& q) {
  // The matcher's pose of the robot z = m * pose moves by dz: m moves by dm/dz dz, with dm/dz as
  // in AnchorMatcherFrame.
  Eigen::Matrix3d j_z = Eigen::Matrix3d::Identity();
  j_z.block<2, 1>(0, 2) = -RotatedDerivative(x_(kFrame + 2), x_.segment<2>(3));
  p_.block<3, 3>(kFrame, kFrame) += j_z * q * j_z.transpose();
}

EkfUpdate PoseEkf::UpdateZeroRate(double rate_rad_s) {
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(1, kN);
  h(0, kBias) = 1.0;
  Eigen::VectorXd innovation(1);
  innovation << rate_rad_s - x_(kBias);
  Eigen::MatrixXd r(1, 1);
  r << Squared(options_.gyro_sigma_rad_s);
  return Update(innovation, h, r);
}

EkfUpdate PoseEkf::Update(const Eigen::VectorXd& innovation, const Eigen::MatrixXd& h,
                          const Eigen::MatrixXd& r) {
  const Eigen::MatrixXd p = p_;
  const Eigen::MatrixXd s = h * p * h.transpose() + r;
  const Eigen::LDLT<Eigen::MatrixXd> s_ldlt(s);
  // K = P H^T S^-1, through the symmetric solve S K^T = H P.
  const Eigen::MatrixXd k = s_ldlt.solve(h * p).transpose();
  Eigen::VectorXd dx = k * innovation;
  x_ += dx;
  x_(2) = NormalizeAngle(x_(2));
  x_(kYaw) = NormalizeAngle(x_(kYaw));
  x_(kFrame + 2) = NormalizeAngle(x_(kFrame + 2));
  p_ = JosephUpdate(p, k, h, r);
  return {innovation.dot(s_ldlt.solve(innovation)), static_cast<int>(innovation.size())};
}

void PoseEkf::Clone() {
  // c' = pose: the clone rows and columns become copies of the pose's.
  Eigen::Matrix<double, kN, kN> j = Eigen::Matrix<double, kN, kN>::Zero();
  j.block<3, 3>(0, 3).setIdentity();
  j.block<kN - 3, kN - 3>(3, 3).setIdentity();
  x_.head<3>() = x_.segment<3>(3);
  p_ = j * p_ * j.transpose();
}

}  // namespace slamrig::slam
