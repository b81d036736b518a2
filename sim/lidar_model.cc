#include "sim/lidar_model.h"

#include <cmath>
#include <numbers>

#include "slam/types/check.h"
#include "slam/types/validation.h"

namespace slamrig::sim {
namespace {

double DegToRad(double deg) { return deg * std::numbers::pi / 180.0; }

}  // namespace

double LidarOptions::angle_min_rad() const { return -0.5 * DegToRad(fov_deg); }

double LidarOptions::angle_increment_rad() const {
  return DegToRad(fov_deg) / static_cast<double>(num_beams - 1);
}

double LidarOptions::time_increment_s() const {
  return 1.0 / (rate_hz * static_cast<double>(beams_per_revolution));
}

std::vector<std::string> LidarOptions::Validate() const {
  Rules rules;
  rules.InRange("rate_hz", rate_hz, 0.0, 1000.0, Ends::kOpenLow)
      .Above("num_beams", num_beams, 1)
      .InRange("fov_deg", fov_deg, 0.0, 360.0, Ends::kOpen);
  if (num_beams > 1 && fov_deg > 0.0) {
    // The beams of one scan must fit into one turn of the mirror.
    const double beams_in_fov = fov_deg / 360.0 * beams_per_revolution;
    rules.Require(beams_in_fov + 1e-9 >= num_beams - 1, "beams_per_revolution",
                  beams_per_revolution,
                  "must be >= (num_beams - 1) * 360 / fov_deg = " +
                      FormatNumber((num_beams - 1) * 360.0 / fov_deg));
  }
  rules.NonNegative("range_min_m", range_min_m)
      .Require(range_max_m > range_min_m, "range_max_m", range_max_m,
               "must be > range_min_m (" + FormatNumber(range_min_m) + ")")
      .NonNegative("range_noise_stddev_m", range_noise_stddev_m)
      .Fraction("range_noise_fraction", range_noise_fraction)
      .NonNegative("range_resolution_m", range_resolution_m)
      .Positive("short_decay_per_m", short_decay_per_m)
      .Fraction("p_short", p_short)
      .Fraction("p_max", p_max)
      .Fraction("p_random", p_random);
  const double p_sum = p_short + p_max + p_random;
  rules.Require(p_sum <= 1.0, "p_short + p_max + p_random", p_sum, "must be <= 1");
  return rules.errors();
}

LidarModel::LidarModel(const LidarOptions& options, std::uint64_t seed)
    : options_(options), rng_(seed, "lidar") {
  SLAMRIG_CHECK_VALID(options_, "LidarOptions");
  if (options_.range_resolution_m > 0.0) inverse_resolution_ = 1.0 / options_.range_resolution_m;
  p_max_random_ = options_.p_max + options_.p_random;
  p_any_ = options_.p_max + options_.p_random + options_.p_short;
}

double LidarModel::Measure(double true_range_m) {
  const LidarOptions& o = options_;
  const bool hit = true_range_m < o.range_max_m;
  double z = 0.0;
  const double u = p_any_ > 0.0 ? rng_.Uniform() : 1.0;
  if (u < o.p_max) {
    return o.range_max_m;
  } else if (u < p_max_random_) {
    z = o.range_min_m + rng_.Uniform() * (o.range_max_m - o.range_min_m);
  } else if (u < p_any_ && hit) {
    // Exponential truncated to [0, true range), by inversion.
    const double lambda = o.short_decay_per_m;
    z = -std::log1p(-rng_.Uniform() * -std::expm1(-lambda * true_range_m)) / lambda;
  } else if (!hit) {
    return o.range_max_m;
  } else {
    z = true_range_m;
    if (o.range_noise_fraction > 0.0) {
      z += std::hypot(o.range_noise_stddev_m, o.range_noise_fraction * true_range_m) *
           rng_.Gaussian();
    } else if (o.range_noise_stddev_m > 0.0) {
      z += o.range_noise_stddev_m * rng_.Gaussian();
    }
  }
  z = std::max(z, 0.0);
  if (o.range_resolution_m > 0.0) {
    // Round half up to the resolution (z >= 0, so truncation after +0.5 is rounding).
    z = static_cast<double>(static_cast<std::int64_t>(z * inverse_resolution_ + 0.5)) *
        o.range_resolution_m;
  }
  return z >= o.range_max_m ? o.range_max_m : z;
}

LaserScan LidarModel::MakeScan(Time time, std::span<const double> true_ranges_m) {
  SLAMRIG_CHECK(true_ranges_m.size() == static_cast<std::size_t>(options_.num_beams),
                "one true range per beam");
  LaserScan scan;
  scan.time = time;
  // The metadata are stated as the floats sensor_msgs/LaserScan carries (and ranges are floats,
  // so a no-return reading, exactly range_max_m, compares as "at or beyond" the limit): a scan
  // recorded to a ROS 2 bag reads back bit for bit.
  auto as_float = [](double v) { return static_cast<double>(static_cast<float>(v)); };
  scan.angle_min_rad = as_float(options_.angle_min_rad());
  scan.angle_increment_rad = as_float(options_.angle_increment_rad());
  scan.time_increment_s = as_float(options_.time_increment_s());
  scan.range_min_m = as_float(options_.range_min_m);
  scan.range_max_m = as_float(options_.range_max_m);
  scan.base_from_laser = options_.mount.ToPose2();
  scan.ranges_m.resize(true_ranges_m.size());
  for (std::size_t i = 0; i < true_ranges_m.size(); ++i) {
    scan.ranges_m[i] = static_cast<float>(Measure(true_ranges_m[i]));
  }
  return scan;
}

}  // namespace slamrig::sim
