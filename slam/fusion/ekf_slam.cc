#include "slam/fusion/ekf_slam.h"

#include <Eigen/Cholesky>
#include <cmath>

#include "slam/fusion/consistency.h"
#include "slam/fusion/data_association.h"
#include "slam/types/check.h"
#include "slam/types/validation.h"

namespace slamrig::slam {
namespace {

constexpr int kP = EkfSlam::kPoseDim;
constexpr int kStateBias = 3;

// PoseEkf's state: clone (0-2), pose (3-5), gyro bias (6), gyro scale error (7), matcher frame
// (8-10); EKF-SLAM uses the pose and gyro block (3-7) and leaves the others at zero.
constexpr int kMotionN = PoseEkf::kStateSize;
using MotionMatrix = Eigen::Matrix<double, kMotionN, kMotionN>;
using MotionVector = Eigen::Matrix<double, kMotionN, 1>;

int LandmarkRow(int j) { return kP + 2 * j; }

}  // namespace

std::vector<std::string> EkfSlamOptions::Validate() const {
  Rules rules;
  rules.Nested("", motion.Validate())
      .Nested("extraction", extraction.Validate())
      .Require(gate_probability > 0.0 && gate_probability < 1.0, "gate_probability",
               gate_probability, "must be in (0, 1)")
      .Require(
          new_landmark_gate_probability >= gate_probability && new_landmark_gate_probability < 1.0,
          "new_landmark_gate_probability", new_landmark_gate_probability,
          "must be in [gate_probability, 1)")
      .AtLeast("min_sightings", min_sightings, 1)
      .Positive("tentative_radius_m", tentative_radius_m)
      .AtLeast("tentative_max_age_scans", tentative_max_age_scans, 1)
      .NonNegative("max_range_m", max_range_m);
  return rules.errors();
}

RangeBearingPrediction PredictRangeBearing(const Pose2& pose, const Eigen::Vector2d& landmark) {
  const Eigen::Vector2d d = landmark - pose.translation();
  const double q = d.squaredNorm();
  const double r = std::sqrt(q);
  RangeBearingPrediction out;
  out.z << r, NormalizeAngle(std::atan2(d.y(), d.x()) - pose.theta());
  out.d_pose << -d.x() / r, -d.y() / r, 0.0, d.y() / q, -d.x() / q, -1.0;
  out.d_landmark << d.x() / r, d.y() / r, -d.y() / q, d.x() / q;
  return out;
}

LandmarkFromObservation InverseRangeBearing(const Pose2& pose, const Eigen::Vector2d& z) {
  const double a = pose.theta() + z(1);
  const double c = std::cos(a), s = std::sin(a);
  LandmarkFromObservation out;
  out.position = pose.translation() + z(0) * Eigen::Vector2d(c, s);
  out.d_pose << 1.0, 0.0, -z(0) * s, 0.0, 1.0, z(0) * c;
  out.d_observation << c, -z(0) * s, s, z(0) * c;
  return out;
}

EkfSlam::EkfSlam(const EkfSlamOptions& options)
    : options_(options),
      x_(Eigen::VectorXd::Zero(kP)),
      p_(Eigen::MatrixXd::Zero(kP, kP)),
      motion_(options.motion),
      probe_pose_(options.motion),
      probe_gyro_(options.motion) {
  SLAMRIG_CHECK_VALID(options, "EkfSlamOptions");
  // PoseEkf's prior on the gyro states.
  p_(kStateBias, kStateBias) =
      options.motion.gyro_bias_sigma_rad_s * options.motion.gyro_bias_sigma_rad_s;
  p_(kStateBias + 1, kStateBias + 1) =
      options.motion.gyro_scale_sigma * options.motion.gyro_scale_sigma;
}

void EkfSlam::ResetPose(const Pose2& pose) {
  x_.head<3>() << pose.x(), pose.y(), pose.theta();
  p_.topRows<3>().setZero();
  p_.leftCols<3>().setZero();
}

template <typename Step>
void EkfSlam::Predict(const Step& step) {
  MotionVector x = MotionVector::Zero();
  x.head<8>() << x_.head<3>(), x_.head<3>(), x_(kStateBias), x_(kStateBias + 1);
  // The filter proper: no clone, the pose and gyro states' covariance.
  MotionMatrix p = MotionMatrix::Zero();
  p.block<5, 5>(3, 3) = p_.topLeftCorner<5, 5>();
  motion_.SetState(x, p);
  // Probe 1: clone == pose with unit covariance, so cov(pose', clone) = F[:, pose].
  MotionMatrix a = MotionMatrix::Zero();
  a.topLeftCorner<3, 3>().setIdentity();
  a.block<3, 3>(0, 3).setIdentity();
  a.block<3, 3>(3, 0).setIdentity();
  a.block<3, 3>(3, 3).setIdentity();
  probe_pose_.SetState(x, a);
  // Probe 2: clone x == bias, clone y == scale, so cov(state', clone xy) = F[:, bias, scale].
  MotionMatrix b = MotionMatrix::Zero();
  b(0, 0) = b(0, 6) = b(6, 0) = b(6, 6) = 1.0;
  b(1, 1) = b(1, 7) = b(7, 1) = b(7, 7) = 1.0;
  probe_gyro_.SetState(x, b);
  step(motion_);
  step(probe_pose_);
  step(probe_gyro_);
  Eigen::Matrix<double, 5, 5> f;
  f.leftCols<3>() = probe_pose_.covariance().block<5, 3>(3, 0);
  f.rightCols<2>() = probe_gyro_.covariance().block<5, 2>(3, 0);
  x_.head<kP>() = motion_.state().segment<5>(3);
  p_.topLeftCorner<kP, kP>() = motion_.covariance().block<5, 5>(3, 3);
  const int m = static_cast<int>(x_.size()) - kP;
  if (m > 0) {
    const Eigen::MatrixXd cross = f * p_.topRightCorner(kP, m);
    p_.topRightCorner(kP, m) = cross;
    p_.bottomLeftCorner(m, kP) = cross.transpose();
  }
}

void EkfSlam::PredictGyro(double rate_rad_s, double dt_s) {
  Predict([&](PoseEkf& f) { f.PredictGyro(rate_rad_s, dt_s); });
}

void EkfSlam::PredictWheels(double right_m, double left_m, double track_width_m,
                            std::optional<double> gyro_yaw_rad, double slip_m2) {
  Predict(
      [&](PoseEkf& f) { f.PredictWheels(right_m, left_m, track_width_m, gyro_yaw_rad, slip_m2); });
}

void EkfSlam::PredictIncrement(const Pose2& increment, double distance_m, double turn_rad) {
  Predict([&](PoseEkf& f) { f.PredictIncrement(increment, distance_m, turn_rad); });
}

double EkfSlam::UpdateZeroRate(double rate_rad_s) {
  const int n = static_cast<int>(x_.size());
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(1, n);
  h(0, kStateBias) = 1.0;
  Eigen::MatrixXd r(1, 1);
  r << options_.motion.gyro_sigma_rad_s * options_.motion.gyro_sigma_rad_s;
  const double innovation = rate_rad_s - x_(kStateBias);
  const double s = p_(kStateBias, kStateBias) + r(0, 0);
  const Eigen::MatrixXd k = p_.col(kStateBias) / s;
  x_ += k * innovation;
  x_(2) = NormalizeAngle(x_(2));
  p_ = JosephUpdate(p_, k, h, r);
  return innovation * innovation / s;
}

int EkfSlam::Augment(const Eigen::Vector2d& z, const Eigen::Matrix2d& r) {
  const LandmarkFromObservation g = InverseRangeBearing(pose(), z);
  const int n = static_cast<int>(x_.size());
  // The new rows: G_p times the pose rows (the landmark's correlation with everything the pose
  // is correlated with), and its own block with the observation's noise.
  const Eigen::MatrixXd cross = g.d_pose * p_.topRows<3>();  // 2 x n
  const Eigen::Matrix2d own = g.d_pose * p_.topLeftCorner<3, 3>() * g.d_pose.transpose() +
                              g.d_observation * r * g.d_observation.transpose();
  x_.conservativeResize(n + 2);
  x_.tail<2>() = g.position;
  p_.conservativeResize(n + 2, n + 2);
  p_.bottomLeftCorner(2, n) = cross;
  p_.topRightCorner(n, 2) = cross.transpose();
  p_.bottomRightCorner<2, 2>() = 0.5 * (own + own.transpose());
  return landmarks() - 1;
}

void EkfSlam::Update(const std::vector<LandmarkObservation>& observations,
                     const std::vector<int>& landmark_of_observation, LandmarkUpdate* out) {
  std::vector<int> paired;
  for (int i = 0; i < static_cast<int>(observations.size()); ++i)
    if (landmark_of_observation[i] >= 0) paired.push_back(i);
  const int k = static_cast<int>(paired.size());
  out->pairings = k;
  if (k == 0) return;
  const int n = static_cast<int>(x_.size());
  const Pose2 at = pose();
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(2 * k, n);
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(2 * k, 2 * k);
  Eigen::VectorXd innovation(2 * k);
  for (int a = 0; a < k; ++a) {
    const LandmarkObservation& z = observations[paired[a]];
    const int j = landmark_of_observation[paired[a]];
    const RangeBearingPrediction pred = PredictRangeBearing(at, landmark(j));
    h.block<2, 3>(2 * a, 0) = pred.d_pose;
    h.block<2, 2>(2 * a, LandmarkRow(j)) = pred.d_landmark;
    r.block<2, 2>(2 * a, 2 * a) = z.covariance;
    innovation(2 * a) = z.range_m - pred.z(0);
    innovation(2 * a + 1) = NormalizeAngle(z.bearing_rad - pred.z(1));
  }
  const Eigen::MatrixXd ph = p_ * h.transpose();
  const Eigen::MatrixXd s = h * ph + r;
  const Eigen::LDLT<Eigen::MatrixXd> s_ldlt(s);
  // K = P H^T S^-1, through the symmetric solve S K^T = H P.
  const Eigen::MatrixXd gain = s_ldlt.solve(ph.transpose()).transpose();
  x_ += gain * innovation;
  x_(2) = NormalizeAngle(x_(2));
  p_ = JosephUpdate(p_, gain, h, r);
  out->nis = innovation.dot(s_ldlt.solve(innovation));
  out->dimension = 2 * k;
}

bool EkfSlam::RadiiAgree(const Tentative& t) const {
  // The radii's spread about their inverse-variance weighted mean, in units of their variances:
  // chi-square with n - 1 degrees of freedom when they measure one radius.
  const int n = static_cast<int>(t.radii.size());
  if (n < 2) return true;
  double weight_sum = 0.0, weighted = 0.0;
  for (int i = 0; i < n; ++i) {
    // A fit without residual (exact points) has no variance; it cannot be tested.
    if (!(t.radius_variances[i] > 0.0)) return true;
    weight_sum += 1.0 / t.radius_variances[i];
    weighted += t.radii[i] / t.radius_variances[i];
  }
  const double mean = weighted / weight_sum;
  double q = 0.0;
  for (int i = 0; i < n; ++i)
    q += (t.radii[i] - mean) * (t.radii[i] - mean) / t.radius_variances[i];
  return q <= ChiSquareQuantile(options_.gate_probability, static_cast<double>(n - 1));
}

bool EkfSlam::LooksRound(const Tentative& t) const {
  // One sighting of a corner from afar has too few points to tell it from an arc; ten pooled
  // have the degrees of freedom to.
  return RadiiAgree(t) && !LinesAreBetter(t.circle_sse, t.circle_dof, t.lines_sse, t.lines_dof,
                                          options_.extraction.model_test_probability);
}

EkfSlam::Nearby EkfSlam::PredictNearby(double reach_m) const {
  const Pose2 at = pose();
  Nearby nearby;
  for (int j = 0; j < landmarks(); ++j) {
    RangeBearingPrediction pred = PredictRangeBearing(at, landmark(j));
    if (pred.z(0) > reach_m + options_.extraction.max_radius_m) continue;
    nearby.landmarks.push_back(j);
    nearby.predictions.push_back(pred);
  }
  return nearby;
}

Eigen::Matrix2d EkfSlam::PredictionBlock(const Nearby& nearby, int a, int b) const {
  const int la = LandmarkRow(nearby.landmarks[a]), lb = LandmarkRow(nearby.landmarks[b]);
  const auto& pa = nearby.predictions[a];
  const auto& pb = nearby.predictions[b];
  return pa.d_pose * p_.block<3, 3>(0, 0) * pb.d_pose.transpose() +
         pa.d_pose * p_.block<3, 2>(0, lb) * pb.d_landmark.transpose() +
         pa.d_landmark * p_.block<2, 3>(la, 0) * pb.d_pose.transpose() +
         pa.d_landmark * p_.block<2, 2>(la, lb) * pb.d_landmark.transpose();
}

void EkfSlam::Associate(const std::vector<LandmarkObservation>& observations, const Nearby& nearby,
                        LandmarkUpdate* out) {
  const int m = static_cast<int>(nearby.landmarks.size());
  AssociationProblem problem;
  problem.gate_probability = options_.gate_probability;
  for (const LandmarkObservation& z : observations) {
    problem.observations.emplace_back(z.range_m, z.bearing_rad);
    problem.observation_covariances.push_back(z.covariance);
  }
  for (const RangeBearingPrediction& pred : nearby.predictions) {
    problem.predictions.push_back(pred.z);
  }
  problem.prediction_covariance.resize(2 * m, 2 * m);
  for (int a = 0; a < m; ++a) {
    for (int b = a; b < m; ++b) {
      const Eigen::Matrix2d s = PredictionBlock(nearby, a, b);
      problem.prediction_covariance.block<2, 2>(2 * a, 2 * b) = s;
      problem.prediction_covariance.block<2, 2>(2 * b, 2 * a) = s.transpose();
    }
  }
  const Association association =
      options_.association == LandmarkAssociationMethod::kNearestNeighbour
          ? NearestNeighbour(problem)
          : JointCompatibility(problem);
  for (std::size_t i = 0; i < observations.size(); ++i) {
    const int a = association.landmark_of_observation[i];
    if (a >= 0) out->landmark_of_observation[i] = nearby.landmarks[a];
  }
  Update(observations, out->landmark_of_observation, out);
}

bool EkfSlam::Ambiguous(const LandmarkObservation& obs, const Eigen::Vector2d& z, const Pose2& now,
                        double gate, Nearby* nearby) const {
  const int m = static_cast<int>(nearby->landmarks.size());
  bool ambiguous = false;
  for (int a = 0; a < m && !ambiguous; ++a) {
    const RangeBearingPrediction pred = PredictRangeBearing(now, landmark(nearby->landmarks[a]));
    nearby->predictions[a] = pred;
    const Eigen::Matrix2d s = PredictionBlock(*nearby, a, a) + obs.covariance;
    Eigen::Vector2d v = z - pred.z;
    v(1) = NormalizeAngle(v(1));
    ambiguous = v.dot(s.ldlt().solve(v)) < gate;
  }
  return ambiguous;
}

int EkfSlam::Sight(const LandmarkObservation& obs, const Eigen::Vector2d& z, const Pose2& now) {
  const Eigen::Vector2d position = InverseRangeBearing(now, z).position;
  Tentative* seen = nullptr;
  for (Tentative& t : tentative_) {
    if ((t.position - position).norm() < options_.tentative_radius_m) {
      seen = &t;
      break;
    }
  }
  if (!seen) {
    tentative_.push_back({position, 0, 0, {}, {}, 0.0, 0.0, 0, 0});
    seen = &tentative_.back();
  }
  if (seen->sightings > 0 && seen->last_scan == scans_) return -1;  // once per scan
  ++seen->sightings;
  seen->last_scan = scans_;
  seen->radii.push_back(obs.radius_m);
  seen->radius_variances.push_back(obs.radius_variance_m2);
  seen->circle_sse += obs.circle_sse_m2;
  seen->circle_dof += obs.circle_dof;
  seen->lines_sse += obs.lines.sse_m2;
  seen->lines_dof += obs.lines.dof;
  if (seen->sightings < options_.min_sightings) return -1;
  if (!LooksRound(*seen)) {
    // Not one round object: forget what was seen, so that only sightings from here on count.
    ++inconsistent_tentatives_;
    *seen = {position, 0, scans_, {}, {}, 0.0, 0.0, 0, 0};
    return -1;
  }
  const int id = Augment(z, obs.covariance);
  tentative_.erase(tentative_.begin() + (seen - tentative_.data()));
  return id;
}

LandmarkUpdate EkfSlam::Observe(const std::vector<LandmarkObservation>& observations,
                                double range_max_m) {
  ++scans_;
  const int n_obs = static_cast<int>(observations.size());
  LandmarkUpdate out;
  out.observations = n_obs;
  out.landmark_of_observation.assign(n_obs, -1);
  const double reach = options_.max_range_m > 0.0 ? options_.max_range_m : range_max_m;
  Nearby nearby = PredictNearby(reach);
  if (!nearby.landmarks.empty() && n_obs > 0) Associate(observations, nearby, &out);

  // Unpaired observations: ambiguous near a landmark (after the update), else a sighting of a
  // tentative landmark, which enters the state once seen in min_sightings scans.
  const double new_gate = ChiSquareQuantile(options_.new_landmark_gate_probability, 2.0);
  const Pose2 now = pose();
  for (int i = 0; i < n_obs; ++i) {
    if (out.landmark_of_observation[i] >= 0) continue;
    const LandmarkObservation& obs = observations[i];
    const Eigen::Vector2d z(obs.range_m, obs.bearing_rad);
    if (Ambiguous(obs, z, now, new_gate, &nearby)) {
      ++out.ambiguous;
      continue;
    }
    const int id = Sight(obs, z, now);
    if (id >= 0) {
      out.landmark_of_observation[i] = id;
      ++out.new_landmarks;
    }
  }
  std::erase_if(tentative_, [&](const Tentative& t) {
    return scans_ - t.last_scan >= options_.tentative_max_age_scans;
  });
  return out;
}

}  // namespace slamrig::slam
