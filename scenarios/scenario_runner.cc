#include "scenarios/scenario_runner.h"

#include <chrono>
#include <cmath>
#include <memory>
#include <optional>

#include "scenarios/live_view.h"
#include "sim/simulator.h"
#include "slam/eval/map_score.h"
#include "slam/eval/trajectory_metrics.h"
#include "slam/odometry/scan_sync.h"
#include "slam/pf/particle_filter.h"

namespace slamrig::scenario {
namespace {

using Clock = std::chrono::steady_clock;

// One SLAM configuration running alongside the simulator.
class Estimator {
 public:
  explicit Estimator(const SlamConfig& config)
      : config_(config), sync_(config.sync, Resolve(config.sync.source)) {
    result_.name = config.name;
    result_.algorithm = config.algorithm;
    if (config.algorithm == SlamAlgorithm::kParticleFilter) {
      pf_ = std::make_unique<slam::ParticleFilter>(config.pf);
    } else {
      map_.emplace(config.map);
    }
  }

  // Feeds one record; `map_from_start` places the estimator's frame (its first scan's pose) in
  // the map frame, so that trajectories start on the truth.
  void Add(const Record& record, const std::optional<Pose2>& map_from_start) {
    const auto start = Clock::now();
    for (const slam::SyncedScan& s : sync_.Add(record)) Process(s, map_from_start);
    wall_s_ += std::chrono::duration<double>(Clock::now() - start).count();
  }
  void Flush(const std::optional<Pose2>& map_from_start) {
    const auto start = Clock::now();
    for (const slam::SyncedScan& s : sync_.Flush()) Process(s, map_from_start);
    wall_s_ += std::chrono::duration<double>(Clock::now() - start).count();
  }

  const std::string& name() const { return config_.name; }
  bool started() const { return started_; }
  const Pose2& map_from_start() const { return map_from_start_; }
  bool is_particle_filter() const { return pf_ != nullptr; }
  const Pose2& pose() const { return last_pose_; }
  const slam::OccupancyGrid& map() const { return pf_ ? pf_->map() : *map_; }
  std::vector<Pose2> Particles() const {
    std::vector<Pose2> poses;
    if (pf_) {
      for (const auto& p : pf_->particles()) poses.push_back(map_from_start_ * p.pose);
    }
    return poses;
  }
  double wall_s() const { return wall_s_; }
  int resamples() const { return pf_ ? pf_->resample_count() : 0; }

  ConfigResult TakeResult() {
    result_.map.emplace(map());
    result_.map_from_estimator = map_from_start_;
    return std::move(result_);
  }

 private:
  static slam::OdometrySource Resolve(slam::OdometrySource s) {
    // The simulated robot always has wheel encoders.
    return s == slam::OdometrySource::kAuto ? slam::OdometrySource::kWheelTicks : s;
  }

  void Process(const slam::SyncedScan& s, const std::optional<Pose2>& map_from_start) {
    if (!started_) {
      map_from_start_ = map_from_start.value_or(Pose2());
      started_ = true;
    }
    Pose2 estimate, mean;
    if (pf_) {
      const slam::ParticleFilterStep step = pf_->AddScan(s.scan, s.increment);
      estimate = step.best_pose;
      mean = step.mean_pose;
      result_.neff_time_s.push_back(s.scan.time.seconds());
      result_.neff.push_back(step.neff);
    } else {
      dead_reckoning_ = dead_reckoning_ * s.increment;
      estimate = mean = dead_reckoning_;
      map_->InsertScan(s.scan, dead_reckoning_);
    }
    last_pose_ = map_from_start_ * estimate;
    result_.estimate.Append(s.scan.time, last_pose_);
    result_.mean_estimate.Append(s.scan.time, map_from_start_ * mean);
  }

