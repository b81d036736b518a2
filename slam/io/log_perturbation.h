#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "slam/io/dataset.h"
#include "slam/odometry/scan_sync.h"
#include "slam/odometry/wheel_odometry.h"

namespace slamrig {
class YamlNode;
}

namespace slamrig::slam {

/// Odometry perturbations: random noise proportional to each increment, a systematic scale and
/// heading bias, and intervals with no odometry at all.
struct OdometryPerturbation {
  /// 1-sigma translation noise per metre of each increment's translation (per axis of an
  /// odometry pose's increment; along the track for wheel ticks).
  double noise_per_m = 0.0;
  /// 1-sigma rotation noise per radian of each increment's rotation.
  double noise_per_rad = 0.0;
  double scale = 1.0;           ///< systematic factor on every translation
  double bias_rad_per_m = 0.0;  ///< systematic heading change per metre travelled (CCW > 0)
  /// [t0, t1] intervals, seconds from the log's first record, with no odometry record.
  std::vector<Eigen::Vector2d> lost;
};

/// Laser scans dropped at random.
struct ScanPerturbation {
  double drop_fraction = 0.0;  ///< probability that a scan is dropped
};

/// Range readings.
struct RangePerturbation {
  double noise_m = 0.0;  ///< 1-sigma Gaussian noise added to every hit
  double max_m = 0.0;    ///< a shorter maximum range (0: the log's own)
};

/// Beams made invalid (a reading of 0, below the scan's minimum range: no information).
struct BeamPerturbation {
  int drop_every = 0;          ///< every k-th beam (beams k-1, 2k-1, ...; 0: none)
  double drop_fraction = 0.0;  ///< probability that a beam is dropped
};

/// Perturbations of a log's record stream, applied when it is read (the file is never changed);
/// every default leaves the stream bit-identical. The reference is never perturbed.
struct LogPerturbation {
  OdometryPerturbation odometry;
  ScanPerturbation scans;
  RangePerturbation range;
  BeamPerturbation beams;

