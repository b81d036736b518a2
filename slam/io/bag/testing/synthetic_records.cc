#include "slam/io/bag/testing/synthetic_records.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace slamrig::slam::testing {
namespace {

// splitmix64: a tiny generator whose output does not depend on the standard library.
struct Rng {
  std::uint64_t state;
  std::uint64_t Next() {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }
};

}  // namespace

Dataset SyntheticRun(double duration_s, std::uint64_t seed, int beams) {
  Rng rng{seed};
  Dataset data;
  data.source = "synthetic";
  const Time start = Time::FromSeconds(1000.0);
  const auto end_ns = start.ns + static_cast<std::int64_t>(std::llround(duration_s * 1e9));
  const std::int64_t scan_ns = 25'000'000, imu_ns = 10'000'000;
  const double fov = 1.5 * std::numbers::pi;
  const Pose2 base_from_laser(0.15, 0.0, 0.0);
  double x = 0.0, y = 0.0, theta = 0.0;
  for (std::int64_t t = start.ns; t < end_ns; t += 5'000'000) {
    if ((t - start.ns) % imu_ns == 0) {
      ImuSample imu;
      imu.time = Time{t};
      imu.angular_velocity_rad_s = {0.01 * rng.Uniform(), -0.01 * rng.Uniform(),
                                    rng.Uniform() - 0.5};
      imu.linear_acceleration_m_s2 = {rng.Uniform() - 0.5, rng.Uniform() - 0.5, 9.81};
      data.records.push_back(imu);
    }
    if ((t - start.ns) % scan_ns != 0) continue;
    const Time stamp{t + 1};  // sensors a nanosecond apart, as in a real log
    WheelTicks ticks;
    ticks.time = stamp;
    for (int i = 0; i < 2; ++i) {
      ticks.right_ticks.push_back(static_cast<std::int32_t>(rng.Next() % 9) - 1);
      ticks.left_ticks.push_back(static_cast<std::int32_t>(rng.Next() % 9) - 1);
    }
    data.records.push_back(ticks);
    x += 0.01 * std::cos(theta);
    y += 0.01 * std::sin(theta);
    theta = NormalizeAngle(theta + 0.02 * (rng.Uniform() - 0.3));
    data.records.push_back(OdometryPose{Time{t + 2}, Pose2(x, y, theta)});
    LaserScan scan;
    scan.time = Time{t + 3};
    scan.angle_min_rad = static_cast<float>(-0.5 * fov);
    scan.angle_increment_rad = static_cast<float>(fov / (beams - 1));
    scan.time_increment_s = static_cast<float>(0.025 / 1440.0);
    scan.range_min_m = static_cast<float>(0.1);
    scan.range_max_m = 30.0;
    scan.base_from_laser = base_from_laser;
    scan.ranges_m.resize(static_cast<std::size_t>(beams));
    for (float& r : scan.ranges_m) {
      const double u = rng.Uniform();
      r = u < 0.05 ? 30.0f : static_cast<float>(std::round(100.0 + u * 29000.0) * 1e-3);
    }
    data.records.push_back(std::move(scan));
    data.reference.push_back({Time{t + 4}, Pose2(x + 0.1, y - 0.05, theta + 0.01)});
  }
  std::stable_sort(data.records.begin(), data.records.end(),
                   [](const Record& a, const Record& b) { return RecordTime(a) < RecordTime(b); });
  return data;
}

}  // namespace slamrig::slam::testing
