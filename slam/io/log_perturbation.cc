#include "slam/io/log_perturbation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "slam/config/fields.h"
#include "slam/config/yaml_node.h"
#include "slam/odometry/odometry_interval.h"
#include "slam/types/error.h"
#include "slam/types/random_stream.h"
#include "slam/types/validation.h"

namespace slamrig::slam {
namespace {

bool IsOdometry(const Record& r) {
  return std::holds_alternative<OdometryPose>(r) || std::holds_alternative<WheelTicks>(r);
}

// The standard normal draws of the odometry noise. One set serves every odometry record between
// two scans (the records' noise is fully correlated within a scan interval), so an increment
// between scans, the motion SLAM sees, gets sigma = noise_per_m * |t| whatever the odometry
// rate of the log; a log without scans draws anew for each record.
class NoiseDraws {
 public:
  NoiseDraws(RandomStream* rng, bool per_record) : rng_(rng), per_record_(per_record) {}
  void NewInterval() { stale_ = true; }
  const Eigen::Vector3d& Get() {
    if (stale_ || per_record_) {
      const double x = rng_->Gaussian(), y = rng_->Gaussian(), r = rng_->Gaussian();
      draws_ = {x, y, r};
      stale_ = false;
    }
    return draws_;
  }

 private:
  RandomStream* rng_;
  bool per_record_;
  bool stale_ = true;
  Eigen::Vector3d draws_ = Eigen::Vector3d::Zero();
};

// A perturbed increment.
struct Step {
  Eigen::Vector2d translation;
  double theta;
};

// The increment (t, theta) perturbed: noise on both axes of t when `lateral` (else along x only),
// rotation noise proportional to `rotation_for_noise`.
Step PerturbStep(const OdometryPerturbation& p, const Eigen::Vector2d& t, double theta,
                 double rotation_for_noise, bool lateral, NoiseDraws* draws) {
  const Eigen::Vector3d& n = draws->Get();
  const double length = t.norm();
  Step s;
  s.translation =
      p.scale * t + p.noise_per_m * length * Eigen::Vector2d(n.x(), lateral ? n.y() : 0.0);
  s.theta =
      theta + p.bias_rad_per_m * length + p.noise_per_rad * std::abs(rotation_for_noise) * n.z();
  return s;
}

// OdometryPose streams: perturb each increment, re-accumulate from the first pose.
void PerturbPoses(std::vector<Record>* records, const OdometryPerturbation& p, NoiseDraws* draws) {
  std::optional<Pose2> previous_original, previous_perturbed;
  for (Record& r : *records) {
    if (std::holds_alternative<LaserScan>(r)) draws->NewInterval();
    auto* odometry = std::get_if<OdometryPose>(&r);
    if (odometry == nullptr) continue;
    const Pose2 original = odometry->odom_from_base;
    if (previous_original) {
      const Pose2 u = previous_original->Between(original);
      const Step s = PerturbStep(p, u.translation(), u.theta(), u.theta(), true, draws);
      odometry->odom_from_base =
          *previous_perturbed * Pose2(s.translation.x(), s.translation.y(), s.theta);
    }
    previous_original = original;
    previous_perturbed = odometry->odom_from_base;
  }
}

// Adds `delta` ticks (a real number) to every wheel of one side, carrying the fraction.
void AddTicks(std::vector<std::int32_t>* wheels, double delta, double* carry) {
  const double total = delta + *carry;
  const double whole = std::round(total);
  *carry = total - whole;
  for (std::int32_t& t : *wheels) {
    const double v = static_cast<double>(t) + whole;
    t = static_cast<std::int32_t>(std::clamp(v, -2147483648.0, 2147483647.0));
  }
}

// WheelTicks streams: perturb each record's distance and yaw, rewrite its ticks and shift the
// gyro rates of the IMU samples in its interval (those after the previous ticks record, stamped
// after it: the ones WheelOdometry integrates with it).
void PerturbTicks(std::vector<Record>* records, const OdometryPerturbation& p,
                  const DiffDriveParams& robot, NoiseDraws* draws) {
  const double metres_per_tick = robot.MetresPerTick();
  double carry_right = 0.0, carry_left = 0.0;
  std::optional<Time> previous_time;
  std::vector<ImuSample*> interval_imu;
  for (Record& r : *records) {
    if (std::holds_alternative<LaserScan>(r)) draws->NewInterval();
    if (auto* imu = std::get_if<ImuSample>(&r)) {
      if (!previous_time || imu->time > *previous_time) interval_imu.push_back(imu);
      continue;
    }
    auto* ticks = std::get_if<WheelTicks>(&r);
    if (ticks == nullptr) continue;
    if (ticks->right_ticks.empty() || ticks->left_ticks.empty()) {
      previous_time = ticks->time;
      interval_imu.clear();
      continue;  // WheelOdometry rejects such a record; leave it for it to name
    }
    const double right = MeanTicks(ticks->right_ticks) * metres_per_tick;
    const double left = MeanTicks(ticks->left_ticks) * metres_per_tick;
    const double distance = 0.5 * (right + left);
    const double yaw = (right - left) / robot.track_width_m;
    const double dt = previous_time ? SecondsBetween(ticks->time, *previous_time) : 0.0;
    const bool gyro = previous_time && !interval_imu.empty() && dt > 0.0;
    double gyro_yaw = 0.0;
    if (gyro) {
      for (const ImuSample* s : interval_imu) gyro_yaw += s->angular_velocity_rad_s.z();
      gyro_yaw *= dt / static_cast<double>(interval_imu.size());
    }
    const Step s =
        PerturbStep(p, Eigen::Vector2d(distance, 0.0), yaw, gyro ? gyro_yaw : yaw, false, draws);
    const double yaw_change = s.theta - yaw;
    const double right_new = s.translation.x() + 0.5 * robot.track_width_m * s.theta;
    const double left_new = s.translation.x() - 0.5 * robot.track_width_m * s.theta;
    AddTicks(&ticks->right_ticks, (right_new - right) / metres_per_tick, &carry_right);
    AddTicks(&ticks->left_ticks, (left_new - left) / metres_per_tick, &carry_left);
    if (gyro) {
      for (ImuSample* imu : interval_imu) imu->angular_velocity_rad_s.z() += yaw_change / dt;
    }
    previous_time = ticks->time;
    interval_imu.clear();
  }
}

bool InLost(const OdometryPerturbation& p, double t) {
  return std::any_of(p.lost.begin(), p.lost.end(),
                     [t](const Eigen::Vector2d& i) { return t >= i.x() && t <= i.y(); });
}

// Removes the odometry records inside lost intervals; ticks go to the next ticks record.
void DropLostOdometry(std::vector<Record>* records, const OdometryPerturbation& p, Time start) {
  std::vector<Record> kept;
  kept.reserve(records->size());
  std::optional<WheelTicks> owed;  // ticks of removed records, for the next one
  for (Record& r : *records) {
    if (IsOdometry(r) && InLost(p, SecondsBetween(RecordTime(r), start))) {
      if (const auto* ticks = std::get_if<WheelTicks>(&r)) {
        if (!owed) {
          owed = *ticks;
        } else if (owed->right_ticks.size() == ticks->right_ticks.size() &&
                   owed->left_ticks.size() == ticks->left_ticks.size()) {
          for (std::size_t i = 0; i < ticks->right_ticks.size(); ++i)
            owed->right_ticks[i] += ticks->right_ticks[i];
          for (std::size_t i = 0; i < ticks->left_ticks.size(); ++i)
            owed->left_ticks[i] += ticks->left_ticks[i];
        }
      }
      continue;
    }
    if (auto* ticks = std::get_if<WheelTicks>(&r); ticks && owed) {
      if (owed->right_ticks.size() == ticks->right_ticks.size() &&
          owed->left_ticks.size() == ticks->left_ticks.size()) {
        for (std::size_t i = 0; i < ticks->right_ticks.size(); ++i)
          ticks->right_ticks[i] += owed->right_ticks[i];
        for (std::size_t i = 0; i < ticks->left_ticks.size(); ++i)
          ticks->left_ticks[i] += owed->left_ticks[i];
      }
      owed.reset();
    }
    kept.push_back(std::move(r));
  }
  *records = std::move(kept);
}

void DropScans(Dataset* data, double fraction, RandomStream* rng) {
  std::vector<Record> kept;
  kept.reserve(data->records.size());
  std::vector<Time> dropped;
  for (Record& r : data->records) {
    // One draw per scan, whatever the fraction, so the choice of scans is fixed by the seed.
    if (std::holds_alternative<LaserScan>(r) && rng->Uniform() < fraction) {
      dropped.push_back(RecordTime(r));
      continue;
    }
    kept.push_back(std::move(r));
  }
  data->records = std::move(kept);
  if (dropped.empty() || data->reference.empty()) return;
  // The reference pose stamped like each dropped scan (the first not yet taken) goes with it.
  std::sort(dropped.begin(), dropped.end());
  std::vector<GroundTruthPose> reference;
  reference.reserve(data->reference.size());
  std::vector<bool> used(dropped.size(), false);
  for (GroundTruthPose& g : data->reference) {
    auto it = std::lower_bound(dropped.begin(), dropped.end(), g.time);
    bool drop = false;
    for (; it != dropped.end() && *it == g.time; ++it) {
      const auto i = static_cast<std::size_t>(it - dropped.begin());
      if (!used[i]) {
        used[i] = true;
        drop = true;
        break;
      }
    }
    if (!drop) reference.push_back(g);
  }
  data->reference = std::move(reference);
}

void PerturbScan(LaserScan* scan, const LogPerturbation& p, RandomStream* range_rng,
                 RandomStream* beam_rng) {
  if (p.range.max_m > 0.0 && p.range.max_m < scan->range_max_m) {
    scan->range_max_m = p.range.max_m;
    const float no_return = static_cast<float>(p.range.max_m);
    for (float& r : scan->ranges_m) r = r >= no_return ? no_return : r;
  }
  if (p.range.noise_m > 0.0) {
    const float low = static_cast<float>(scan->range_min_m);
    const float high = std::nextafter(static_cast<float>(scan->range_max_m), 0.0f);
    for (std::size_t i = 0; i < scan->ranges_m.size(); ++i) {
      if (!scan->IsHit(i)) continue;
      const double noisy = scan->ranges_m[i] + p.range.noise_m * range_rng->Gaussian();
      scan->ranges_m[i] = std::clamp(static_cast<float>(noisy), low, high);
    }
  }
  if (p.beams.drop_every > 0 || p.beams.drop_fraction > 0.0) {
    if (!(scan->range_min_m > 0.0)) scan->range_min_m = std::numeric_limits<float>::denorm_min();
    const auto every = static_cast<std::size_t>(p.beams.drop_every);
    for (std::size_t i = 0; i < scan->ranges_m.size(); ++i) {
      const bool by_index = every > 0 && (i + 1) % every == 0;
      const bool by_chance =
          p.beams.drop_fraction > 0.0 && beam_rng->Uniform() < p.beams.drop_fraction;
      if (by_index || by_chance) scan->ranges_m[i] = 0.0f;
    }
  }
}

}  // namespace

bool LogPerturbation::Active() const {
  const OdometryPerturbation& o = odometry;
  return o.noise_per_m != 0.0 || o.noise_per_rad != 0.0 || o.scale != 1.0 ||
         o.bias_rad_per_m != 0.0 || !o.lost.empty() || scans.drop_fraction != 0.0 ||
         range.noise_m != 0.0 || range.max_m != 0.0 || beams.drop_every != 0 ||
         beams.drop_fraction != 0.0;
}

std::vector<std::string> LogPerturbation::Validate() const {
  Rules rules;
  rules.InRange("odometry.noise_per_m", odometry.noise_per_m, 0.0, 10.0)
      .InRange("odometry.noise_per_rad", odometry.noise_per_rad, 0.0, 10.0)
      .InRange("odometry.scale", odometry.scale, 0.0, 10.0, Ends::kOpenLow)
      .InRange("odometry.bias_rad_per_m", odometry.bias_rad_per_m, -10.0, 10.0);
  for (std::size_t i = 0; i < odometry.lost.size(); ++i) {
    const Eigen::Vector2d& l = odometry.lost[i];
    rules.Require(l.x() >= 0.0 && l.y() >= l.x() && std::isfinite(l.y()),
                  "odometry.lost[" + std::to_string(i) + "]",
                  "[" + FormatNumber(l.x()) + ", " + FormatNumber(l.y()) + "]",
                  "must be [t0, t1] seconds with 0 <= t0 <= t1");
  }
  rules.Fraction("scans.drop_fraction", scans.drop_fraction)
      .InRange("range.noise_m", range.noise_m, 0.0, 100.0)
      .InRange("range.max_m", range.max_m, 0.0, 1e4)
      .Require(beams.drop_every == 0 || beams.drop_every >= 2, "beams.drop_every", beams.drop_every,
               "must be 0 (none) or >= 2 (1 would drop every beam)")
      .Fraction("beams.drop_fraction", beams.drop_fraction);
  return rules.errors();
}

LogPerturbation ParseLogPerturbation(const YamlNode& node) {
  if (!node.IsMap()) node.Fail("perturb is a map (odometry: {noise_per_m: 0.05}, ...)");
  LogPerturbation p;
  FieldReader reader(node);
  VisitFields(reader, p);
  node.ThrowIfInvalid(PrefixErrors(node.path(), p.Validate()));
  node.CheckAllKeysUsed();
  return p;
}

LogPerturbation LogPerturbationFromFlags(const std::vector<std::string>& flags) {
  YamlNode node = YamlNode::LoadString("{}", "--perturb");
  for (const std::string& flag : flags) {
    const std::size_t eq = flag.find('=');
    if (eq == std::string::npos || eq == 0)
      throw ConfigError("--perturb " + flag + ": expected KEY=VALUE");
    node.Override(flag.substr(0, eq), flag.substr(eq + 1), "--perturb " + flag);
  }
  return ParseLogPerturbation(node);
}

void ApplyLogPerturbation(Dataset* data, const LogPerturbation& p, std::uint64_t seed,
                          const DiffDriveParams& robot) {
  if (!p.Active() || data->records.empty()) return;
  const std::size_t records_before = data->records.size();
  const OdometryPerturbation& o = p.odometry;
  if (o.noise_per_m != 0.0 || o.noise_per_rad != 0.0 || o.scale != 1.0 || o.bias_rad_per_m != 0.0) {
    const bool has_scans =
        std::any_of(data->records.begin(), data->records.end(),
                    [](const Record& r) { return std::holds_alternative<LaserScan>(r); });
    RandomStream rng(seed, "perturb.odometry");
    NoiseDraws pose_draws(&rng, !has_scans);
    PerturbPoses(&data->records, o, &pose_draws);
    NoiseDraws tick_draws(&rng, !has_scans);
    PerturbTicks(&data->records, o, robot, &tick_draws);
  }
  std::size_t lost = 0, dropped = 0;
  if (!o.lost.empty()) {
    DropLostOdometry(&data->records, o, RecordTime(data->records.front()));
    lost = records_before - data->records.size();
  }
  if (p.scans.drop_fraction > 0.0) {
    RandomStream rng(seed, "perturb.scans");
    const std::size_t before = data->records.size();
    DropScans(data, p.scans.drop_fraction, &rng);
    dropped = before - data->records.size();
  }
  if (p.range.noise_m > 0.0 || p.range.max_m > 0.0 || p.beams.drop_every > 0 ||
      p.beams.drop_fraction > 0.0) {
    RandomStream range_rng(seed, "perturb.range"), beam_rng(seed, "perturb.beams");
    for (Record& r : data->records) {
      if (auto* scan = std::get_if<LaserScan>(&r)) PerturbScan(scan, p, &range_rng, &beam_rng);
    }
  }
  data->notes.push_back("records perturbed at read time (seed " + std::to_string(seed) +
                        "; the reference is not): " + std::to_string(dropped) + " scans dropped, " +
                        std::to_string(lost) + " odometry records removed in lost intervals");
}

namespace {

// Least squares of y = a x1 + b x2 with a, b >= 0 (no intercept): the normal equations, and
// the one-variable fit when the pair has a negative coefficient.
class RotationErrorFit {
 public:
  void Add(double x1, double x2, double y) {
    s11_ += x1 * x1;
    s12_ += x1 * x2;
    s22_ += x2 * x2;
    s1y_ += x1 * y;
    s2y_ += x2 * y;
  }
  std::pair<double, double> Solve() const {
    const double det = s11_ * s22_ - s12_ * s12_;
    if (det > 1e-12 * s11_ * s22_) {
      const double a = (s22_ * s1y_ - s12_ * s2y_) / det;
      const double b = (s11_ * s2y_ - s12_ * s1y_) / det;
      if (a >= 0.0 && b >= 0.0) return {a, b};
    }
    const double a = s11_ > 0.0 ? std::max(0.0, s1y_ / s11_) : 0.0;
    const double b = s22_ > 0.0 ? std::max(0.0, s2y_ / s22_) : 0.0;
    // The single term that explains more of sum y^2 (residual s_yy - coefficient * s_xy).
    if (a * s1y_ >= b * s2y_) return {a, 0.0};
    return {0.0, b};
  }

