#include "scenarios/scenario_runner.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "scenarios/external_run.h"
#include "scenarios/external_stream.h"
#include "scenarios/live_view.h"
#include "scenarios/recording.h"
#include "scenarios/run_recorder.h"
#include "sim/camera/camera_rig.h"
#include "sim/simulator.h"
#include "slam/eval/landmark_score.h"
#include "slam/eval/loop_closure_score.h"
#include "slam/eval/map_score.h"
#include "slam/eval/nees.h"
#include "slam/eval/pose_association.h"
#include "slam/eval/recovery_time.h"
#include "slam/eval/trajectory_error.h"
#include "slam/eval/trajectory_metrics.h"
#include "slam/io/map_server.h"
#include "slam/pipeline/algorithm.h"
#include "slam/pipeline/estimator_runner.h"
#include "slam/pipeline/external_estimator.h"
#include "slam/types/error.h"
#include "slam/types/interrupt.h"
#include "slam/types/thread_pool.h"

namespace slamrig::scenario {
namespace {

// A kidnapped estimate counts as recovered once it stays this close to the true position: a
// kidnapping moves it metres, while an estimate on its track drifts ~0.1-0.3 m from the truth
// in the truth's own frame (no alignment) as its map bends (the office's pf, seeds 1-2).
constexpr double kRecoveredM = 0.5;

using Runners = std::vector<std::unique_ptr<slam::EstimatorRunner>>;

// Whether the estimators may each run on a thread of their own (the algorithm table says).
bool Concurrent(const Runners& runners) {
  return std::all_of(runners.begin(), runners.end(), [](const auto& r) {
    const slam::Algorithm* algorithm = slam::FindAlgorithm(r->config().algorithm);
    return algorithm != nullptr && algorithm->runs_beside_others;
  });
}

// A stream-mode external configuration's program, started and attached to its estimator.
void AttachStream(slam::EstimatorRunner& runner, const std::string& work_dir) {
  auto* external = dynamic_cast<slam::ExternalEstimator*>(&runner.estimator());
  if (external == nullptr || !external->streams()) return;
  external->Attach(
      std::make_unique<ExternalStreamSession>(runner.config().name, *external, work_dir));
}

Runners MakeRunners(const ScenarioSpec& spec, const std::vector<Record>* log_records,
                    const std::string& work_dir) {
  Runners runners;
  for (const slam::EstimatorConfig& config : spec.configs) {
    // A simulated robot always has wheel encoders; a log says what it has.
    const slam::OdometrySource source =
        log_records ? slam::ResolveOdometrySource(*log_records, config.odometry.source)
        : config.odometry.source == slam::OdometrySource::kAuto ? slam::OdometrySource::kWheelTicks
                                                                : config.odometry.source;
    runners.push_back(std::make_unique<slam::EstimatorRunner>(config, source, spec.seed));
    AttachStream(*runners.back(), work_dir);
  }
  return runners;
}

// The recording of a run (a file, a live view or both), when asked for: every configuration's scans
// go to it as they are taken, placed by the reference pose of the run's first scan
// (`map_from_start`, filled later).
std::unique_ptr<RunRecorder> MakeRecorder(const RunnerOptions& options, Runners& runners,
                                          const std::optional<Pose2>& map_from_start) {
  if (options.record_path.empty() && !options.live) return nullptr;
  std::vector<std::string> names;
  for (const auto& r : runners) names.push_back(r->config().name);
  RecorderOptions recording;
  const slam::EstimatorConfig& first = runners.front()->config();
  recording.odometry = slam::WheelOdometryOptions{first.odometry.robot, first.odometry.use_gyro};
  auto recorder =
      std::make_unique<RunRecorder>(options.record_path, names, recording, options.live);
  for (std::size_t i = 0; i < runners.size(); ++i) {
    slam::EstimatorRunner* runner = runners[i].get();
    RunRecorder* rec = recorder.get();
    runner->SetScanCallback([rec, runner, i, &map_from_start](std::size_t,
                                                              const slam::SyncedScan& scan,
                                                              const slam::ScanEstimate& estimate) {
      rec->Scan(i, scan.scan.time, estimate, runner->estimator(), map_from_start.value_or(Pose2()));
    });
  }
  return recorder;
}

bool InBlackout(const SimulatedSource& source, Time t) {
  const double s = t.seconds();
  for (const BlackoutFault& b : source.blackouts) {
    if (s >= b.from_s && s < b.to_s) return true;
  }
  return false;
}

// The live view: the map of the first estimator that has particles (the system under test),
// else the first one's, with every estimate and the truth.
void ShowLive(LiveView& view, double now_s, const Runners& runners, const Pose2& map_from_start,
              bool started, const Pose2& truth) {
  const slam::EstimatorRunner* shown = runners.front().get();
  bool shown_has_particles = !shown->estimator().View().particles.empty();
  std::vector<LiveEstimate> live;
  for (const auto& r : runners) {
    LiveEstimate e;
    e.name = r->config().name;
    e.has_pose = started && r->scans() > 0;
    e.pose = map_from_start * r->pose();
    const slam::EstimatorView extras = r->estimator().View();
    for (const slam::WeightedPose& p : extras.particles)
      e.particles.push_back(map_from_start * p.pose);
    for (const slam::ViewEdge& edge : extras.edges) {
      e.edges.push_back({map_from_start * edge.from, map_from_start * edge.to, edge.loop_closure});
    }
    const Eigen::Matrix2d rotation = map_from_start.Rotation();
    for (const slam::LandmarkEstimate& l : extras.landmarks) {
      e.landmarks.push_back(
          {map_from_start * l.position_m, rotation * l.covariance * rotation.transpose()});
    }
    if (extras.pose_covariance) {
      e.position_covariance =
          rotation * extras.pose_covariance->topLeftCorner<2, 2>() * rotation.transpose();
    }
    if (!extras.particles.empty() && !shown_has_particles) {
      shown = r.get();
      shown_has_particles = true;
    }
    live.push_back(std::move(e));
  }
  view.Update(now_s, shown->estimator().map(), map_from_start, truth, live);
}

// The NEES of the online poses that have a covariance, against the reference at the same time.
void ScoreNees(const ScenarioResult& run, ConfigResult* c) {
  slam::NeesSeries series =
      slam::PoseNeesSeries(c->online, c->run.covariances, c->map_from_estimator.theta(), run.truth);
  if (series.nees.empty()) return;
  c->nees_time_s = std::move(series.time_s);
  c->nees = std::move(series.nees);
  double sum = 0.0;
  for (double v : c->nees) sum += v;
  auto& m = c->metrics;
  m["mean_nees"] = sum / static_cast<double>(c->nees.size());
  m["final_nees"] = c->nees.back();
  // One run: NEES of a consistent 3-dof estimate lies in chi2_3's 95 % region.
  const slam::NeesBounds bounds = slam::AneesBounds(3, 1);
  m["nees_lower_95"] = bounds.lower;
  m["nees_upper_95"] = bounds.upper;
}

// A landmark within this distance of a true pillar can be that pillar (slam::ScoreLandmarks).
constexpr double kPillarMatchRadius = 0.5;

// A landmark estimator's map against the world's round pillars (its circles), in the map frame.
void ScoreLandmarks(const ScenarioResult& run, ConfigResult* c) {
  const slam::LandmarkMap& map = c->run.landmarks;
  std::vector<Eigen::Vector2d> pillars;
  for (const sim::ShapeSpec& shape : run.spec->simulated->options.world.walls)
    if (shape.type == sim::ShapeType::kCircle) pillars.push_back(shape.center_m);
  const Eigen::Matrix2d rotation = c->map_from_estimator.Rotation();
  std::vector<slam::ScoredLandmark> landmarks;
  for (const slam::LandmarkEstimate& l : map.landmarks) {
    landmarks.push_back(
        {c->map_from_estimator * l.position_m, rotation * l.covariance * rotation.transpose()});
  }
  std::vector<slam::ScoredSighting> sightings;
  for (const slam::LandmarkSighting& s : map.sightings)
    sightings.push_back({s.time, s.landmark, s.center_base_m});
  const slam::LandmarkScore score =
      slam::ScoreLandmarks(pillars, landmarks, sightings, run.truth, kPillarMatchRadius);
  auto& m = c->metrics;
  m["pillars"] = score.pillars;
  m["pillars_mapped"] = score.mapped;
  m["spurious_landmarks"] = score.spurious;
  m["landmark_error_max_m"] = score.error_max_m;
  m["landmark_error_mean_m"] = score.error_mean_m;
  m["landmark_anees"] = score.anees;
  if (score.anees_bounds) {
    m["landmark_anees_lower_95"] = score.anees_bounds->lower;
    m["landmark_anees_upper_95"] = score.anees_bounds->upper;
  }
  m["landmark_sightings"] = score.sightings;
  m["wrong_associations"] = score.wrong_associations;
}

// Loop closures against the reference: one reference pose per scan, in scan order.
void ScoreLoops(const ScenarioResult& run, ConfigResult* c) {
  if (run.truth.size() != c->estimate.size()) return;
  std::vector<Pose2> reference;
  for (const StampedPose& p : run.truth.poses()) reference.push_back(p.pose);
  const slam::LoopClosureScore loops = slam::ScoreLoopClosures(c->run.loop_closures, reference);
  c->metrics["loop_precision"] = loops.precision;
  c->metrics["loop_recall"] = loops.recall;
  c->metrics["false_loop_closures"] = loops.false_closures;
  c->loop_is_true = loops.is_true;
}

// Scores of one configuration: the metrics that apply to it (MetricsOf names), each from what
// this run has (a reference, kidnappings, the truth map, covariances, loop closures, pillars).
void Score(const ScenarioResult& run, double data_time_s, ConfigResult* c) {
  auto& m = c->metrics;
  const slam::Algorithm* algorithm = slam::FindAlgorithm(c->algorithm);
  m["scans"] = static_cast<double>(c->estimate.size());
  // Made-up stamps give a made-up duration: no real-time factor then.
  if (!run.times_synthesised)
    m["realtime_factor"] = c->run.wall_s > 0.0 ? data_time_s / c->run.wall_s : NAN;
  for (const auto& [name, value] : c->run.statistics) m[name] = value;
  // The estimator's own judgement: its runs of lost scans.
  if (c->run.judges_itself) {
    m["lost_intervals"] = static_cast<double>(c->run.lost_intervals.size());
    m["lost_s"] = slam::LostSeconds(c->run.lost_intervals);
  }
  if (c->estimate.size() < 2 || run.truth.size() < 2) return;
  const slam::TrajectoryMetrics t = slam::EvaluateTrajectory(c->estimate, run.truth);
  c->reference_from_estimate = t.ate.reference_from_estimate;
  m["ate_rmse_m"] = t.ate.translation_m.rmse;
  m["ate_mean_m"] = t.ate.translation_m.mean;
  m["ate_median_m"] = t.ate.translation_m.median;
  m["ate_max_m"] = t.ate.translation_m.max;
  m["ate_rot_rmse_rad"] = t.ate.rotation_rad.rmse;
  m["online_ate_rmse_m"] = slam::ComputeAte(c->online, run.truth).translation_m.rmse;
  if (c->mean_estimate.size() >= 2)
    m["mean_ate_rmse_m"] = slam::ComputeAte(c->mean_estimate, run.truth).translation_m.rmse;
  ScoreNees(run, c);
  if (algorithm && algorithm->maps_landmarks && run.spec->simulated) ScoreLandmarks(run, c);
  // Means of the pairs' translation errors; NaN when the run is too short for a spacing.
  const auto mean = [](const slam::ErrorStats& s) { return s.count ? s.mean : NAN; };
  m["rpe_m_per_scan"] = mean(t.rpe_per_scan.translation_m);
  m["rpe_m_per_1m"] = mean(t.rpe_1m.translation_m);
  m["rpe_m_per_10m"] = mean(t.rpe_10m.translation_m);
  m["rpe_rad_per_10m"] = mean(t.rpe_10m.rotation_rad);
  // The last pose against the reference at the same scan (same start pose, no alignment).
  const std::vector<slam::PosePair> pairs = slam::AssociatePoses(c->estimate, run.truth);
  if (!pairs.empty()) {
    m["final_error_m"] =
        (pairs.back().reference.translation() - pairs.back().estimate.translation()).norm();
    // From the truth, for any estimator: how long after each kidnapping until the estimate is
    // back within kRecoveredM of the true pose for good.
    if (!run.kidnap_times.empty()) {
      m["recovery_time_s"] = slam::WorstRecoveryTime(pairs, run.kidnap_times, kRecoveredM);
    }
  }
  if (algorithm && algorithm->closes_loops) ScoreLoops(run, c);
  if (run.truth_map && c->has_map) {
    // A simulation's map is scored where the estimate starts (on the truth); a log's reference
    // is itself an estimate, whose first pose is no better an anchor than any other, so there the
    // map is scored in the ATE alignment's frame.
    const Pose2 reference_from_map = run.spec->simulated
                                         ? c->map_from_estimator
                                         : t.ate.reference_from_estimate * c->map_from_estimator;
    const slam::MapScore score = slam::ScoreMap(c->run.map, reference_from_map, *run.truth_map);
    m["map_f1"] = score.f1;
    m["map_iou"] = score.iou;
    m["map_precision"] = score.precision;
    m["map_recall"] = score.recall;
  }
}

Trajectory InMapFrame(const Trajectory& t, const Pose2& map_from_estimator) {
  Trajectory out;
  for (const StampedPose& p : t.poses()) out.Append(p.time, map_from_estimator * p.pose);
  return out;
}

// The texture metrics of one texture map; `reference_psnr_db` (the truth's) gives the loss.
void ScoreTextureMetrics(const TextureResult& t, double reference_psnr_db,
                         std::map<std::string, double>* m) {
  (*m)["texture_psnr_db"] = t.score.psnr_db.value_or(NAN);
  (*m)["texture_mean_abs_error"] = t.score.mean_abs_error.value_or(NAN);
  (*m)["texture_coverage"] = t.score.coverage;
  (*m)["texture_frames"] = t.frames;
  if (std::isfinite(reference_psnr_db))
    (*m)["texture_psnr_loss_db"] = reference_psnr_db - t.score.psnr_db.value_or(NAN);
}

// The texture from the true poses (the `truth` pseudo-configuration), after checking that the
// camera saw the floor at all: a camera that never does is a configuration mistake, not a
// black map to score.
void ScoreTruthTexture(const ScenarioSpec& spec, const TextureRun& texture,
                       ScenarioResult* result) {
  if (texture.floor_pixels() == 0) {
    throw ConfigError(spec.path + ": robot.camera: " + std::to_string(texture.frames()) +
                      " frames and not one floor pixel within texture.max_depth_m (" +
                      std::to_string(texture.depth_readings()) +
                      " depth readings in all); is robot.camera.mount pointing at the floor?");
  }
  result->true_texture = texture.truth();
  result->truth_texture = texture.WithTruePoses();
  ScoreTextureMetrics(*result->truth_texture, NAN, &result->truth_metrics);
}

// A log without laser scans (wheel encoders and an IMU alone): an estimator's trajectory is the
// one it reports at its records' rate (dead reckoning and the EKF); others cannot run on it.
void UseRecordRate(const std::string& log_path, slam::EstimatorRun* run) {
  if (run->record_rate.empty()) {
    throw ParseError(log_path + ": no laser scans; " + run->algorithm +
                     " needs them (dead-reckoning and ekf run on wheel encoder records alone)");
  }
  run->final = run->online = run->record_rate;
  run->covariances = run->record_rate_covariances;
  run->odometry_source = slam::OdometrySource::kWheelTicks;
}

// What an external program's input files say besides the records.
ExternalSource ExternalSourceOf(const ScenarioSpec& spec) {
  ExternalSource source;
  if (spec.simulated) {
    source.carmen_params = CarmenLogParams(spec.simulated->options);
    source.ticks_per_revolution = spec.simulated->options.robot.encoders.ticks_per_revolution;
  }
  return source;
}

// An external configuration: its program runs on the records now, and its poses and map replace
// the in-process part's placeholders. False, with the failure in `result`, when the program or
// its output failed.
bool TakeExternal(const slam::ExternalEstimator& external, const std::string& work_dir,
                  const Pose2& map_from_start, ConfigResult* c, ScenarioResult* result) {
  if (external.streams()) {
    // Its poses came in lockstep and are the run's; its map and statistics the estimator's.
    const std::string failure = external.link()->failure();
    if (!failure.empty()) {
      result->failures.push_back({c->name, c->algorithm, failure});
      return false;
    }
    c->has_map = external.link()->map().has_value();
    if (!c->run.final.empty())
      c->map_from_estimator = map_from_start * c->run.final.poses().front().pose.Inverse();
    return true;
  }
  ExternalOutcome outcome =
      RunExternal(c->name, external, ExternalSourceOf(*result->spec), work_dir);
  if (!outcome.failure.empty()) {
    result->failures.push_back({c->name, c->algorithm, outcome.failure});
    return false;
  }
  c->run.online = outcome.poses;
  c->run.final = std::move(outcome.poses);
  c->has_map = outcome.map.has_value();
  if (outcome.map) c->run.map = std::move(*outcome.map);
  c->run.wall_s = outcome.child_wall_s;
  c->run.statistics = {{"peak_rss_mib", static_cast<double>(outcome.peak_rss_kb) / 1024.0},
                       {"input_write_s", outcome.input_write_s},
                       {"child_wall_s", outcome.child_wall_s}};
  // The program's frame is its own: placed so that its first pose is the reference pose at the
  // first scan, as every estimator's first pose is.
  if (!c->run.final.empty())
    c->map_from_estimator = map_from_start * c->run.final.poses().front().pose.Inverse();
  return true;
}

void Finish(Runners& runners, const Pose2& map_from_start, double data_time_s,
            const TextureRun* texture, const RunnerOptions& options, ScenarioResult* result) {
  if (texture) ScoreTruthTexture(*result->spec, *texture, result);
  const bool records_only = result->spec->log && result->scans == 0;
  // Every stream ends (its program exits) before an offline program starts.
  for (auto& r : runners) r->Finish();
  for (auto& r : runners) {
    ConfigResult c;
    c.name = r->config().name;
    c.algorithm = r->config().algorithm;
    c.map_from_estimator = map_from_start;
    const auto* external = dynamic_cast<const slam::ExternalEstimator*>(&r->estimator());
    c.run = r->TakeResult();
    if (records_only) UseRecordRate(result->spec->log->path, &c.run);
    if (external && !TakeExternal(*external, options.work_dir, map_from_start, &c, result))
      continue;
    c.estimate = InMapFrame(c.run.final, map_from_start);
    c.online = InMapFrame(c.run.online, map_from_start);
    c.mean_estimate = InMapFrame(c.run.mean, map_from_start);
    Score(*result, data_time_s, &c);
    if (texture) {
      // Scored in the frame ATE aligns the trajectory to (a map's frame is defined up to a rigid
      // motion), and as anchored at the start pose, which the other maps of a simulation use.
      c.texture = texture->WithAlignedPoses(c.estimate, result->truth);
      ScoreTextureMetrics(*c.texture, result->truth_metrics["texture_psnr_db"], &c.metrics);
      c.metrics["texture_psnr_anchored_db"] =
          texture->WithPoses(c.estimate).score.psnr_db.value_or(NAN);
      // Where the loss comes from: the error's slowly varying part (the map's distortion) and its
      // scan-to-scan jitter, each alone on the true poses; 1 s either side separates them.
      const auto [slow, jitter] = texture->WithErrorParts(c.estimate, result->truth, 1.0);
      const double truth_psnr = result->truth_metrics["texture_psnr_db"];
      c.metrics["texture_psnr_loss_slow_db"] = truth_psnr - slow.score.psnr_db.value_or(NAN);
      c.metrics["texture_psnr_loss_jitter_db"] = truth_psnr - jitter.score.psnr_db.value_or(NAN);
    }
    result->configs.push_back(std::move(c));
  }
  CheckExpectations(result);
}

ScenarioResult RunSimulated(const ScenarioSpec& spec, const RunnerOptions& options) {
  const SimulatedSource& source = *spec.simulated;
  ScenarioResult result;
  result.spec = &spec;
  sim::Simulator simulator(source.options);
  // A robot with a camera: its frames join the stream, and the texture side keeps their floor.
  std::optional<sim::CameraRig> rig;
  std::optional<TextureRun> texture;
  if (const auto& camera = source.options.robot.camera) {
    try {
      rig.emplace(&simulator, *camera, spec.seed);
    } catch (const ConfigError& e) {
      throw ConfigError(spec.path + ": robot.camera: " + e.what());
    } catch (const ParseError& e) {
      throw ParseError(spec.path + ": robot.camera: " + e.what());
    }
    const sim::FloorTexture& floor = rig->camera().floor();
    slam::TextureMapOptions layout = spec.texture;
    layout.min_m = floor.min_m();
    layout.max_m = floor.max_m();
    texture.emplace(layout, floor.TruthColors(layout), floor.FloorMask(layout));
  }
  Runners runners = MakeRunners(spec, nullptr, options.work_dir);
  std::optional<Pose2> map_from_start;  // true pose at the first scan SLAM sees
  std::unique_ptr<RunRecorder> recorder = MakeRecorder(options, runners, map_from_start);
  slam::OccupancyGrid truth_map{slam::OccupancyGridOptions{}};
  std::unique_ptr<LiveView> view;
  if (options.view) view = std::make_unique<LiveView>("slamrig: " + spec.name);
  // The live texture: each frame at the first configuration's latest pose (what it knows then).
  std::optional<slam::TextureMap> live_texture;
  if (view && texture) live_texture.emplace(texture->options());

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
        if (recorder) recorder->Truth(scan->time, truth);
        // The truth map: the noise-free ranges from the true poses, i.e. the world as the
        // lidar can see it, without the sensor's noise and outliers.
        truth_scan = *scan;
        if (sample.true_ranges_m.size() == scan->ranges_m.size())
          truth_scan.ranges_m = sample.true_ranges_m;
        truth_map.InsertScan(truth_scan, truth);
        if (InBlackout(source, scan->time)) {
          ++result.scans_blacked_out;
          continue;
        }
        if (!map_from_start) map_from_start = truth;
      } else if (const auto* frame = std::get_if<RgbdFrame>(&record)) {
        ++result.frames;
        texture->Add(*frame, step.truth[i].map_from_base);
        if (live_texture && map_from_start && runners.front()->scans() > 0) {
          live_texture->Insert(*frame, *map_from_start * runners.front()->pose());
        }
      }
      if (recorder) recorder->Record(record);
      for (auto& r : runners) r->Add(record);
    }
  };
  // A camera that sees nothing at some pose is one error naming the camera's key.
  auto step = [&](bool flush) {
    if (!rig) return flush ? simulator.Flush() : simulator.Step();
    try {
      return flush ? rig->Flush() : rig->Step();
    } catch (const ConfigError& e) {
      throw ConfigError(spec.path + ": robot.camera: " + e.what());
    }
  };

  while (simulator.time() < end && !simulator.drive_finished()) {
    ThrowIfInterrupted();
    if (next_kidnap < source.kidnaps.size() &&
        simulator.time().seconds() >= source.kidnaps[next_kidnap].at_s) {
      simulator.Teleport(source.kidnaps[next_kidnap++].to);
      ++result.kidnaps_done;
      result.kidnap_times.push_back(simulator.time());
    }
    consume(step(false));
    if (options.pace) options.pace(simulator.time());
    const double now_s = simulator.time().seconds();
    if (now_s >= next_progress_s) {
      next_progress_s = now_s + 1.0;
      if (options.progress) options.progress(now_s, spec.duration_s);
      if (view) {
        ShowLive(*view, now_s, runners, map_from_start.value_or(Pose2()),
                 map_from_start.has_value(), simulator.Truth().map_from_base);
        if (live_texture) view->ShowTexture(live_texture->Colors());
      }
    }
  }
  consume(step(true));
  result.sim_time_s = simulator.time().seconds();
  result.truth_map.emplace(std::move(truth_map));
  Finish(runners, map_from_start.value_or(Pose2()), result.sim_time_s,
         texture ? &*texture : nullptr, options, &result);
  if (recorder) {
    recorder->Finish(result);
    result.recording = options.record_path;
  }
  return result;
}

