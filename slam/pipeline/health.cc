#include "slam/pipeline/health.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "slam/eval/chi_square.h"
#include "slam/types/check.h"

namespace slamrig::slam {

QualityRatio::QualityRatio(double fast_rate, double slow_rate, int warmup, double hold_below)
    : fast_rate_(fast_rate), slow_rate_(slow_rate), warmup_(warmup), hold_below_(hold_below) {
  SLAMRIG_CHECK(0.0 < slow_rate && slow_rate < fast_rate && fast_rate <= 1.0 && warmup >= 1,
                "QualityRatio: needs 0 < slow_rate < fast_rate <= 1 and warmup >= 1");
}

double QualityRatio::Add(double quality) {
  // The first sample starts both averages; later ones move each by its own rate.
  if (samples_ == 0) {
    fast_ = slow_ = quality;
  } else {
    fast_ += fast_rate_ * (quality - fast_);
    if (!(warm() && quality < hold_below_ * slow_)) slow_ += slow_rate_ * (quality - slow_);
  }
  ++samples_;
  return ratio();
}

double QualityRatio::ratio() const {
  if (!warm() || !(slow_ > 0.0)) return 1.0;
  return fast_ / slow_;
}

void NisWindow::Add(double nis, int dimension) {
  SLAMRIG_CHECK(dimension > 0, "NisWindow::Add: dimension must be > 0");
  window_.emplace_back(nis, dimension);
  nis_sum_ += nis;
  dimension_sum_ += dimension;
  if (static_cast<int>(window_.size()) > kUpdates) {
    nis_sum_ -= window_.front().first;
    dimension_sum_ -= window_.front().second;
    window_.pop_front();
  }
}

double NisWindow::ratio() const {
  if (window_.empty()) return 0.0;
  return nis_sum_ / ChiSquareQuantile(kProbability, dimension_sum_);
}

double Observability(const MatchConstraints& geometry, const Eigen::Vector2d& direction) {
  const double norm = direction.norm();
  const double strongest = geometry.eigenvalues.y();
  if (!(norm > 0.0) || !(strongest > 0.0)) return 0.0;
  const Eigen::Vector2d along = geometry.eigenvectors.transpose() * (direction / norm);
  const double information = along.x() * along.x() * geometry.eigenvalues.x() +
                             along.y() * along.y() * geometry.eigenvalues.y();
  return std::clamp(information / strongest, 0.0, 1.0);
}

bool WheelAgreement::Add(const Pose2& estimate_increment, const Pose2& wheel_increment,
                         double observability, double wheel_yaw_sigma_rad) {
  const Eigen::Vector2d wheels = wheel_increment.translation();
  const double wheels_m = wheels.norm();
  const bool turned = AddTurn({wheels_m, wheel_increment.theta(), estimate_increment.theta(),
                               wheel_yaw_sigma_rad * wheel_yaw_sigma_rad});
  if (observability >= kObservable) return turned;
  // The estimate's own motion along the wheels' direction.
  const double estimate_m =
      wheels_m > 0.0 ? estimate_increment.translation().dot(wheels / wheels_m) : 0.0;
  window_.push_back({wheels_m, estimate_m, false});
  wheels_m_ += wheels_m;
  estimate_m_ += estimate_m;
  // The window: the fewest latest scans that still cover kWindowM of wheel travel.
  while (window_.size() > 1 && wheels_m_ - window_.front().wheels_m >= kWindowM) {
    wheels_m_ -= window_.front().wheels_m;
    estimate_m_ -= window_.front().estimate_m;
    window_.pop_front();
  }
  const bool flagged = std::abs(ratio() - 1.0) > kTolerance;
  if (!flagged) {
    CloseStretch();
    return turned;
  }
  // The stretch's displacement: every scan of the window not yet counted (the first flag's whole
  // window, then each new scan).
  if (in_stretch_) stretch_travel_m_ += wheels_m;
  in_stretch_ = true;
  for (Step& step : window_) {
    if (step.counted) continue;
    stretch_m_ += step.estimate_m - step.wheels_m;
    step.counted = true;
  }
  return true;
}

bool WheelAgreement::AddTurn(const Turn& turn) {
  turns_.Add(turn);
  long_turns_.Add(turn);
  drift_.Travel(turn.wheels_m);
  const double drift = drift_.rad_per_m();
  bool flagged = false;
  for (const TurnWindow* window : {&turns_, &long_turns_}) {
    if (!window->Contradicted(drift)) continue;
    flagged = true;
    heading_contradicted_rad_ =
        std::max(heading_contradicted_rad_, std::abs(window->net_difference_rad(drift)));
  }
  if (!flagged && turns_.travel_m() >= kHeadingWindowM) {
    drift_.Add(turns_.difference_rad() / turns_.travel_m());
  }
  return flagged;
}

void WheelAgreement::DriftEstimate::Add(double rad_per_m) {
  const double unit = (rad_per_m + kDriftRangeRadPerM) / (2.0 * kDriftRangeRadPerM);
  const int bin =
      std::clamp(static_cast<int>(std::lround(unit * (kDriftBins - 1))), 0, kDriftBins - 1);
  ++counts_[static_cast<std::size_t>(bin)];
  ++total_;
}

double WheelAgreement::DriftEstimate::rad_per_m() const {
  if (travel_m_ < kDriftHistoryM || total_ == 0) return 0.0;
  int below = 0;
  for (int bin = 0; bin < kDriftBins; ++bin) {
    below += counts_[static_cast<std::size_t>(bin)];
    if (2 * below >= total_) {
      return -kDriftRangeRadPerM + 2.0 * kDriftRangeRadPerM * bin / (kDriftBins - 1);
    }
  }
  return 0.0;
}

double WheelAgreement::turn_difference_rad() const {
  return turns_.net_difference_rad(drift_.rad_per_m());
}

void WheelAgreement::TurnWindow::Add(const Turn& turn) {
  turns_.push_back(turn);
  travel_m_ += turn.wheels_m;
  wheels_rad_ += turn.wheels_rad;
  wheels_abs_rad_ += std::abs(turn.wheels_rad);
  estimate_rad_ += turn.estimate_rad;
  wheels_variance_rad2_ += turn.wheels_variance_rad2;
  while (turns_.size() > 1 && travel_m_ - turns_.front().wheels_m >= length_m_) {
    const Turn& old = turns_.front();
    travel_m_ -= old.wheels_m;
    wheels_rad_ -= old.wheels_rad;
    wheels_abs_rad_ -= std::abs(old.wheels_rad);
    estimate_rad_ -= old.estimate_rad;
    wheels_variance_rad2_ -= old.wheels_variance_rad2;
    turns_.pop_front();
  }
}

void WheelAgreement::TurnWindow::Clear() {
  turns_.clear();
  travel_m_ = wheels_rad_ = wheels_abs_rad_ = estimate_rad_ = wheels_variance_rad2_ = 0.0;
}

double WheelAgreement::TurnWindow::difference_rad() const {
  return travel_m_ >= kHeadingWindowM ? estimate_rad_ - wheels_rad_ : 0.0;
}

double WheelAgreement::TurnWindow::net_difference_rad(double drift_rad_per_m) const {
  return travel_m_ >= kHeadingWindowM ? difference_rad() - drift_rad_per_m * travel_m_ : 0.0;
}

// A window that is not full has no net difference, so it is never contradicted.
bool WheelAgreement::TurnWindow::Contradicted(double drift_rad_per_m) const {
  const double noise_rad = kHeadingNoiseSigmas * std::sqrt(std::max(wheels_variance_rad2_, 0.0));
  return std::abs(net_difference_rad(drift_rad_per_m)) >
         std::max(kHeadingToleranceRad + kHeadingSkidShare * wheels_abs_rad_, noise_rad);
}

void WheelAgreement::CloseStretch() {
  contradicted_m_ += Persistent() ? std::abs(stretch_m_) : 0.0;
  stretch_m_ = stretch_travel_m_ = 0.0;
  in_stretch_ = false;
}

void WheelAgreement::Reset() {
  CloseStretch();
  window_.clear();
  wheels_m_ = estimate_m_ = 0.0;
  turns_.Clear();
  long_turns_.Clear();
}

double WheelAgreement::ratio() const {
  return wheels_m_ >= kWindowM ? estimate_m_ / wheels_m_ : 1.0;
}

WheelCheck::WheelCheck(bool enabled, const ScanPointsOptions& points)
    : enabled_(enabled), points_(points) {}

bool WheelCheck::Judge(const LaserScan& scan, const Pose2& wheel_increment,
                       const Pose2& estimate_increment, bool updated) {
  if (!enabled_) return false;
  if (updated || !geometry_seen_) {
    geometry_ = ScanGeometry(ScanToBasePoints(scan, points_));
    geometry_seen_ = true;
  }
  // How well the scan sees motion along the wheels' direction: only poorly observed motion is
  // judged against the wheels.
  observability_ = Observability(geometry_, wheel_increment.translation());
  return agreement_.Add(estimate_increment, wheel_increment, observability_);
}

void WheelCheck::AppendTrace(std::vector<TraceValue>* trace) const {
  trace->push_back({"wheel_distance_ratio", agreement_.ratio()});
  trace->push_back({"wheel_turn_difference_rad", agreement_.turn_difference_rad()});
  trace->push_back({"motion_observability", observability_});
}

void WheelCheck::AppendStatistics(std::map<std::string, double>* statistics) const {
  (*statistics)["wheel_contradiction_m"] = agreement_.contradicted_m();
  (*statistics)["wheel_heading_contradiction_rad"] = agreement_.heading_contradicted_rad();
}

std::vector<std::string> WheelCheck::WithStatisticNames(std::vector<std::string> names) {
  names.push_back("wheel_contradiction_m");
  names.push_back("wheel_heading_contradiction_rad");
  return names;
}

bool WheelCheck::Diverged() const {
  return agreement_.contradicted_m() > kDivergedErrorM ||
         agreement_.heading_contradicted_rad() > 0.0;
}

void BlindStretchBound::Start() {
  covariance_.setZero();
  heading_ = 0.0;
}

void BlindStretchBound::Add(const Pose2& increment, const Eigen::Vector2d& sigmas) {
  const double c = std::cos(heading_), s = std::sin(heading_);
  const double ux = increment.x(), uy = increment.y();
  Eigen::Matrix3d by_pose = Eigen::Matrix3d::Identity();
  by_pose(0, 2) = -(s * ux + c * uy);
  by_pose(1, 2) = c * ux - s * uy;
  Eigen::Matrix3d by_increment = Eigen::Matrix3d::Identity();
  by_increment.topLeftCorner<2, 2>() << c, -s, s, c;
  const Eigen::Vector3d variances(sigmas.x() * sigmas.x(), sigmas.x() * sigmas.x(),
                                  sigmas.y() * sigmas.y());
  covariance_ = by_pose * covariance_ * by_pose.transpose() +
                by_increment * variances.asDiagonal() * by_increment.transpose();
  heading_ += increment.theta();
}

double BlindStretchBound::bound_m() const {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(covariance_.topLeftCorner<2, 2>());
  return std::sqrt(ChiSquareQuantile(0.99, 2) * std::max(eig.eigenvalues()[1], 0.0));
}

void WallCrossings::Add(const std::vector<Eigen::Vector2d>& crossed) {
  std::vector<std::pair<int, int>> squares;
  squares.reserve(crossed.size());
  for (const Eigen::Vector2d& p : crossed) {
    squares.emplace_back(static_cast<int>(std::floor(p.x() / kBinM)),
                         static_cast<int>(std::floor(p.y() / kBinM)));
  }
  std::sort(squares.begin(), squares.end());
  squares.erase(std::unique(squares.begin(), squares.end()), squares.end());
  for (const auto& square : squares) ++counts_[square];
  window_.push_back(std::move(squares));
  if (static_cast<int>(window_.size()) > kUpdates) {
    for (const auto& square : window_.front()) {
      const auto it = counts_.find(square);
      if (--it->second == 0) counts_.erase(it);
    }
    window_.pop_front();
  }
  worst_m_ = std::max(worst_m_, extent_m());
}

void HealthRecord::Add(bool lost) {
  if (lost) {
    ++lost_scans_;
    if (!lost_at_end()) loss_scans_.emplace_back(scans_, scans_);
    loss_scans_.back().second = scans_;
  }
  ++scans_;
}

bool HealthRecord::Diverged() const {
  return lost_at_end() || static_cast<double>(lost_scans_) > kDivergedLostShare * scans_;
}

FrontEndHealth::FrontEndHealth() : score_ratio_(0.3, 0.02, 10, kLostRatio) {}

bool FrontEndHealth::Judge(const IcpOdometryStep& step, std::vector<TraceValue>* trace) {
  const bool matched = step.outcome == IcpOdometryOutcome::kMatched ||
                       step.outcome == IcpOdometryOutcome::kDegenerate;
  const bool first = step.outcome == IcpOdometryOutcome::kFirstScan;
  // Degeneracy: the smallest over the largest eigenvalue of the match's translation covariance
  // (of the ICP Hessian's inverse): 1 for a match constrained alike in every direction, near 0
  // along a corridor; 0 without a match.
  double conditioning = 0.0;
  if (matched) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(step.covariance.topLeftCorner<2, 2>());
    conditioning = eig.eigenvalues()[1] > 0.0 ? eig.eigenvalues()[0] / eig.eigenvalues()[1] : 0.0;
  }
  const double ratio = first ? 1.0 : score_ratio_.Add(matched ? step.score : 0.0);
  // The correction of the prior in units of its search window (+-sigmas of the measured noise).
  const Eigen::Vector2d correction =
      first ? Eigen::Vector2d::Zero().eval()
            : Eigen::Vector2d((step.pose.translation() - step.prior.translation()).norm() /
                                  std::max(step.window.x(), 1e-9),
                              std::abs(NormalizeAngle(step.pose.theta() - step.prior.theta())) /
                                  std::max(step.window.y(), 1e-9));
  trace->push_back({"match_score", matched ? step.score : 0.0});
  trace->push_back({"match_score_ratio", ratio});
  trace->push_back({"match_conditioning", conditioning});
  trace->push_back({"searched", step.searched ? (step.search_chosen ? 2.0 : 1.0) : 0.0});
  trace->push_back({"search_widened", step.search_widened ? 1.0 : 0.0});
  trace->push_back({"correction_xy_of_window", correction.x()});
  trace->push_back({"correction_yaw_of_window", correction.y()});
  // Lost: the match failed (the scan placed by the odometry alone, blind) or the match score's
  // short-term average fell below half its long-term level.
  const bool failed = step.outcome == IcpOdometryOutcome::kMatchFailed ||
                      step.outcome == IcpOdometryOutcome::kNoPoints;
  return !first && (failed || ratio < kLostRatio);
}

std::vector<LostInterval> LostIntervals(const Trajectory& online, const std::vector<bool>& lost) {
  SLAMRIG_CHECK(online.size() == lost.size(), "LostIntervals: one flag per scan");
  std::vector<LostInterval> intervals;
  for (std::size_t i = 0; i < lost.size(); ++i) {
    if (!lost[i]) continue;
    if (i == 0 || !lost[i - 1]) intervals.push_back({online[i].time, online[i].time, 0});
    ++intervals.back().scans;
    // A stamp earlier than the interval's start (a log's out-of-order stamps) ends it at its start.
    intervals.back().to =
        std::max(intervals.back().from, i + 1 < lost.size() ? online[i + 1].time : online[i].time);
  }
  return intervals;
}

double LostSeconds(const std::vector<LostInterval>& intervals) {
  double seconds = 0.0;
  for (const LostInterval& interval : intervals) seconds += interval.seconds();
  return seconds;
}

}  // namespace slamrig::slam