 private:
  double s11_ = 0.0, s12_ = 0.0, s22_ = 0.0, s1y_ = 0.0, s2y_ = 0.0;
};

}  // namespace

OdometryNoiseMeasurement MeasureOdometryNoise(const Dataset& data, const ScanSyncOptions& sync,
                                              const OdometryNoiseSpacing& spacing) {
  const ScanSyncResult synced = SyncToScans(data.records, sync);
  if (data.reference.size() != synced.scans.size()) {
    throw ParseError(data.source + ": " + std::to_string(data.reference.size()) +
                     " reference poses for " + std::to_string(synced.scans.size()) +
                     " scans; measuring odometry noise needs one reference pose per scan");
  }
  OdometryNoiseMeasurement m;
  double sum_e_t2 = 0.0, sum_e_r2 = 0.0, sum_t2 = 0.0, sum_r2 = 0.0, sum_dot = 0.0;
  double sum_r_dot = 0.0;
  RotationErrorFit fit;
  const bool every_scan = !(spacing.travel_m > 0.0 || spacing.turn_rad > 0.0);
  std::size_t last = 0;  // the last kept scan
  Pose2 u;               // the odometry from it
  for (std::size_t k = 1; k < synced.scans.size(); ++k) {
    u = every_scan ? synced.scans[k].increment : u * synced.scans[k].increment;
    const Pose2 g = data.reference[last].map_from_base.Between(data.reference[k].map_from_base);
    if (!every_scan && g.translation().norm() < spacing.travel_m &&
        std::abs(g.theta()) < spacing.turn_rad) {
      continue;
    }
    const Eigen::Vector2d e = u.translation() - g.translation();
    const double e_theta = NormalizeAngle(u.theta() - g.theta());
    sum_e_t2 += e.squaredNorm();
    sum_e_r2 += e_theta * e_theta;
    sum_t2 += g.translation().squaredNorm();
    sum_r2 += g.theta() * g.theta();
    sum_dot += u.translation().dot(g.translation());
    sum_r_dot += u.theta() * g.theta();
    fit.Add(g.translation().squaredNorm(), g.theta() * g.theta(), e_theta * e_theta);
    m.path_m += g.translation().norm();
    m.turn_rad += std::abs(g.theta());
    ++m.increments;
    last = k;
    u = Pose2();
  }
  if (m.increments == 0) throw ParseError(data.source + ": fewer than two scans to compare");
  const double n = m.increments;
  m.rms_translation_m = std::sqrt(sum_e_t2 / n);
  m.rms_rotation_rad = std::sqrt(sum_e_r2 / n);
  m.noise_per_m = sum_t2 > 0.0 ? std::sqrt(0.5 * sum_e_t2 / sum_t2) : 0.0;
  m.noise_per_rad = sum_r2 > 0.0 ? std::sqrt(sum_e_r2 / sum_r2) : 0.0;
  m.scale = sum_t2 > 0.0 ? sum_dot / sum_t2 : 1.0;
  m.rotation_scale = sum_r2 > 0.0 ? sum_r_dot / sum_r2 : 1.0;
  const auto [per_m2, per_rad2] = fit.Solve();
  m.rotation_per_m = std::sqrt(per_m2);
  m.rotation_per_rad = std::sqrt(per_rad2);
  return m;
}

}  // namespace slamrig::slam
