#pragma once

// Self-diagnosis shared by the estimators: each reports its own per-scan health values in its
// trace, and from them, by its own rule, whether it is lost at that scan (ScanEstimate::lost).
// The rules are built from the pieces here: the ratio of a quality's short-term to its long-term
// average (augmented MCL's w_fast / w_slow, Thrun et al., "Probabilistic Robotics", 2005,
// Table 8.3), which judges a scan against the run's own level instead of a fixed threshold; a
// Kalman filter's NIS over its last updates against its chi-square quantile; the ICP front end's
// rule; and the verdict `diverged` from the lost flags. The runner turns consecutive lost scans
// into LostIntervals. docs/estimators.md ("How each estimator judges itself") lists the rules.

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <deque>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "slam/matching/icp_odometry.h"
#include "slam/matching/scan_points.h"
#include "slam/matching/solution_remapping.h"
#include "slam/pipeline/estimator.h"
#include "slam/types/pose2.h"
#include "slam/types/records.h"
#include "slam/types/time.h"
#include "slam/types/trajectory.h"

namespace slamrig::slam {

/// A quality whose short-term average falls below this share of its long-term one is lost (the
/// pf's relocalisation.lost_ratio default).
inline constexpr double kLostRatio = 0.5;

/// An estimator calls its run diverged when it was lost at its last scan or on more than this
/// share of its scans: a loss it recovered from is a lost interval, not a failed run.
inline constexpr double kDivergedLostShare = 0.1;

/// The short-term over the long-term exponentially weighted average of a positive quality (a
/// match score, a matched fraction): about 1 while the quality holds its usual level, well below
/// 1 when it falls. Dimensionless, so a threshold on it holds for any dataset's level.
class QualityRatio {
 public:
  /// Weights per sample of the short- and long-term averages, 0 < slow_rate < fast_rate <= 1;
  /// the ratio is given once `warmup` samples are in (before that, 1). A sample below
  /// `hold_below` times the long-term average leaves that average alone (0: none does): the
  /// level to come back to, which a long loss must not become.
  QualityRatio(double fast_rate, double slow_rate, int warmup, double hold_below = 0.0);

  /// Adds one quality (>= 0) and returns the ratio after it.
  double Add(double quality);
  /// The current ratio (1 before the warm-up ends or while the long-term average is 0).
  double ratio() const;
  bool warm() const { return samples_ >= warmup_; }

 private:
  double fast_rate_, slow_rate_;
  int warmup_;
  double hold_below_;
  int samples_ = 0;
  double fast_ = 0.0, slow_ = 0.0;
};

/// A Kalman filter's consistency over its last updates: the sum of their normalised innovations
/// squared (NIS) is chi-square with the sum of their dimensions as degrees of freedom when the
/// filter is consistent (Bar-Shalom et al., "Estimation with Applications to Tracking and
/// Navigation", 2001, Sec. 5.4.2); above its 99.9 % quantile the filter's model no longer
/// explains its measurements. A window, not one update, so that one outlier does not decide.
class NisWindow {
 public:
  static constexpr int kUpdates = 10;  ///< updates in the window
  static constexpr double kProbability = 0.999;

  /// Adds one update's NIS and its dimension (> 0).
  void Add(double nis, int dimension);
  /// The window's NIS sum over its chi-square quantile: > 1 is inconsistent; 0 while empty.
  double ratio() const;
  /// Inconsistent: a full window whose ratio is above 1.
  bool inconsistent() const { return static_cast<int>(window_.size()) == kUpdates && ratio() > 1; }

