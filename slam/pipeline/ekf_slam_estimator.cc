#include "slam/pipeline/ekf_slam_estimator.h"

#include <cmath>

#include "slam/types/validation.h"

namespace slamrig::slam {
namespace {

// As the `ekf` estimator: a run of still encoder intervals is a standstill, and a gyro sample
// beyond chi2_1 at 0.999 of the bias is none.

}  // namespace

std::vector<std::string> EkfSlamEstimatorOptions::Validate() const {
  Rules rules;
  rules.Nested("", filter.Validate())
      .Nested("map", map.Validate())
      .AtLeast("map_every_scans", map_every_scans, 1);
  return rules.errors();
}

EkfSlamEstimator::EkfSlamEstimator(const EkfSlamEstimatorOptions& options,
                                   const EstimatorContext& context)
    : options_(options),
      feed_(context.robot, context.use_gyro, options.filter.motion),
      slam_(options.filter),
      map_(options.map) {}

void EkfSlamEstimator::AddRecord(const Record& record) {
  if (const auto* imu = std::get_if<ImuSample>(&record)) feed_.AddImu(*imu, slam_);
  if (const auto* ticks = std::get_if<WheelTicks>(&record)) feed_.AddTicks(*ticks, slam_);
}

ScanEstimate EkfSlamEstimator::AddScan(const SyncedScan& scan) {
  if (scans_ == 0) {
    slam_.ResetPose(Pose2());
  } else if (!feed_.saw_ticks()) {
    slam_.PredictIncrement(scan.increment, scan.increment.translation().norm(),
                           scan.increment.theta());
  }
  ++scans_;
  const std::vector<LandmarkObservation> observations =
      ExtractLandmarks(scan.scan, options_.filter.extraction);
  const LandmarkUpdate update = slam_.Observe(observations, scan.scan.range_max_m);
  observations_ += update.observations;
  pairings_ += update.pairings;
  ambiguous_ += update.ambiguous;
  if (update.dimension > 0) {
    ++updates_;
    nis_sum_ += update.nis;
    nis_dof_sum_ += update.dimension;
    nis_window_.Add(update.nis, update.dimension);
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
  // Lost: the last updates' NIS sum above its chi-square quantile (NisWindow).
  estimate.trace.push_back({"nis_window_ratio", nis_window_.ratio()});
  estimate.lost = nis_window_.inconsistent();
  health_.Add(*estimate.lost);
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

const std::vector<std::string>& EkfSlamEstimator::StatisticNames() {
  static const std::vector<std::string> names = {"landmarks",
                                                 "tentative_landmarks",
                                                 "inconsistent_tentatives",
                                                 "landmark_observations",
                                                 "landmark_pairings",
                                                 "ambiguous_observations",
                                                 "landmark_updates",
                                                 "zero_rate_updates",
                                                 "gyro_bias_rad_s",
                                                 "mean_nis_per_dof",
                                                 "lost",
                                                 "diverged"};
  return names;
}

std::map<std::string, double> EkfSlamEstimator::Statistics() const {
  return {{"landmarks", slam_.landmarks()},
          {"tentative_landmarks", slam_.tentative_landmarks()},
          {"inconsistent_tentatives", slam_.inconsistent_tentatives()},
          {"landmark_observations", observations_},
          {"landmark_pairings", pairings_},
          {"ambiguous_observations", ambiguous_},
          {"landmark_updates", updates_},
          {"zero_rate_updates", feed_.zero_rate_updates()},
          {"gyro_bias_rad_s", slam_.gyro_bias()},
          {"mean_nis_per_dof", nis_dof_sum_ > 0.0 ? nis_sum_ / nis_dof_sum_ : 0.0},
          {"lost", health_.losses()},
          {"diverged", health_.Diverged() ? 1.0 : 0.0}};
}

}  // namespace slamrig::slam