  SlamConfig config_;
  slam::ScanSynchronizer sync_;
  std::unique_ptr<slam::ParticleFilter> pf_;
  std::optional<slam::OccupancyGrid> map_;  // dead reckoning's
  Pose2 dead_reckoning_;
  Pose2 map_from_start_;
  Pose2 last_pose_;
  bool started_ = false;
  double wall_s_ = 0.0;
  ConfigResult result_;
};

bool InBlackout(const ScenarioSpec& spec, Time t) {
  const double s = t.seconds();
  for (const BlackoutFault& b : spec.blackouts) {
    if (s >= b.from_s && s < b.to_s) return true;
  }
  return false;
}

void Score(const ScenarioResult& run, double sim_time_s, double wall_s, int resamples,
           ConfigResult* c) {
  auto& m = c->metrics;
  m["scans"] = static_cast<double>(c->estimate.size());
  m["realtime_factor"] = wall_s > 0.0 ? sim_time_s / wall_s : NAN;
  if (c->algorithm == SlamAlgorithm::kParticleFilter) {
    double sum = 0.0;
    for (const double n : c->neff) sum += n;
    m["mean_neff"] = c->neff.empty() ? NAN : sum / static_cast<double>(c->neff.size());
    m["resamples"] = resamples;
  }
  if (c->estimate.size() < 2) return;
  const slam::TrajectoryMetrics t = slam::EvaluateTrajectory(c->estimate, run.truth);
  m["ate_rmse_m"] = t.ate.translation_m.rmse;
  m["ate_mean_m"] = t.ate.translation_m.mean;
  m["ate_median_m"] = t.ate.translation_m.median;
  m["ate_max_m"] = t.ate.translation_m.max;
  m["ate_rot_rmse_rad"] = t.ate.rotation_rad.rmse;
  // Means of the pairs' translation errors; NaN when the run is too short for a spacing.
  const auto mean = [](const slam::ErrorStats& s) { return s.count ? s.mean : NAN; };
  m["rpe_m_per_scan"] = mean(t.rpe_per_scan.translation_m);
  m["rpe_m_per_1m"] = mean(t.rpe_1m.translation_m);
  m["rpe_m_per_10m"] = mean(t.rpe_10m.translation_m);
  m["rpe_rad_per_10m"] = mean(t.rpe_10m.rotation_rad);
  const StampedPose& last = c->estimate.poses().back();
  if (const auto truth = run.truth.Interpolate(last.time)) {
    m["final_error_m"] = (truth->translation() - last.pose.translation()).norm();
  }
}

}  // namespace

ScenarioResult RunScenario(const ScenarioSpec& spec, const RunnerOptions& options) {
  ScenarioResult result;
  result.spec = &spec;
  sim::Simulator simulator(spec.sim);
  std::vector<std::unique_ptr<Estimator>> estimators;
  for (const SlamConfig& config : spec.slam)
    estimators.push_back(std::make_unique<Estimator>(config));
  slam::OccupancyGrid truth_map{slam::OccupancyGridOptions{}};
  std::unique_ptr<LiveView> view;
  if (options.view) view = std::make_unique<LiveView>("slamrig: " + spec.name);

  std::optional<Pose2> map_from_start;  // true pose at the first scan SLAM sees
  LaserScan truth_scan;
  std::size_t next_kidnap = 0;
  double next_progress_s = 0.0;
  const Time end = Time::FromSeconds(spec.duration_s);
  auto consume = [&](const sim::StepResult& step) {
    for (std::size_t i = 0; i < step.records.size(); ++i) {
      const Record& record = step.records[i];
      if (const auto* scan = std::get_if<LaserScan>(&record)) {
        const sim::TruthSample& sample = step.truth[i];
        const Pose2& truth = sample.map_from_base;
        ++result.scans;
        result.truth.Append(scan->time, truth);
        // The truth map: the noise-free ranges from the true poses, i.e. the world as the
        // lidar can see it, without the sensor's noise and outliers.
        truth_scan = *scan;
        if (sample.true_ranges_m.size() == scan->ranges_m.size())
          truth_scan.ranges_m = sample.true_ranges_m;
        truth_map.InsertScan(truth_scan, truth);
        if (InBlackout(spec, scan->time)) {
          ++result.scans_blacked_out;
          continue;
        }
        if (!map_from_start) map_from_start = truth;
      }
      for (auto& e : estimators) e->Add(record, map_from_start);
    }
  };

  while (simulator.time() < end && !simulator.drive_finished()) {
    if (next_kidnap < spec.kidnaps.size() &&
        simulator.time().seconds() >= spec.kidnaps[next_kidnap].at_s) {
      simulator.Teleport(spec.kidnaps[next_kidnap++].to);
      ++result.kidnaps_done;
    }
    consume(simulator.Step());
    const double now_s = simulator.time().seconds();
    if (now_s >= next_progress_s) {
      next_progress_s = now_s + 1.0;
      if (options.progress) options.progress(now_s, spec.duration_s);
      if (view) {
        std::vector<LiveEstimate> live;
        // The map of the first particle filter (the system under test), else the first one's.
        const Estimator* shown = estimators.front().get();
        for (const auto& e : estimators) {
          live.push_back({e->name(), e->started(), e->pose(), e->Particles()});
          if (e->is_particle_filter() && !shown->is_particle_filter()) shown = e.get();
        }
        view->Update(now_s, shown->map(), shown->map_from_start(), simulator.Truth().map_from_base,
                     live);
      }
    }
  }
  consume(simulator.Flush());
  for (auto& e : estimators) e->Flush(map_from_start);
  result.sim_time_s = simulator.time().seconds();
  result.truth_map.emplace(std::move(truth_map));

  for (auto& e : estimators) {
    const double wall_s = e->wall_s();
    const int resamples = e->resamples();
    ConfigResult c = e->TakeResult();
    Score(result, result.sim_time_s, wall_s, resamples, &c);
    // Map scores: the estimate's map against the truth map, in the truth's frame.
    const slam::MapScore score = slam::ScoreMap(*c.map, c.map_from_estimator, *result.truth_map);
    c.metrics["map_f1"] = score.f1;
    c.metrics["map_iou"] = score.iou;
    c.metrics["map_precision"] = score.precision;
    c.metrics["map_recall"] = score.recall;
    result.configs.push_back(std::move(c));
  }
  CheckExpectations(&result);
  return result;
}

}  // namespace slamrig::scenario