 private:
  std::deque<std::pair<double, int>> window_;
  double nis_sum_ = 0.0;
  int dimension_sum_ = 0;
};

/// An error an estimator can neither rule out nor take back, above which it calls its run
/// diverged: the filters' displacement against the wheels (WheelAgreement), graph SLAM's bound on
/// what an unrepaired blind stretch left (BlindStretchBound). Tens of times a scan match's error.
inline constexpr double kDivergedErrorM = 1.0;

/// Whether an estimate's motion agrees with the wheels' over the last stretch of driving: the
/// distance the estimate moved along the wheels' direction, summed over the scans of the last
/// kWindowM metres of wheel travel, over the wheels' own distance there. A scan matcher that
/// holds the robot still while the wheels roll on (a map written from a stopped estimate fits a
/// stopped estimate best: a featureless corridor), or that races ahead of them, contradicts them
/// by far more than any wheel's scale error or slip over that stretch: outside
/// [1 - kTolerance, 1 + kTolerance] the estimate is not following the robot. The heading is left
/// out: raw odometry's heading drifts (degrees per metre) where its distance holds.
///
/// Only scans that observe the motion poorly are judged (Observability below kObservable): where
/// the scan's own geometry pins the robot along the wheels' direction, the scan is the better
/// witness (wheels slip, spin, or log the wrong sign when reversing), and an estimate that
/// follows it is right to leave the wheels. The window is the last kWindowM of wheel travel over
/// the judged scans.
///
/// The turns are compared too, on every scan and over longer stretches (the last kHeadingWindowM
/// of wheel travel, and the last kLongHeadingWindowM once kHeadingWindowM is held): an estimate
/// that turns more than kHeadingToleranceRad plus kHeadingSkidShare of the wheels' own turning
/// away from them there (a scan matcher rotating on a few far landmarks while the robot drives
/// straight) contradicts them by more than the wheels' heading drift on the straight (the ten
/// real logs and their copies with twice the odometry noise: at most 32 degrees over 10 m and 10
/// beyond half the turn over 30 m) and their skid in turns (up to half the turn) explain, whatever
/// the scans observe. The longer stretch catches a slow runaway (80 degrees over 15 m of straight
/// driving, never 45 within 10 m) that the shorter one lets through. Both compare the turns net of
/// the wheels' own steady drift (DriftEstimate): a robot whose wheels drift 1.2 degrees per metre
/// on the straight has 36 of them in the long stretch before its estimate errs at all.
class WheelAgreement {
 public:
  static constexpr double kWindowM = 2.0;      ///< metres of wheel travel judged together
  static constexpr double kTolerance = 0.5;    ///< the distance ratio's allowed departure from 1
  static constexpr double kObservable = 0.25;  ///< a scan this observable is not judged
  static constexpr double kHeadingWindowM = 10.0;  ///< metres of wheel travel whose turns compare
  /// ... and over up to this much (judged from kHeadingWindowM on): a slow runaway.
  static constexpr double kLongHeadingWindowM = 30.0;
  static constexpr double kHeadingToleranceRad = 0.7853981633974483;  ///< 45 degrees ...
  static constexpr double kHeadingSkidShare = 0.5;  ///< ... plus this share of the wheels' turning
  /// ... or, where larger, this many standard deviations of the wheels' measured heading noise
  /// summed over the window (Add's wheel_yaw_sigma_rad).
  static constexpr double kHeadingNoiseSigmas = 5.0;

  /// Adds one scan's increments since the previous scan, both in the robot's frame there: the
  /// estimate's own (an estimator that revises its choice of hypothesis, like an RBPF switching
  /// particles, gives the chosen hypothesis's own motion) and the wheels'. True when the window
  /// is full and its ratio lies outside the tolerance, or the heading window is full and its
  /// turns disagree. `observability`: the scan's along the wheels' direction (Observability); at
  /// kObservable or above its distance is not judged.
  ///
  /// `wheel_yaw_sigma_rad`: the standard deviation of the wheels' heading increment where the
  /// estimator measured it (0: not known). A turn difference within kHeadingNoiseSigmas times
  /// the window's summed deviation is the wheels' own noise and never contradicts them: wheels
  /// whose heading scatters by more than the fixed tolerance per turn are no witness of it.
  bool Add(const Pose2& estimate_increment, const Pose2& wheel_increment,
           double observability = 0.0, double wheel_yaw_sigma_rad = 0.0);
  /// Forgets the window: after a gap in the odometry or a jump the estimator made on purpose (a
  /// relocalisation), the motion before it says nothing about the motion after.
  void Reset();
  /// The window's distance ratio (1 while the window is not full).
  double ratio() const;
  /// The heading window's turn, the estimate's less the wheels', net of the wheels' learnt drift
  /// over it (what is judged; 0 while it is not full), rad.
  double turn_difference_rad() const;
  /// The largest turn difference of a flagged heading window so far, net of the wheels' learnt
  /// drift, in magnitude (0: none). A heading lost by that much is not a wheel's error, and no
  /// later scan takes it back.
  double heading_contradicted_rad() const { return heading_contradicted_rad_; }
  /// The estimate's displacement against the wheels over the persistent flagged stretches: per
  /// stretch of consecutive flagged scans, the estimate's distance less the wheels' (from the
  /// window that first flagged it to its last scan), summed in magnitude. A stretch persists when
  /// it stays flagged over more than kWindowM of wheel travel after its first flag: one jump of
  /// the estimate (a correction) leaves the window within that, a stopped or racing estimate
  /// does not.
  double contradicted_m() const {
    return contradicted_m_ + (Persistent() ? std::abs(stretch_m_) : 0.0);
  }

