// Landmark EKF-SLAM (Smith, Self and Cheeseman, "Estimating uncertain spatial relationships in
// robotics", 1990; the form of Durrant-Whyte and Bailey, "Simultaneous localization and mapping:
// part I", IEEE RAM 2006, Sec. "EKF-SLAM"): one Gaussian over the robot's pose, the gyro's bias
// and scale error, and every mapped landmark's (x, y). The motion model is PoseEkf's (encoders and
// gyro at their own rates); range-bearing observations of round landmarks update it in Joseph
// form; new landmarks augment the state with their cross-covariances. The estimate is known to
// grow overconfident over long runs (Bailey et al., "Consistency of the EKF-SLAM algorithm",
// IROS 2006): the linearisation at the estimate makes the heading look observable when it is not.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "slam/fusion/ekf_slam_options.h"
#include "slam/fusion/landmark_extraction.h"
#include "slam/fusion/pose_ekf.h"
#include "slam/types/pose2.h"

namespace slamrig::slam {

/// The range-bearing observation of a landmark and its Jacobians.
struct RangeBearingPrediction {
  Eigen::Vector2d z = Eigen::Vector2d::Zero();  ///< (range_m, bearing_rad) from base_link
  Eigen::Matrix<double, 2, 3> d_pose = Eigen::Matrix<double, 2, 3>::Zero();  ///< d z / d(x, y, yaw)
  Eigen::Matrix2d d_landmark = Eigen::Matrix2d::Zero();  ///< d z / d(landmark x, y)
};

/// z = (|m - p|, atan2(m - p) - yaw) of landmark `m` seen from `pose`; the landmark must not sit
/// at the pose's position.
RangeBearingPrediction PredictRangeBearing(const Pose2& pose, const Eigen::Vector2d& landmark);

/// The landmark at range-bearing `z` from `pose` and its Jacobians (the inverse observation).
struct LandmarkFromObservation {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  Eigen::Matrix<double, 2, 3> d_pose = Eigen::Matrix<double, 2, 3>::Zero();
  Eigen::Matrix2d d_observation = Eigen::Matrix2d::Zero();
};
LandmarkFromObservation InverseRangeBearing(const Pose2& pose, const Eigen::Vector2d& z);

/// What one scan's landmark update did.
struct LandmarkUpdate {
  int observations = 0;
  int pairings = 0;       ///< observations that updated a landmark
  int new_landmarks = 0;  ///< landmarks added to the state
  int ambiguous = 0;      ///< unpaired but too close to a landmark to start one
  double nis = 0.0;       ///< of the stacked update (0 without pairings)
  int dimension = 0;      ///< its chi-square degrees of freedom (2 per pairing)
  /// For each observation (input order): the landmark index it updated or started, else -1.
  std::vector<int> landmark_of_observation;
};

/// The filter. State (5 + 2n): pose x, y, yaw; gyro bias (rad/s); gyro scale error; then each
/// landmark's x, y. Poses and landmarks in one fixed frame. Deterministic; not thread-safe.
class EkfSlam {
 public:
  explicit EkfSlam(const EkfSlamOptions& options);

  /// Sets the pose to `pose` with zero covariance; bias, scale and landmarks (if any) stay.
  void ResetPose(const Pose2& pose);
  /// PoseEkf's motion model (see there), the landmarks' cross-covariances carried along.
  void PredictGyro(double rate_rad_s, double dt_s);
  void PredictWheels(double right_m, double left_m, double track_width_m,
                     std::optional<double> gyro_yaw_rad, double slip_m2 = 0.0);
  void PredictIncrement(const Pose2& increment, double distance_m, double turn_rad);
  /// A gyro sample at standstill measures the bias (b = rate), over the whole state.
  double UpdateZeroRate(double rate_rad_s);
  /// Pairs `observations` (base_link range-bearing) with the mapped landmarks, updates with the
  /// pairs, and admits the unpaired ones that have been seen often enough. `range_max_m`: the
  /// sensor's, for which landmarks are candidates when max_range_m is 0.
  LandmarkUpdate Observe(const std::vector<LandmarkObservation>& observations, double range_max_m);