// The map a log's configurations are scored against: the true world's map when the source
// names one, else the log's scans at its reference poses (filled while the log runs).
std::optional<slam::OccupancyGrid> TrueMapOf(const LogSource& log, const slam::Dataset& data) {
  if (log.truth_map.empty()) return std::nullopt;
  if (data.reference.empty()) {
    throw ConfigError(log.truth_map + ": a true map is placed by the log's reference, and " +
                      log.path + " has none");
  }
  return slam::GridFromMapImage(slam::ReadMapServerMap(log.truth_map));
}

// The scans the run will take: the log's, up to the source's limit.
std::size_t ScansToRun(const LogSource& log, const std::vector<Record>& records) {
  std::size_t n = 0;
  for (const Record& r : records) n += std::holds_alternative<LaserScan>(r);
  return log.max_scans > 0 ? std::min(n, log.max_scans) : n;
}

// The estimators take `records` and the reference map its scans, each on a thread of its own
// where there are processors: they are independent of one another, so the results are the same
// in any order. `progress` hears every 100th scan of the first estimator.
void RunSideBySide(Runners& runners, std::span<const Record> records,
                   std::span<const std::pair<const LaserScan*, Pose2>> truth_map_scans,
                   slam::OccupancyGrid* truth_map, const std::function<void(Time)>& progress) {
  std::vector<std::function<void()>> tasks;
  tasks.emplace_back([&] {
    for (const auto& [scan, reference] : truth_map_scans) truth_map->InsertScan(*scan, reference);
  });
  for (std::size_t i = 0; !records.empty() && i < runners.size(); ++i) {
    tasks.emplace_back([&, i] {
      std::size_t scans = 0;
      for (const Record& record : records) {
        ThrowIfInterrupted();
        runners[i]->Add(record);
        if (i == 0 && progress && std::holds_alternative<LaserScan>(record) && ++scans % 100 == 0)
          progress(RecordTime(record));
      }
    });
  }
  slam::RunTasks(tasks, Concurrent(runners) ? slam::DefaultThreadCount() : 1);
}