 private:
  struct Step {
    double wheels_m, estimate_m;
    bool counted;  // in a stretch's displacement
  };
  struct Turn {
    double wheels_m, wheels_rad, estimate_rad;
    double wheels_variance_rad2 = 0.0;  // of wheels_rad, where the estimator measured it
  };
  // The turns over the fewest latest scans that cover a length of wheel travel.
  class TurnWindow {
   public:
    explicit TurnWindow(double length_m) : length_m_(length_m) {}
    void Add(const Turn& turn);
    void Clear();
    // The estimate's turn less the wheels' (0 while it holds less than kHeadingWindowM), rad.
    double difference_rad() const;
    // That difference less `drift_rad_per_m` times the window's travel (0 while not full), rad.
    double net_difference_rad(double drift_rad_per_m) const;
    // Whether the net difference is more than the wheels' drift and skid explain.
    bool Contradicted(double drift_rad_per_m) const;
    double travel_m() const { return travel_m_; }

   private:
    double length_m_;
    std::deque<Turn> turns_;
    double travel_m_ = 0.0, wheels_rad_ = 0.0, wheels_abs_rad_ = 0.0, estimate_rad_ = 0.0;
    double wheels_variance_rad2_ = 0.0;
  };
  // The wheels' own steady heading drift per metre on this run: the median of the short
  // window's turn difference per metre over its full windows that were not flagged, counted in
  // kDriftBins bins over +-kDriftRangeRadPerM; 0 until kDriftHistoryM of wheel travel is held (a
  // runaway at the start is not learnt as the wheels' bias).
  class DriftEstimate {
   public:
    static constexpr int kDriftBins = 201;
    static constexpr double kDriftRangeRadPerM = 0.05;
    static constexpr double kDriftHistoryM = 50.0;
    void Travel(double wheels_m) { travel_m_ += wheels_m; }
    void Add(double rad_per_m);
    double rad_per_m() const;

   private:
    std::array<int, kDriftBins> counts_{};
    int total_ = 0;
    double travel_m_ = 0.0;
  };
  bool Persistent() const { return stretch_travel_m_ > kWindowM; }
  void CloseStretch();
  // Adds one scan's turns to the heading window; true when it is flagged.
  bool AddTurn(const Turn& turn);
  TurnWindow turns_{kHeadingWindowM}, long_turns_{kLongHeadingWindowM};
  DriftEstimate drift_;
  double heading_contradicted_rad_ = 0.0;
  std::deque<Step> window_;
  double wheels_m_ = 0.0, estimate_m_ = 0.0;
  bool in_stretch_ = false;
  double stretch_m_ = 0.0;         // the open stretch's signed displacement
  double stretch_travel_m_ = 0.0;  // and its wheel travel after its first flag
  double contradicted_m_ = 0.0;    // the closed stretches'
};

/// How well a scan's geometry (ScanGeometry) observes translation along `direction` (robot frame):
/// the information along it over the strongest direction's, about 1 in a room, near 0 along a
/// corridor's axis; 0 for a scan without geometry or a zero direction.
double Observability(const MatchConstraints& geometry, const Eigen::Vector2d& direction);

/// A filter's check of its estimate against the wheels (WheelAgreement), with the scan geometry
/// it judges by: that of the scan of the filter's last update, which holds until its next (the
/// filter moves on the odometry alone in between). Off without the robot's own odometry.
class WheelCheck {
 public:
  /// `points`: how the filter turns a scan into points (its geometry is judged from them).
  WheelCheck(bool enabled, const ScanPointsOptions& points);

  /// Judges one scan: the wheels' increment since the previous scan, the estimate's own, and
  /// whether the filter updated on this scan. True when the estimate contradicts the wheels.
  bool Judge(const LaserScan& scan, const Pose2& wheel_increment, const Pose2& estimate_increment,
             bool updated);
  /// Forgets the motion so far (WheelAgreement::Reset): after a gap in the odometry or a jump the
  /// filter made on purpose.
  void Reset() { agreement_.Reset(); }
  /// The last scan's health values: wheel_distance_ratio, wheel_turn_difference_rad,
  /// motion_observability.
  void AppendTrace(std::vector<TraceValue>* trace) const;
  /// The statistics wheel_contradiction_m and wheel_heading_contradiction_rad.
  void AppendStatistics(std::map<std::string, double>* statistics) const;
  /// `names` with those statistics' names after them: an estimator's StatisticNames().
  static std::vector<std::string> WithStatisticNames(std::vector<std::string> names);
  /// The estimate contradicted the wheels by more than kDivergedErrorM in distance, or lost its
  /// heading against them (WheelAgreement::heading_contradicted_rad).
  bool Diverged() const;

