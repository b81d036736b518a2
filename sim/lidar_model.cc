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
  std::vector<std::string> errors;
  auto require = [&errors](bool ok, const std::string& what) {
    if (!ok) errors.push_back(what);
  };
  require(rate_hz > 0.0 && rate_hz <= 1000.0,
          "rate_hz = " + FormatNumber(rate_hz) + "; must be in (0, 1000]");
  require(num_beams > 1, "num_beams = " + std::to_string(num_beams) + "; must be > 1");
  require(fov_deg > 0.0 && fov_deg < 360.0,
          "fov_deg = " + FormatNumber(fov_deg) + "; must be in (0, 360)");
  if (num_beams > 1 && fov_deg > 0.0) {
    // The beams of one scan must fit into one turn of the mirror.
    const double beams_in_fov = fov_deg / 360.0 * beams_per_revolution;
    require(beams_in_fov + 1e-9 >= num_beams - 1,
            "beams_per_revolution = " + std::to_string(beams_per_revolution) +
                "; must be >= (num_beams - 1) * 360 / fov_deg = " +
                FormatNumber((num_beams - 1) * 360.0 / fov_deg));
  }
  require(range_min_m >= 0.0, "range_min_m = " + FormatNumber(range_min_m) + "; must be >= 0");
  require(range_max_m > range_min_m, "range_max_m = " + FormatNumber(range_max_m) +
                                         "; must be > range_min_m (" + FormatNumber(range_min_m) +
                                         ")");
  require(range_noise_stddev_m >= 0.0,
          "range_noise_stddev_m = " + FormatNumber(range_noise_stddev_m) + "; must be >= 0");
  require(range_noise_fraction >= 0.0 && range_noise_fraction <= 1.0,
          "range_noise_fraction = " + FormatNumber(range_noise_fraction) + "; must be in [0, 1]");
  require(range_resolution_m >= 0.0,
          "range_resolution_m = " + FormatNumber(range_resolution_m) + "; must be >= 0");
  require(short_decay_per_m > 0.0,
          "short_decay_per_m = " + FormatNumber(short_decay_per_m) + "; must be > 0");
  for (const auto& [name, p] : {std::pair{"p_short", p_short}, std::pair{"p_max", p_max},
                                std::pair{"p_random", p_random}}) {
    require(p >= 0.0 && p <= 1.0,
            std::string(name) + " = " + FormatNumber(p) + "; must be in [0, 1]");
  }
  require(p_short + p_max + p_random <= 1.0,
          "p_short + p_max + p_random = " + FormatNumber(p_short + p_max + p_random) +
              "; must be <= 1");
  return errors;
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
