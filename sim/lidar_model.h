#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "sim/mount_pose.h"
#include "slam/types/random_stream.h"
#include "slam/types/records.h"

namespace slamrig::sim {

/// A scanning 2D lidar. Defaults are a Hokuyo UTM-30LX: 1081 beams over 270 degrees (0.25 degree
/// steps, 1440 steps per turn), 40 Hz, 0.1-30 m, about 1 cm range noise, 1 mm resolution.
struct LidarOptions {
  bool enabled = true;                 ///< false: the robot has no lidar
  double rate_hz = 40.0;               ///< scans per second (one mirror turn per scan)
  int num_beams = 1081;                ///< beams per scan, first at -fov/2, last at +fov/2
  double fov_deg = 270.0;              ///< angle from the first to the last beam
  int beams_per_revolution = 1440;     ///< angular steps in a full turn; sets the per-beam time
  double range_min_m = 0.1;            ///< shorter readings are invalid
  double range_max_m = 30.0;           ///< no return is reported as exactly this
  double range_noise_stddev_m = 0.01;  ///< Gaussian noise on a hit
  /// Gaussian noise on a hit proportional to its range (0.01: 1 % of the range, 1 sigma),
  /// combined with range_noise_stddev_m as the root of the sum of squares.
  double range_noise_fraction = 0.0;
  double range_resolution_m = 0.001;  ///< readings are rounded to this (0: none)
  double p_short = 0.005;             ///< probability of an unexpected short return
  double short_decay_per_m = 0.5;     ///< rate of the exponential short-return distance
  double p_max = 0.003;               ///< probability of a dropout (max-range reading)
  double p_random = 0.002;            ///< probability of a uniform random reading
  MountPose mount{0.133, 0.0, 0.0};   ///< base_from_laser

  /// Angle of beam 0 in the laser frame.
  double angle_min_rad() const;
  /// Angle step between beams.
  double angle_increment_rad() const;
  /// Time between beams (a spinning mirror: one turn per scan).
  double time_increment_s() const;
  /// One message per broken rule, e.g. "num_beams = 0; must be > 1".
  std::vector<std::string> Validate() const;
};

/// Turns true ranges into what the lidar reports, with the beam mixture model of Thrun, Burgard
/// and Fox, Probabilistic Robotics (2005), Sec. 6.3: Gaussian noise around the true range, short
/// returns (exponential), max-range dropouts and uniform random readings. A beam that hits nothing
/// within range reads exactly range_max_m with no noise, as real range finders report it.
class LidarModel {
 public:
  /// `options` must be valid (checked). Draws from the stream "lidar" of `seed`.
  LidarModel(const LidarOptions& options, std::uint64_t seed);

  /// The scan that starts at `time` given the true distance of each beam (+infinity: no hit).
  /// `true_ranges_m` has num_beams entries.
  LaserScan MakeScan(Time time, std::span<const double> true_ranges_m);

  /// The options it was built with.
  const LidarOptions& options() const { return options_; }

 private:
  double Measure(double true_range_m);

  LidarOptions options_;
  double inverse_resolution_ = 0.0;
  double p_max_random_ = 0.0;  // p_max + p_random, the bound of the random readings
  double p_any_ = 0.0;         // p_max + p_random + p_short, the bound of every unexpected reading
  RandomStream rng_;
};

}  // namespace slamrig::sim