 private:
  bool enabled_;
  ScanPointsOptions points_;
  WheelAgreement agreement_;
  MatchConstraints geometry_;
  bool geometry_seen_ = false;
  double observability_ = 0.0;
};

/// The error a stretch placed by the odometry alone may have left: its pose covariance from the
/// odometry's noise per increment, compounded from zero at the stretch's start (first-order
/// SE(2) propagation), and the position's 99 % bound, sqrt(chi2_2(0.99) x the largest
/// eigenvalue of the position block).
class BlindStretchBound {
 public:
  /// Starts a new stretch at zero error.
  void Start();
  /// Adds one increment (robot frame) and its noise: standard deviations of x and y alike, and of
  /// the yaw.
  void Add(const Pose2& increment, const Eigen::Vector2d& sigmas);
  /// The 99 % bound on the position error so far, metres.
  double bound_m() const;

 private:
  Eigen::Matrix3d covariance_ = Eigen::Matrix3d::Zero();
  double heading_ = 0.0;  // from the stretch's start
};

/// How much of a map's walls its own scans see through (CountSeeThrough's crossed cells), over the
/// last kUpdates updates: the extent of wall crossed, as distinct kBinM squares. A likelihood or
/// correlative matcher cannot see a map written twice (each new scan fits the copy it is
/// writing); the rays can: a revisit placed beside the first visit crosses the first copy's walls
/// from every place it passes. Doors seen closed and then open, people and furniture mapped and
/// then seen past, are crossed too; docs/studies/see-through.md measures both (the ten real logs
/// reach 17 m, generated offices with good runs 23 m, the logs whose maps were written twice 31
/// to 35 m) and why no bound on it is a lost rule yet. A health value.
class WallCrossings {
 public:
  static constexpr int kUpdates = 40;   ///< updates counted together (about 10 m of driving)
  static constexpr double kBinM = 0.2;  ///< wall extent is counted in squares this big

  /// Adds one update's crossed wall points (world frame).
  void Add(const std::vector<Eigen::Vector2d>& crossed);
  /// The wall crossed over the window, metres (distinct squares times kBinM).
  double extent_m() const { return static_cast<double>(counts_.size()) * kBinM; }
  /// The largest extent_m so far.
  double worst_m() const { return worst_m_; }

 private:
  std::deque<std::vector<std::pair<int, int>>> window_;
  std::map<std::pair<int, int>, int> counts_;  // square -> updates in the window that crossed it
  double worst_m_ = 0.0;
};

/// An estimator's per-scan lost flags, counted: the statistics `lost` (losses) and `diverged`.
class HealthRecord {
 public:
  void Add(bool lost);

  int scans() const { return scans_; }
  int lost_scans() const { return lost_scans_; }
  /// Times it became lost (runs of consecutive lost scans).
  int losses() const { return static_cast<int>(loss_scans_.size()); }
  /// Each loss's first and last scan, counted from 0 in Add order.
  const std::vector<std::pair<int, int>>& loss_scans() const { return loss_scans_; }
  /// Lost at the last scan: the last loss runs to it.
  bool lost_at_end() const {
    return !loss_scans_.empty() && loss_scans_.back().second == scans_ - 1;
  }
  /// Lost at the last scan, or on more than kDivergedLostShare of the scans.
  bool Diverged() const;

 private:
  int scans_ = 0;
  int lost_scans_ = 0;
  std::vector<std::pair<int, int>> loss_scans_;
};

/// The health of a scan-to-local-map front end (IcpOdometry: the graph's and icp-odometry's) at
/// each scan, and its lost rule.
class FrontEndHealth {
 public:
  FrontEndHealth();
  /// Judges the step that placed one scan: appends its health values to `trace` and returns
  /// whether the front end is lost there.
  bool Judge(const IcpOdometryStep& step, std::vector<TraceValue>* trace);

 private:
  QualityRatio score_ratio_;
};

/// A run of consecutive lost scans.
struct LostInterval {
  Time from;  ///< the first lost scan's time
  /// The next scan's time (the first one not lost), or the last scan's at the end; never before
  /// `from`.
  Time to;
  int scans = 0;  ///< lost scans in it
  double seconds() const { return SecondsBetween(to, from); }
};

/// The lost intervals of a run: `lost[i]` for the scan at `online[i]` (same length).
std::vector<LostInterval> LostIntervals(const Trajectory& online, const std::vector<bool>& lost);
/// Their total length, seconds.
double LostSeconds(const std::vector<LostInterval>& intervals);

}  // namespace slamrig::slam
