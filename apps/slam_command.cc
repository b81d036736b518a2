// `slamrig slam LOG --algorithm dead-reckoning|pf --out DIR`: SLAM on a CARMEN log (a real one or
// one written by `slamrig simulate`) or an ECE276A robot log, scored against the log's reference
// when it has one.

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>

#include "apps/cli_args.h"
#include "apps/commands.h"
#include "apps/data_path.h"
#include "slam/eval/json_writer.h"
#include "slam/eval/map_score.h"
#include "slam/eval/run_timing.h"
#include "slam/eval/trajectory_metrics.h"
#include "slam/io/atomic_file.h"
#include "slam/io/bag/bag_reader.h"
#include "slam/io/carmen_reader.h"
#include "slam/io/dataset.h"
#include "slam/io/ece276a_reader.h"
#include "slam/io/map_image.h"
#include "slam/io/map_server.h"
#include "slam/io/tum_io.h"
#include "slam/odometry/scan_sync.h"
#include "slam/odometry/wheel_odometry.h"
#include "slam/pf/slam_run.h"
#include "slam/types/error.h"

namespace slamrig::app {
namespace {

using Clock = std::chrono::steady_clock;

std::string Fixed(double v, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*f", digits, v);
  return buffer;
}

slam::Dataset LoadLog(const std::string& path, bool lenient, std::string* kind) {
  if (slam::LooksLikeBag(path)) {
    *kind = "ros2 bag";
    return slam::ReadBag(path);  // wheel ticks with the ticks per revolution the bag records
  }
  if (slam::LooksLikeEce276a(path)) {
    *kind = "ece276a";
    return slam::ReadEce276a(slam::FindEce276aFiles(path));
  }
  *kind = "carmen";
  slam::CarmenReadOptions options;
  options.lenient = lenient;
  return slam::CarmenToDataset(slam::ReadCarmenLog(path, options));
}

const char* SourceName(slam::OdometrySource s) {
  switch (s) {
    case slam::OdometrySource::kWheelTicks:
      return "wheel_ticks";
    case slam::OdometrySource::kOdometryPoses:
      return "poses";
    case slam::OdometrySource::kNone:
      return "none";
    case slam::OdometrySource::kAuto:
      break;
  }
  return "auto";
}

// Dead reckoning straight from the encoders (and gyro), one pose per encoder record: for logs
// without a lidar, such as the shared ECE276A data.
Trajectory EncoderDeadReckoning(const std::vector<Record>& records,
                                const slam::ScanSyncOptions& sync) {
  slam::WheelOdometryOptions options;
  options.robot = sync.robot;
  options.use_gyro = sync.use_gyro;
  slam::WheelOdometry odometry(options);
  Trajectory trajectory;
  for (const Record& r : records) {
    if (const auto* imu = std::get_if<ImuSample>(&r)) odometry.AddImu(*imu);
    if (const auto* ticks = std::get_if<WheelTicks>(&r)) {
      const OdometryPose p = odometry.AddTicks(*ticks);
      if (trajectory.empty() || trajectory.poses().back().time <= p.time)
        trajectory.Append(p.time, p.odom_from_base);
    }
  }
  return trajectory;
}

// Progress on stderr, at most every two seconds, for logs that take a while.
class Progress {
 public:
  explicit Progress(bool enabled)
      : enabled_(enabled), start_(Clock::now()), next_(start_ + std::chrono::seconds(2)) {}
  void operator()(std::size_t done, std::size_t total) {
    if (!enabled_) return;
    const auto now = Clock::now();
    if (now < next_ && done < total) return;
    next_ = now + std::chrono::seconds(2);
    const double s = std::chrono::duration<double>(now - start_).count();
    std::fprintf(
        stderr, "\rslam: %zu/%zu scans (%.0f%%), %.1f s", done, total,
        100.0 * static_cast<double>(done) / static_cast<double>(std::max<std::size_t>(total, 1)),
        s);
    if (done == total) std::fputc('\n', stderr);
    std::fflush(stderr);
    printed_ = true;
  }