  Pose2 pose() const { return {x_(0), x_(1), x_(2)}; }
  Eigen::Matrix3d PoseCovariance() const { return p_.topLeftCorner<3, 3>(); }
  double gyro_bias() const { return x_(3); }
  double gyro_bias_variance() const { return p_(3, 3); }
  double gyro_scale_error() const { return x_(4); }
  int landmarks() const { return static_cast<int>((x_.size() - kPoseDim) / 2); }
  Eigen::Vector2d landmark(int i) const { return x_.segment<2>(kPoseDim + 2 * i); }
  Eigen::Matrix2d landmark_covariance(int i) const {
    return p_.block<2, 2>(kPoseDim + 2 * i, kPoseDim + 2 * i);
  }
  int tentative_landmarks() const { return static_cast<int>(tentative_.size()); }
  /// Tentative landmarks dropped at admission because their sightings' radii disagreed or lines
  /// fitted them better than circles.
  int inconsistent_tentatives() const { return inconsistent_tentatives_; }
  const Eigen::VectorXd& state() const { return x_; }
  const Eigen::MatrixXd& covariance() const { return p_; }

  /// Adds the landmark at `z` (covariance `r`) from the current pose to the state:
  /// m = g(pose, z), P_mm = G_p P_pp G_p^T + G_z R G_z^T, P_m* = G_p P_p*. Returns its index.
  int Augment(const Eigen::Vector2d& z, const Eigen::Matrix2d& r);

  static constexpr int kPoseDim = 5;

 private:
  struct Tentative {
    Eigen::Vector2d position = Eigen::Vector2d::Zero();  ///< of the first sighting
    int sightings = 0;
    int last_scan = 0;
    /// Each sighting's fitted radius and its variance.
    std::vector<double> radii;
    std::vector<double> radius_variances;
    /// The sightings' circle and line-model residuals, pooled.
    double circle_sse = 0.0, lines_sse = 0.0;
    int circle_dof = 0, lines_dof = 0;
  };

  /// Runs one motion step through PoseEkf: the pose, bias and scale and their covariance from
  /// one copy of it, and the step's Jacobian F from two probes whose clones (static under
  /// motion) are correlated with the pose or with the gyro states, so that their cross-covariance
  /// after the step is F's columns. The landmarks' cross-covariances become F P_pl.
  template <typename Step>
  void Predict(const Step& step);
  /// Stacked Kalman update of the pairs (observation i, landmark j), Joseph form.
  void Update(const std::vector<LandmarkObservation>& observations,
              const std::vector<int>& landmark_of_observation, LandmarkUpdate* out);

  /// The landmarks within `reach_m` of the pose, with their predicted observations.
  struct Nearby {
    std::vector<int> landmarks;
    std::vector<RangeBearingPrediction> predictions;
  };
  Nearby PredictNearby(double reach_m) const;
  /// The 2 x 2 block (a, b) of H P H^T for nearby landmarks a and b (H is sparse: the pose and
  /// one landmark per row pair).
  Eigen::Matrix2d PredictionBlock(const Nearby& nearby, int a, int b) const;
  /// Pairs the observations with nearby landmarks (the association method) and updates the
  /// state with the pairs.
  void Associate(const std::vector<LandmarkObservation>& observations, const Nearby& nearby,
                 LandmarkUpdate* out);
  /// Whether an unpaired observation `z` falls within the new-landmark gate of a nearby
  /// landmark, predicted again from `now` (after the update).
  bool Ambiguous(const LandmarkObservation& obs, const Eigen::Vector2d& z, const Pose2& now,
                 double gate, Nearby* nearby) const;
  /// Counts a sighting of the tentative landmark at `z` seen from `now`; the index of the
  /// landmark it becomes in the state, or -1.
  int Sight(const LandmarkObservation& obs, const Eigen::Vector2d& z, const Pose2& now);

  /// Whether the sightings' fitted radii are consistent with one radius.
  bool RadiiAgree(const Tentative& t) const;
  /// Whether the sightings, pooled, look round: their radii agree, and lines fit them no better.
  bool LooksRound(const Tentative& t) const;

  EkfSlamOptions options_;
  Eigen::VectorXd x_;
  Eigen::MatrixXd p_;
  PoseEkf motion_;
  PoseEkf probe_pose_;
  PoseEkf probe_gyro_;
  std::vector<Tentative> tentative_;
  int scans_ = 0;
  int inconsistent_tentatives_ = 0;
};

}  // namespace slamrig::slam