ScenarioResult RunLog(const ScenarioSpec& spec, const RunnerOptions& options) {
  const LogSource& log = *spec.log;
  slam::Dataset data = slam::ReadLog(log.path, log.read);
  slam::ApplyLogPerturbation(&data, log.perturb, spec.seed, log.robot);
  std::optional<slam::OccupancyGrid> true_map = TrueMapOf(log, data);
  ScenarioResult result;
  result.spec = &spec;
  result.notes = data.notes;
  const bool said = std::any_of(result.notes.begin(), result.notes.end(), [](const std::string& n) {
    return n.rfind("no raw odometry", 0) == 0;
  });
  if (!said && slam::ResolveOdometrySource(data.records, slam::OdometrySource::kAuto) ==
                   slam::OdometrySource::kNone) {
    result.notes.push_back(
        "no odometry in the log: running without it (a scan-matched motion prior)");
  }
  result.truncated = data.truncated;
  result.log_format = data.format;
  result.times_synthesised = data.times_synthesised;
  if (!data.reference_kind.empty()) result.reference_kind = data.reference_kind;
  Runners runners = MakeRunners(spec, &data.records, options.work_dir);
  std::optional<Pose2> map_from_start;
  std::unique_ptr<RunRecorder> recorder = MakeRecorder(options, runners, map_from_start);
  if (options.on_scan) {
    const std::size_t total = ScansToRun(log, data.records);
    const slam::EstimatorRunner& first = *runners.front();
    RunRecorder* rec = recorder.get();
    runners.front()->SetScanCallback([&, rec, total](std::size_t i, const slam::SyncedScan& scan,
                                                     const slam::ScanEstimate& estimate) {
      if (rec)
        rec->Scan(0, scan.scan.time, estimate, first.estimator(), map_from_start.value_or(Pose2()));
      options.on_scan(i + 1, total, scan, first);
    });
  }
  std::unique_ptr<LiveView> view;
  if (options.view) view = std::make_unique<LiveView>("slamrig: " + spec.name);

  // The reference map: the log's scans at its reference poses, one per scan in order.
  slam::OccupancyGrid truth_map{slam::OccupancyGridOptions{}};
  std::vector<std::pair<const LaserScan*, Pose2>> truth_map_scans;
  std::optional<Time> first_time, last_time;
  std::size_t scans = 0;
  const bool limited = spec.has_duration;
  // Watched record by record (a recording or a live view of every estimator, a pace), the
  // estimators take each record in turn; else each takes them all on a thread of its own after
  // this loop (on_scan hears the first estimator's scans on that estimator's thread).
  const bool watched = recorder || view || options.pace;
  std::size_t end = 0;
  for (; end < data.records.size(); ++end) {
    const Record& record = data.records[end];
    const Time t = RecordTime(record);
    const bool is_scan = std::holds_alternative<LaserScan>(record);
    if (!first_time) first_time = t;
    if (limited && SecondsBetween(t, *first_time) > spec.duration_s) break;
    if (is_scan && log.max_scans > 0 && scans >= log.max_scans) break;
    ThrowIfInterrupted();
    if (const auto* scan = std::get_if<LaserScan>(&record)) {
      if (scans < data.reference.size()) {
        const Pose2& reference = data.reference[scans].map_from_base;
        result.truth.Append(data.reference[scans].time, reference);
        if (recorder) recorder->Truth(data.reference[scans].time, reference);
        if (!true_map) truth_map_scans.emplace_back(scan, reference);
        if (!map_from_start) map_from_start = reference;
      }
      ++scans;
      ++result.scans;
    } else if (std::holds_alternative<RgbdFrame>(record)) {
      ++result.frames;  // a log's frames have no true floor to be scored against
    }
    last_time = last_time ? std::max(*last_time, t) : t;
    if (!watched) continue;
    if (recorder) recorder->Record(record);
    for (auto& r : runners) r->Add(record);
    if (options.pace) options.pace(t);
    if (view && is_scan) {
      ShowLive(*view, SecondsBetween(t, *first_time), runners, map_from_start.value_or(Pose2()),
               true, map_from_start.value_or(Pose2()));
    }
    if (options.progress && is_scan && scans % 100 == 0) {
      options.progress(SecondsBetween(t, *first_time), spec.duration_s);
    }
  }
  std::function<void(Time)> progress;
  if (options.progress) {
    progress = [&](Time t) { options.progress(SecondsBetween(t, *first_time), spec.duration_s); };
  }
  RunSideBySide(runners, std::span(data.records).first(watched ? 0 : end), truth_map_scans,
                &truth_map, progress);
  if (result.scans == 0) {
    // Scored over the whole reference: no scan to pair reference poses with.
    for (const GroundTruthPose& g : data.reference) result.truth.Append(g.time, g.map_from_base);
  }
  if (result.truth.out_of_order() > 0) {
    result.notes.push_back(std::to_string(result.truth.out_of_order()) +
                           " reference poses are stamped earlier than the one before them; each "
                           "keeps its own scan's stamp, in scan order");
  }
  result.sim_time_s = first_time ? SecondsBetween(*last_time, *first_time) : 0.0;
  if (true_map) {
    result.truth_map = std::move(true_map);
  } else if (!data.reference.empty() && result.scans > 0) {
    result.truth_map.emplace(std::move(truth_map));
  }
  // A log without a reference is scored on nothing but its own statistics.
  Finish(runners, map_from_start.value_or(Pose2()), result.sim_time_s, nullptr, options, &result);
  if (recorder) {
    recorder->Finish(result);
    result.recording = options.record_path;
  }
  return result;
}

}  // namespace

ScenarioResult RunScenario(const ScenarioSpec& spec, const RunnerOptions& options) {
  for (const slam::EstimatorConfig& config : spec.configs) {
    if (config.algorithm == "external" && options.work_dir.empty()) {
      throw ConfigError(spec.path + ": slam." + config.name +
                        ": algorithm external runs its program in the report folder, and this "
                        "command writes none");
    }
  }
  return spec.simulated ? RunSimulated(spec, options) : RunLog(spec, options);
}

}  // namespace slamrig::scenario
