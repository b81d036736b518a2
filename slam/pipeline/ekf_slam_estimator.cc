#include "slam/pipeline/ekf_slam_estimator.h"

#include <cmath>
#include <numeric>

#include "slam/types/validation.h"

namespace slamrig::slam {
namespace {

// As the `ekf` estimator: a run of still encoder intervals is a standstill, and a gyro sample
// beyond chi2_1 at 0.999 of the bias is none.
constexpr int kStillIntervals = 10;
constexpr double kZeroRateGate = 10.83;

double MeanTicks(const std::vector<std::int32_t>& ticks) {
  if (ticks.empty()) return 0.0;
  return std::accumulate(ticks.begin(), ticks.end(), 0.0) / static_cast<double>(ticks.size());
}

}  // namespace

std::vector<std::string> EkfSlamEstimatorOptions::Validate() const {
  std::vector<std::string> errors = filter.Validate();
  AppendErrors(&errors, PrefixErrors("map", map.Validate()));
  if (map_every_scans < 1)
    errors.push_back(RuleViolation("map_every_scans", map_every_scans, "must be >= 1"));
  return errors;
}

EkfSlamEstimator::EkfSlamEstimator(const EkfSlamEstimatorOptions& options,
                                   const EstimatorContext& context)
    : options_(options),
      robot_(context.robot),
      use_gyro_(context.use_gyro),
      slam_(options.filter),
      map_(options.map) {}

void EkfSlamEstimator::AddRecord(const Record& record) {
  if (const auto* imu = std::get_if<ImuSample>(&record)) AddImu(*imu);
  if (const auto* ticks = std::get_if<WheelTicks>(&record)) AddTicks(*ticks);
}

void EkfSlamEstimator::AddImu(const ImuSample& imu) {
  if (!use_gyro_) return;
  const double rate = imu.angular_velocity_rad_s.z();
  if (!std::isfinite(rate)) return;
  // Each sample is held from the previous one (zero-order hold).
  if (last_imu_time_) {
    const double dt = SecondsBetween(imu.time, *last_imu_time_);
    if (dt > 0.0) {
      gyro_yaw_since_ticks_ += (rate - slam_.gyro_bias()) * dt;
      slam_.PredictGyro(rate, dt);
      gyro_since_ticks_ = true;
    }
  }
  last_imu_time_ = imu.time;
  if (still_intervals_ >= kStillIntervals && options_.filter.motion.zero_rate_updates) {
    const double innovation = rate - slam_.gyro_bias();
    const double sigma = options_.filter.motion.gyro_sigma_rad_s;
    const double variance = slam_.covariance()(3, 3) + sigma * sigma;
    if (innovation * innovation < kZeroRateGate * variance) {
      slam_.UpdateZeroRate(rate);
      ++zero_rate_updates_;
    }
  }
}

void EkfSlamEstimator::AddTicks(const WheelTicks& ticks) {
  const double metres_per_tick = robot_.MetresPerTick();
  const double right_m = MeanTicks(ticks.right_ticks) * metres_per_tick;
  const double left_m = MeanTicks(ticks.left_ticks) * metres_per_tick;
  slam_.PredictWheels(
      right_m, left_m, robot_.track_width_m,
      gyro_since_ticks_ ? std::optional<double>(gyro_yaw_since_ticks_) : std::nullopt);
  still_intervals_ = right_m == 0.0 && left_m == 0.0 ? still_intervals_ + 1 : 0;
  saw_ticks_ = true;
  gyro_since_ticks_ = false;
  gyro_yaw_since_ticks_ = 0.0;
}

ScanEstimate EkfSlamEstimator::AddScan(const SyncedScan& scan) {
  if (scans_ == 0) {
    slam_.ResetPose(Pose2());
  } else if (!saw_ticks_) {
    slam_.PredictIncrement(scan.increment, scan.increment.translation().norm(),
                           scan.increment.theta());
  }
  ++scans_;
  // The robot's velocity over the last scan interval (the odometry's), to undo the sweep's motion.
  BaseVelocity velocity;
  if (previous_scan_time_) {
    const double dt = SecondsBetween(scan.scan.time, *previous_scan_time_);
    if (dt > 0.0) {
      velocity.forward_m_s = scan.increment.x() / dt;
      velocity.yaw_rate_rad_s = scan.increment.theta() / dt;
    }
  }
  previous_scan_time_ = scan.scan.time;
  const std::vector<LandmarkObservation> observations =
      ExtractLandmarks(scan.scan, options_.filter.extraction, velocity);
  const LandmarkUpdate update = slam_.Observe(observations, scan.scan.range_max_m);
  observations_ += update.observations;
  pairings_ += update.pairings;
  ambiguous_ += update.ambiguous;
  if (update.dimension > 0) {
    ++updates_;
    nis_sum_ += update.nis;
    nis_dof_sum_ += update.dimension;
  }
  for (std::size_t i = 0; i < observations.size(); ++i) {
    if (update.landmark_of_observation[i] < 0) continue;
    sightings_.push_back(
        {scan.scan.time, update.landmark_of_observation[i], observations[i].center_m});
  }
  ScanEstimate estimate;
  estimate.pose = slam_.pose();
  estimate.covariance = slam_.PoseCovariance();
  // The NIS over its degrees of freedom (1 when consistent), so that scans with different
  // numbers of pairings share one plot.
  estimate.trace.push_back(
      {"nis_per_dof", update.dimension > 0 ? update.nis / update.dimension : 0.0});
  estimate.trace.push_back({"landmarks", static_cast<double>(slam_.landmarks())});
  estimate.trace.push_back({"pairings", static_cast<double>(update.pairings)});
  if ((scans_ - 1) % options_.map_every_scans == 0) map_.InsertScan(scan.scan, estimate.pose);
  return estimate;
}

std::vector<LandmarkEstimate> EkfSlamEstimator::CurrentLandmarks() const {
  std::vector<LandmarkEstimate> out;
  for (int i = 0; i < slam_.landmarks(); ++i)
    out.push_back({slam_.landmark(i), slam_.landmark_covariance(i)});
  return out;
}

LandmarkMap EkfSlamEstimator::Landmarks() const { return {CurrentLandmarks(), sightings_}; }

EstimatorView EkfSlamEstimator::View() const {
  EstimatorView view;
  view.landmarks = CurrentLandmarks();
  view.pose_covariance = slam_.PoseCovariance();
  return view;
}

std::map<std::string, double> EkfSlamEstimator::Statistics() const {
  return {{"landmarks", slam_.landmarks()},
          {"tentative_landmarks", slam_.tentative_landmarks()},
          {"landmark_observations", observations_},
          {"landmark_pairings", pairings_},
          {"ambiguous_observations", ambiguous_},
          {"landmark_updates", updates_},
          {"zero_rate_updates", zero_rate_updates_},
          {"gyro_bias_rad_s", slam_.gyro_bias()},
          {"mean_nis_per_dof", nis_dof_sum_ > 0.0 ? nis_sum_ / nis_dof_sum_ : 0.0}};
}

}  // namespace slamrig::slam