 private:
  bool enabled_;
  bool printed_ = false;
  Clock::time_point start_, next_;
};

std::string CloudsCsv(const std::vector<slam::ParticleCloud>& clouds) {
  std::string out = "# time_s,particle,x_m,y_m,yaw_rad,weight\n";
  char line[160];
  for (const slam::ParticleCloud& c : clouds) {
    for (std::size_t i = 0; i < c.particles.size(); ++i) {
      const slam::Particle& p = c.particles[i];
      std::snprintf(line, sizeof(line), "%.9f,%zu,%.6f,%.6f,%.6f,%.9g\n", c.time.seconds(), i,
                    p.pose.x(), p.pose.y(), p.pose.theta(), p.weight);
      out += line;
    }
  }
  return out;
}

void WriteMapScore(slam::JsonWriter& json, const std::string& key, const slam::MapScore& s) {
  json.BeginObject(key)
      .Integer("estimate_occupied", s.estimate_occupied)
      .Integer("truth_occupied", s.truth_occupied)
      .Number("precision", s.precision)
      .Number("recall", s.recall)
      .Number("f1", s.f1)
      .Number("iou", s.iou)
      .EndObject();
}

void WritePfConfig(slam::JsonWriter& json, const slam::ParticleFilterOptions& pf) {
  json.BeginObject("pf")
      .Integer("num_particles", pf.num_particles)
      .Integer("seed", static_cast<long long>(pf.seed))
      .String("motion_noise", pf.motion_noise == slam::MotionNoiseModel::kRotTransRot
                                  ? "rot_trans_rot"
                                  : "gaussian")
      .Number("sigma_xy_m", pf.sigma_xy_m)
      .Number("sigma_yaw_rad", pf.sigma_yaw_rad)
      .Number("alpha1", pf.rot_trans_rot.alpha1)
      .Number("alpha2", pf.rot_trans_rot.alpha2)
      .Number("alpha3", pf.rot_trans_rot.alpha3)
      .Number("alpha4", pf.rot_trans_rot.alpha4)
      .String("observation", pf.observation == slam::ObservationModel::kLikelihoodField
                                 ? "likelihood_field"
                                 : "correlation")
      .Integer("xy_half_width_cells", pf.correlation.xy_half_width_cells)
      .Integer("yaw_half_steps", pf.correlation.yaw_half_steps)
      .Number("yaw_step_rad", pf.correlation.yaw_step_rad)
      .Number("likelihood_sigma_m", pf.likelihood_field.sigma_m)
      .Number("observation_scale", pf.observation_scale)
      .Integer("beam_stride", pf.points.beam_stride)
      .Number("voxel_size_m", pf.points.voxel_size_m)
      .Bool("move_to_best_shift", pf.move_to_best_shift)
      .Bool("refine", pf.refine)
      .String("resampling",
              pf.resampling == slam::ResamplingScheme::kSystematic ? "systematic" : "stratified")
      .Number("resample_neff_ratio", pf.resample_neff_ratio)
      .Integer("threads", pf.num_threads)
      .EndObject();
}

}  // namespace

int RunSlamCommand(const std::vector<std::string>& args) {
  std::string log_path, out_dir, algorithm = "pf", preset = "default", odometry = "auto";
  std::string truth_map_path;
  int particles = 100, threads = 1, clouds = 0, max_scans = 0;
  std::uint64_t seed = 1;
  double resolution = 0.05;
  bool no_gyro = false, lenient = false, quiet = false;
  ArgParser parser(
      "slamrig slam", "LOG --out DIR [options]",
      "Runs dead reckoning or particle-filter SLAM on a log and writes, into DIR:\n"
      "trajectory.tum (one pose per scan, stamped with the scan time), map.pgm +\n"
      "map.yaml (ROS map_server), map.png (with the reference trajectory when the log\n"
      "has one) and metrics.json (ATE/RPE against the reference, timing, settings).\n"
      "LOG is a CARMEN log (plain or .gz; real, or written by `slamrig simulate`), a ROS 2\n"
      "bag (MCAP or sqlite3 folder or file: /scan, /imu, /joint_states, /odom,\n"
      "/ground_truth/odom) or an ECE276A dataset (DIR/20, or one of its\n"
      "Encoders/Imu/Hokuyo files).");
  parser.AddPositional("LOG", "log path; a path, or relative to SLAMRIG_DATA_DIR", &log_path);
  parser.AddOption("out", "DIR", "output folder (created)", &out_dir);
  parser.AddOption("algorithm", "NAME", "pf or dead-reckoning", &algorithm);
  parser.AddOption("preset", "NAME",
                   "pf settings: default (the improved filter) or reports (ECE276A)", &preset);
  parser.AddOption("particles", "N", "number of particles", &particles);
  parser.AddOption("seed", "N", "random seed (same seed, same result)", &seed);
  parser.AddOption("threads", "N", "worker threads for the particle scoring", &threads);
  parser.AddOption("resolution", "M", "map cell size in metres", &resolution);
  parser.AddOption("odometry", "SOURCE", "auto, wheel_ticks, poses or none", &odometry);
  parser.AddFlag("no-gyro", "yaw from the wheel encoders even when the log has a gyro", &no_gyro);
  parser.AddOption("clouds", "N",
                   "write the particle cloud every N scans to particles.csv (0: never)", &clouds);
  parser.AddOption("max-scans", "N", "stop after N scans (0: all)", &max_scans);
  parser.AddOption("truth-map", "YAML",
                   "map_server map of the true world: occupied-cell F1/IoU of the estimated map "
                   "(aligned by the ATE alignment; needs a log with a reference)",
                   &truth_map_path);
  parser.AddFlag("lenient", "skip and count malformed CARMEN lines instead of failing", &lenient);
  parser.AddFlag("quiet", "no progress output", &quiet);
  if (!parser.Parse(args)) return 0;
  if (out_dir.empty()) throw ConfigError("slamrig slam: --out DIR is required");
  if (algorithm != "pf" && algorithm != "dead-reckoning") {
    throw ConfigError("slamrig slam: --algorithm: expected pf or dead-reckoning, got '" +
                      algorithm + "'");
  }
  if (preset != "default" && preset != "reports") {
    throw ConfigError("slamrig slam: --preset: expected default or reports, got '" + preset + "'");
  }
  if (max_scans < 0)
    throw ConfigError("slamrig slam: --max-scans = " + std::to_string(max_scans) +
                      "; must be >= 0");
  slam::ParticleFilterOptions pf = preset == "reports"
                                       ? slam::ParticleFilterOptions::ReportsPreset()
                                       : slam::ParticleFilterOptions{};
  pf.num_particles = particles;
  pf.seed = seed;
  pf.num_threads = threads;
  pf.map.resolution_m = resolution;
  pf.cloud_every_n_scans = clouds;
  for (const std::string& e : pf.Validate()) throw ConfigError("slamrig slam: " + e);
  slam::ScanSyncOptions sync;
  sync.use_gyro = !no_gyro;
  const std::map<std::string, slam::OdometrySource> sources = {
      {"auto", slam::OdometrySource::kAuto},
      {"wheel_ticks", slam::OdometrySource::kWheelTicks},
      {"poses", slam::OdometrySource::kOdometryPoses},
      {"none", slam::OdometrySource::kNone}};
  if (!sources.count(odometry)) {
    throw ConfigError("slamrig slam: --odometry: expected auto, wheel_ticks, poses or none, got '" +
                      odometry + "'");
  }
  sync.source = sources.at(odometry);

  // Read and run everything before creating any output, so bad input leaves nothing behind.
  std::string path = ResolveDataPath(log_path);
  // An ECE276A dataset named by folder and number ("ece276a_pr2_partial/20") is no file itself.
  if (!std::filesystem::exists(path) && !slam::LooksLikeEce276a(path) &&
      slam::LooksLikeEce276a((std::filesystem::path(DataDir()) / log_path).string())) {
    path = (std::filesystem::path(DataDir()) / log_path).string();
  }
  std::string kind;
  const slam::Dataset data = LoadLog(path, lenient, &kind);
  slam::ScanSyncResult synced = slam::SyncToScans(data.records, sync);
  if (max_scans > 0 && synced.scans.size() > static_cast<std::size_t>(max_scans)) {
    synced.scans.resize(static_cast<std::size_t>(max_scans));
  }
  Trajectory reference;
  for (const GroundTruthPose& g : data.reference) {
    if (reference.empty() || reference.poses().back().time <= g.time)
      reference.Append(g.time, g.map_from_base);
  }
  const std::string log_name = std::filesystem::path(path).filename().string();
  std::optional<slam::OccupancyGrid> truth_map;
  if (!truth_map_path.empty()) {
    if (reference.empty()) {
      throw ConfigError("slamrig slam: --truth-map needs a log with a reference trajectory");
    }
    truth_map = slam::GridFromMapImage(slam::ReadMapServerMap(truth_map_path));
  }

  slam::SlamRunResult run;
  slam::RunTiming timing;
  const auto start = Clock::now();
  Progress progress(!quiet);
  bool encoder_only = false;
  if (synced.scans.empty()) {
    if (algorithm == "pf")
      throw ParseError(path + ": no laser scans; the particle filter needs them");
    run.trajectory = EncoderDeadReckoning(data.records, sync);
    if (run.trajectory.empty())
      throw ParseError(path + ": no laser scans and no wheel encoder records");
    run.mean_trajectory = run.trajectory;
    encoder_only = true;
  } else if (algorithm == "pf") {
    run = slam::RunParticleFilter(synced.scans, pf,
                                  [&](std::size_t d, std::size_t t) { progress(d, t); });
  } else {
    run = slam::RunDeadReckoning(synced.scans, pf.map,
                                 [&](std::size_t d, std::size_t t) { progress(d, t); });
  }
  timing.wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  timing.scans = static_cast<int>(synced.scans.size());
  if (run.trajectory.size() >= 2) {
    timing.data_s =
        SecondsBetween(run.trajectory.poses().back().time, run.trajectory.poses().front().time);
  }

  // Scores against the reference, with dead reckoning alongside for comparison.
  std::optional<slam::TrajectoryMetrics> metrics, mean_metrics, dr_metrics;
  if (!reference.empty()) {
    metrics = slam::EvaluateTrajectory(run.trajectory, reference);
    if (algorithm == "pf") {
      mean_metrics = slam::EvaluateTrajectory(run.mean_trajectory, reference);
      const slam::SlamRunResult dr = slam::RunDeadReckoning(synced.scans, pf.map);
      dr_metrics = slam::EvaluateTrajectory(dr.trajectory, reference);
    }
  }
  // Map scores: against the same scans inserted at the reference poses, and against the true
  // world's map when given, both in the reference frame through the ATE alignment.
  std::optional<slam::MapScore> map_vs_reference, map_vs_truth;
  if (metrics && !encoder_only) {
    slam::OccupancyGrid reference_map(pf.map);
    for (const slam::SyncedScan& s : synced.scans) {
      if (const std::optional<Pose2> p = reference.Interpolate(s.scan.time)) {
        reference_map.InsertScan(s.scan, *p);
      }
    }
    map_vs_reference = slam::ScoreMap(run.map, metrics->ate.reference_from_estimate, reference_map);
    if (truth_map) {
      map_vs_truth = slam::ScoreMap(run.map, metrics->ate.reference_from_estimate, *truth_map);
    }
  }

  std::filesystem::create_directories(out_dir);
  const std::string dir = out_dir + "/";
  slam::WriteTum(dir + "trajectory.tum", run.trajectory);
  if (algorithm == "pf") slam::WriteTum(dir + "trajectory_mean.tum", run.mean_trajectory);
  if (!reference.empty()) slam::WriteTum(dir + "reference.tum", reference);
  if (!run.clouds.empty()) slam::WriteFileAtomically(dir + "particles.csv", CloudsCsv(run.clouds));
  if (!encoder_only) {
    slam::WriteMapServerMap(run.map, dir + "map");
    // The reference drawn in the estimator's frame: the inverse of the ATE alignment.
    Trajectory reference_in_map;
    if (metrics) {
      const Pose2 map_from_reference = metrics->ate.reference_from_estimate.Inverse();
      for (const StampedPose& p : reference.poses())
        reference_in_map.Append(p.time, map_from_reference * p.pose);
    }
    std::vector<slam::TrajectoryOverlay> overlays;
    if (!reference_in_map.empty())
      overlays.push_back({&reference_in_map,
                          data.reference_kind.empty() ? "reference" : data.reference_kind, 40, 160,
                          40});
    overlays.push_back({&run.trajectory,
                        algorithm == "pf" ? "particle filter (best particle)" : "dead reckoning",
                        200, 60, 0});
    slam::MapImageOptions image_options;
    image_options.title = log_name + ": " + algorithm;
    slam::WriteMapPng(dir + "map.png", run.map, overlays, image_options);
  }

  slam::JsonWriter json;
  json.String("log", path).String("log_format", kind).String("algorithm", algorithm);
  if (algorithm == "pf") json.String("preset", preset);
  json.String("odometry_source", encoder_only ? "wheel_ticks (encoder records, no scans)"
                                              : SourceName(synced.source_used))
      .Integer("scans", timing.scans)
      .Integer("poses", static_cast<long long>(run.trajectory.size()))
      .Number("wall_time_s", timing.wall_s)
      .Number("data_time_s", timing.data_s)
      .Number("real_time_factor", timing.RealTimeFactor())
      .Number("ms_per_scan", timing.MillisecondsPerScan())
      .Integer("gyro_fallbacks", synced.gyro_fallbacks)
      .Integer("scans_without_odometry", synced.scans_without_odometry)
      .Integer("reordered_stamps", run.reordered_stamps);
  if (algorithm == "pf") {
    json.Integer("resamples", run.resamples).Number("mean_neff", run.mean_neff);
    WritePfConfig(json, pf);
  }
  json.BeginObject("map")
      .Number("resolution_m", run.map.resolution())
      .Integer("width", run.map.width())
      .Integer("height", run.map.height())
      .EndObject();
  if (metrics) {
    json.String("reference", data.reference_kind.empty() ? "reference" : data.reference_kind);
    json.BeginObject("trajectory");
    slam::WriteTrajectoryMetrics(json, *metrics);
    json.EndObject();
    if (mean_metrics) {
      json.BeginObject("mean_trajectory");
      slam::WriteTrajectoryMetrics(json, *mean_metrics);
      json.EndObject();
    }
    if (dr_metrics) {
      json.BeginObject("dead_reckoning");
      slam::WriteTrajectoryMetrics(json, *dr_metrics);
      json.EndObject();
    }
  }
  if (map_vs_reference) WriteMapScore(json, "map_vs_reference", *map_vs_reference);
  if (map_vs_truth) WriteMapScore(json, "map_vs_truth", *map_vs_truth);
  json.StringArray("notes", data.notes);
  slam::WriteFileAtomically(dir + "metrics.json", json.Finish());

  std::string line =
      log_name + ": " + algorithm + " on " +
      (encoder_only ? std::to_string(run.trajectory.size()) + " encoder records (no scans)"
                    : std::to_string(timing.scans) + " scans") +
      " in " + Fixed(timing.wall_s, 2) + " s";
  if (!encoder_only) line += " (" + Fixed(timing.RealTimeFactor(), 1) + "x real time)";
  if (metrics) {
    line += "; ATE RMSE " + Fixed(metrics->ate.translation_m.rmse, 3) + " m";
    if (dr_metrics)
      line += " (dead reckoning " + Fixed(dr_metrics->ate.translation_m.rmse, 3) + " m)";
    if (map_vs_reference) line += "; map F1 " + Fixed(map_vs_reference->f1, 3);
  }
  line += " -> " + out_dir;
  std::puts(line.c_str());
  for (const std::string& note : data.notes) std::printf("  note: %s\n", note.c_str());
  return 0;
}

}  // namespace slamrig::app