  /// True if any field differs from its default (something would change).
  bool Active() const;
  /// One RuleViolation() message per broken rule, with the field's key path; empty when valid.
  std::vector<std::string> Validate() const;
};

/// The field tables (slam/config/fields.h): a scenario's `source.perturb` map, and the keys
/// `--perturb KEY=VALUE` takes (odometry.noise_per_m, range.max_m, ...).
template <typename V>
void VisitFields(V& v, OdometryPerturbation& o) {
  v("noise_per_m", o.noise_per_m);
  v("noise_per_rad", o.noise_per_rad);
  v("scale", o.scale);
  v("bias_rad_per_m", o.bias_rad_per_m);
  v("lost", o.lost);
}
template <typename V>
void VisitFields(V& v, ScanPerturbation& o) {
  v("drop_fraction", o.drop_fraction);
}
template <typename V>
void VisitFields(V& v, RangePerturbation& o) {
  v("noise_m", o.noise_m);
  v("max_m", o.max_m);
}
template <typename V>
void VisitFields(V& v, BeamPerturbation& o) {
  v("drop_every", o.drop_every);
  v("drop_fraction", o.drop_fraction);
}
template <typename V>
void VisitFields(V& v, LogPerturbation& o) {
  v.Struct("odometry", o.odometry);
  v.Struct("scans", o.scans);
  v.Struct("range", o.range);
  v.Struct("beams", o.beams);
}

/// Reads a `perturb:` map (every key read, Validate() applied at the node): ConfigError naming
/// the file, line and key otherwise.
LogPerturbation ParseLogPerturbation(const YamlNode& node);

/// Reads `--perturb KEY=VALUE` flags (e.g. "odometry.noise_per_m=0.05",
/// "odometry.lost=[[10, 20]]"): ConfigError naming the flag for a bad key or value.
LogPerturbation LogPerturbationFromFlags(const std::vector<std::string>& flags);

/// Applies `perturbation` to `data.records` in place, drawing from RandomStreams of `seed`
/// named "perturb.odometry", "perturb.scans", "perturb.range" and "perturb.beams" (so the same
/// seed gives the same perturbation, and each kind's draws do not depend on the others).
/// The odometry noise is drawn once per scan interval: every odometry record between two scans
/// uses the same standard normal draws, so the increment between two scans (what SLAM sees, and
/// what MeasureOdometryNoise measures) gets sigma = noise_per_m * |t| and noise_per_rad * |theta|
/// whatever the log's odometry rate (independent draws per record would shrink it by the square
/// root of the records per scan). A log without scans draws per record.
/// Odometry is perturbed in the form each record has:
/// - OdometryPose streams (CARMEN ODOM, a bag's /odom): each increment u = O_{k-1}^-1 O_k gets
///   t' = scale * t + N(0, (noise_per_m |t|)^2) per axis and theta' = theta + bias * |t| +
///   N(0, (noise_per_rad |theta|)^2); the stream is re-accumulated from the first pose, so it
///   stays one consistent odometry trajectory.
/// - WheelTicks (ECE276A encoders, a bag's /joint_states): distance d and encoder yaw of each
///   record (with `robot`'s geometry) get the same along the track; the ticks are rewritten
///   with the fractional remainder carried to the next record, and the yaw change (bias and
///   noise) is also added to the gyro z rate of the IMU samples of that record's interval, so
///   yaw from the gyro changes alike. The rotation noise scales with the gyro's rotation over
///   the interval when it has samples, else the encoders'.
/// Lost intervals remove the odometry records stamped inside them; the first one after an
/// interval spans it (an odometry pose is absolute; the ticks of the removed records are added
/// to it, as a counter that kept counting would report). Dropped scans also drop the reference
/// pose with the same stamp, if any, so a one-pose-per-scan reference stays in step. Range
/// perturbations apply to hits only: max_m turns readings at or beyond it into no-returns
/// (reading = range_max_m = max_m, the form the readers give a no-return), then noise is added
/// (clamped into [range_min_m, range_max_m) so a hit stays a hit); dropped beams read 0 (and a
/// scan with range_min_m 0 gets the smallest positive float as its minimum).
void ApplyLogPerturbation(Dataset* data, const LogPerturbation& perturbation, std::uint64_t seed,
                          const DiffDriveParams& robot = {});

/// A log's own odometry error per scan against its reference (one reference pose per scan, in
/// order, as the corrected CARMEN logs have), with u_k the odometry increment between scans and
/// g_k the reference's: the error model ApplyLogPerturbation draws from, fitted.
struct OdometryNoiseMeasurement {
  int increments = 0;              ///< scan pairs used
  double turn_rad = 0.0;           ///< sum of |theta(g_k)|
  double path_m = 0.0;             ///< sum of |g_k translation|
  double rms_translation_m = 0.0;  ///< RMS of |t(u_k) - t(g_k)| per scan
  double rms_rotation_rad = 0.0;   ///< RMS of the wrapped theta(u_k) - theta(g_k) per scan
  /// sqrt(sum |e_t|^2 / 2 / sum |t(g)|^2): the per-axis noise_per_m that gives the same mean
  /// squared error.
  double noise_per_m = 0.0;
  /// sqrt(sum e_theta^2 / sum theta(g)^2): the noise_per_rad that gives the same mean squared
  /// rotation error (it also absorbs heading error while driving straight).
  double noise_per_rad = 0.0;
  /// sum t(u).t(g) / sum |t(g)|^2: the systematic translation scale.
  double scale = 1.0;
  /// sum theta(u) theta(g) / sum theta(g)^2: the systematic rotation scale.
  double rotation_scale = 1.0;
  /// The rotation error split by its causes, from the least-squares fit (coefficients >= 0)
  /// e_theta^2 = a |t(g)|^2 + b theta(g)^2 over the scan pairs: heading error per metre
  /// travelled, sqrt(a), and per radian turned, sqrt(b). Unlike noise_per_rad it does not
  /// depend on how much of the route is straight.
  double rotation_per_m = 0.0;
  double rotation_per_rad = 0.0;
};

/// Which scan pairs MeasureOdometryNoise compares. With both 0, every consecutive pair; else
/// only the scans at which the reference has moved `travel_m` or turned `turn_rad` since the
/// last kept scan (the first is kept), each compared with the last kept one, so a finely
/// sampled log (a simulation at the lidar's rate) is measured at a coarser log's spacing (the
/// corrected CARMEN logs keep GMapping's scans, about one per metre or half radian).
struct OdometryNoiseSpacing {
  double travel_m = 0.0;
  double turn_rad = 0.0;
};

/// Measures `data`'s odometry (synchronised to its scans by `sync`) against its reference.
/// Throws ParseError naming the source when it has no reference of one pose per scan.
OdometryNoiseMeasurement MeasureOdometryNoise(const Dataset& data, const ScanSyncOptions& sync,
                                              const OdometryNoiseSpacing& spacing = {});

}  // namespace slamrig::slam
