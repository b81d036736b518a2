#include "slam/pipeline/ekf_estimator.h"

#include <algorithm>
#include <cmath>

#include "slam/matching/map_frame_drift.h"
#include "slam/types/validation.h"

namespace slamrig::slam {
namespace {

// The step of the match covariance's adaptation: log(factor) += gain * (NIS / dim - 1). Small
// enough that one update moves it little (the NIS of one update is chi-square, its spread as
// large as its mean), large enough to settle within a few dozen keyframes.
constexpr double kMatchScaleGain = 0.05;
// Bounds of the estimate: a run of near-zero innovations (a robot at rest before a wall) must not
// drive it to where a change of the lidar takes hundreds of updates to undo.
constexpr double kMinMatchScale = 0.1;
constexpr double kMaxMatchScale = 1e3;

// The filter's options with the source's gyro model where it has one and the options ask for it.
EkfOptions WithRobotGyro(EkfOptions options, const EstimatorContext& context) {
  if (options.gyro_noise_from_robot && context.gyro && context.gyro->rate_hz > 0.0) {
    options.filter.gyro_sigma_rad_s =
        context.gyro->noise_density_rad_s_sqrt_hz * std::sqrt(context.gyro->rate_hz);
    options.filter.gyro_bias_walk_rad_s_sqrt_s = context.gyro->random_walk_rad_s2_sqrt_hz;
  }
  return options;
}

}  // namespace

std::vector<std::string> EkfOptions::Validate() const {
  Rules rules;
  rules.Nested("", filter.Validate())
      .Positive("match_covariance_scale", match_covariance_scale)
      .NonNegative("match_sigma_floor_xy_m", match_sigma_floor_xy_m)
      .NonNegative("match_sigma_floor_yaw_rad", match_sigma_floor_yaw_rad)
      .NonNegative("increment_sigma_floor_xy_m", increment_sigma_floor_xy_m)
      .NonNegative("increment_sigma_floor_yaw_rad", increment_sigma_floor_yaw_rad)
      .NonNegative("map_drift_share", map_drift_share)
      .NonNegative("slip_gate", slip_gate)
      .Nested("map", map.Validate());
  return rules.errors();
}

EkfEstimator::EkfEstimator(const EkfOptions& options, const EstimatorContext& context)
    : options_(WithRobotGyro(options, context)),
      feed_(context.robot, context.use_gyro, options_.filter),
      ekf_(options_.filter),
      icp_(IcpOdometryOptions{}),
      map_(options.map) {}

void EkfEstimator::AddRecord(const Record& record) {
  const auto* ticks = std::get_if<WheelTicks>(&record);
  last_record_was_ticks_ = ticks != nullptr;
  if (const auto* imu = std::get_if<ImuSample>(&record)) feed_.AddImu(*imu, ekf_);
  if (ticks) feed_.AddTicks(*ticks, ekf_);
}

std::optional<ScanEstimate> EkfEstimator::RecordEstimate() const {
  if (!last_record_was_ticks_) return std::nullopt;
  ScanEstimate estimate;
  estimate.pose = ekf_.pose();
  estimate.covariance = ekf_.PoseCovariance();
  return estimate;
}

ScanEstimate EkfEstimator::AddScan(const SyncedScan& scan) {
  if (scans_ > 0 && !feed_.saw_ticks()) {
    const double distance = scan.increment.translation().norm();
    ekf_.PredictIncrement(scan.increment, distance, scan.increment.theta());
  }
  return Correct(scan.scan);
}

double EkfEstimator::MatchScale() const {
  // The estimate moves both ways (held at >= 1 it would drift upward, the NIS's spread reflected
  // there); the factor applied only ever inflates the Hessian's covariance, a lower bound on the
  // match's spread.
  return std::max(1.0, std::exp(log_match_scale_));
}

ScanEstimate EkfEstimator::Correct(const LaserScan& scan) {
  const bool first = scans_ == 0;
  ++scans_;
  if (first) ekf_.ResetPose(Pose2());
  ScanEstimate estimate;
  if (options_.scan_matching) {
    const Pose2 prior = previous_pose_.Between(ekf_.pose());
    const IcpOdometryStep step = icp_.Add(scan, prior);
    // The derived drift needs the matcher's shares (point-to-line ICP).
    const bool derived_drift = options_.derived_map_drift && !step.frame_weights.empty();
    const bool joins = feed_.saw_ticks() && (first || step.keyframe);
    // The frame this keyframe's match sees moved since the last keyframe's saw it.
    const Eigen::Matrix3d seen_drift =
        derived_drift && joins && !first
            ? keyframe_errors_.See(step.frame_weights, step.pose.translation())
            : Eigen::Matrix3d::Zero().eval();
    const bool usable =
        step.outcome == IcpOdometryOutcome::kMatched ||
        (options_.update_on_degenerate && step.outcome == IcpOdometryOutcome::kDegenerate);
    // The match's covariance of its pose in the matcher's frame, scaled and floored.
    Eigen::Matrix3d r = options_.match_covariance_scale * step.covariance;
    r(0, 0) += options_.match_sigma_floor_xy_m * options_.match_sigma_floor_xy_m;
    r(1, 1) += options_.match_sigma_floor_xy_m * options_.match_sigma_floor_xy_m;
    r(2, 2) += options_.match_sigma_floor_yaw_rad * options_.match_sigma_floor_yaw_rad;
    r *= MatchScale();
    if (!first && !feed_.saw_ticks()) {
      // Odometry-pose increments (no encoders): keyframe-to-keyframe increments through the
      // clone, as before the matcher's frame. On the corrected CARMEN logs the frame model made
      // intel (1.9 -> 10.9 m), belgioioso (2.6 -> 6.3 m) and edmonton (0.72 -> 1.5 m) worse,
      // which is not understood yet.
      if (usable && (step.keyframe || !options_.keyframe_updates)) {
        // The increment's covariance (the previous keyframe's pose held fixed) in that
        // keyframe's frame, floored.
        Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
        const double c = std::cos(icp_keyframe_.theta()), s = std::sin(icp_keyframe_.theta());
        rotation.topLeftCorner<2, 2>() << c, s, -s, c;
        Eigen::Matrix3d increment =
            options_.match_covariance_scale * rotation * step.covariance * rotation.transpose();
        const double xy = options_.increment_sigma_floor_xy_m;
        const double yaw = options_.increment_sigma_floor_yaw_rad;
        increment(0, 0) += xy * xy;
        increment(1, 1) += xy * xy;
        increment(2, 2) += yaw * yaw;
        const EkfUpdate update = ekf_.UpdateRelativePose(
            icp_keyframe_.Between(step.pose), increment,
            options_.slip_gate > 0.0 ? std::optional<double>(options_.slip_gate) : std::nullopt);
        if (update.inflation > 1.0) ++slip_inflations_;
        nis_sum_ += update.nis;
        ++scan_updates_;
        last_nis_ = update.nis;
        nis_window_.Add(update.nis, update.dimension);
      }
      if (step.keyframe) {
        ++keyframes_;
        icp_keyframe_ = step.pose;
        ekf_.Clone();
      }
    } else if (first) {
      // Both frames start at the first scan's pose.
      ekf_.AnchorMatcherFrame(step.pose, Eigen::Matrix3d::Zero());
      anchored_ = true;
      icp_keyframe_ = step.pose;
      if (!feed_.saw_ticks()) {
        ++keyframes_;
        ekf_.Clone();
      }
    } else if (usable && (step.keyframe || !options_.keyframe_updates)) {
      if (anchored_ && derived_drift && joins) ekf_.DriftMatcherFrame(seen_drift);
      if (anchored_) {
        const EkfUpdate update = ekf_.UpdateMatcherPose(
            step.pose, r,
            options_.slip_gate > 0.0 ? std::optional<double>(options_.slip_gate) : std::nullopt);
        if (update.inflation > 1.0) ++slip_inflations_;
        if (options_.adaptive_match_covariance && update.inflation == 1.0) {
          log_match_scale_ =
              std::clamp(log_match_scale_ + kMatchScaleGain * (update.nis / update.dimension - 1.0),
                         std::log(kMinMatchScale), std::log(kMaxMatchScale));
        }
        nis_sum_ += update.nis;
        ++scan_updates_;
        last_nis_ = update.nis;
        nis_window_.Add(update.nis, update.dimension);
      } else {
        ekf_.AnchorMatcherFrame(step.pose, r);
        anchored_ = true;
        ++anchors_;
      }
    }
    if (joins) {
      ++keyframes_;
      // The first keyframe is the frame itself; every other joins with its match's error.
      if (derived_drift) {
        keyframe_errors_.Join(step.keyframe_id, first ? Eigen::Matrix3d::Zero() : r,
                              step.pose.translation());
      }
      if (!first && !usable) {
        // The keyframe joins the map where the prior put it, along its weak direction at least.
        anchored_ = false;
      } else if (!first && !derived_drift) {
        ekf_.DriftMatcherFrame(options_.map_drift_share * options_.map_drift_share * r);
      }
      ekf_.Clone();
    }
  } else {
    ekf_.Clone();
  }
  previous_pose_ = ekf_.pose();
  estimate.pose = ekf_.pose();
  estimate.covariance = ekf_.PoseCovariance();
  // Every trace has a value at every scan (the report plots them against the scan times): the
  // NIS is the latest update's, held between keyframes.
  estimate.trace.push_back({"nis", last_nis_});
  estimate.trace.push_back({"gyro_bias_rad_s", ekf_.gyro_bias()});
  // Lost: the last scan updates' NIS sum above its chi-square quantile (NisWindow).
  estimate.trace.push_back({"nis_window_ratio", nis_window_.ratio()});
  estimate.lost = nis_window_.inconsistent();
  health_.Add(*estimate.lost);
  map_.InsertScan(scan, estimate.pose);
  return estimate;
}

const std::vector<std::string>& EkfEstimator::StatisticNames() {
  static const std::vector<std::string> names = {"gyro_bias_rad_s",   "gyro_scale_error",
                                                 "gyro_sigma_rad_s",  "scan_updates",
                                                 "zero_rate_updates", "slip_inflations",
                                                 "matched",           "keyframes",
                                                 "anchors",           "match_covariance_factor",
                                                 "wheel_slip_m",      "skid_ratio",
                                                 "mean_nis",          "lost",
                                                 "diverged"};
  return names;
}

std::map<std::string, double> EkfEstimator::Statistics() const {
  return {{"gyro_bias_rad_s", ekf_.gyro_bias()},
          {"gyro_scale_error", ekf_.gyro_scale_error()},
          {"gyro_sigma_rad_s", options_.filter.gyro_sigma_rad_s},
          {"scan_updates", scan_updates_},
          {"zero_rate_updates", feed_.zero_rate_updates()},
          {"slip_inflations", slip_inflations_},
          {"matched", icp_.counts().matched},
          {"keyframes", keyframes_},
          {"anchors", anchors_},
          {"match_covariance_factor", MatchScale()},
          {"wheel_slip_m", feed_.slip().total_slip_m()},
          {"skid_ratio", feed_.slip().skid_ratio()},
          {"mean_nis", scan_updates_ > 0 ? nis_sum_ / scan_updates_ : 0.0},
          {"lost", health_.losses()},
          {"diverged", health_.Diverged() ? 1.0 : 0.0}};
}

}  // namespace slamrig::slam
