// `slamrig slam LOG --algorithm NAME --out DIR`: any estimator of the pipeline on a log (CARMEN,
// real or written by `slamrig simulate`; an ECE276A robot log), scored against the log's
// reference when it has one.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>

#include "apps/cli_args.h"
#include "apps/commands.h"
#include "apps/topic_flags.h"
#include "scenarios/plot.h"
#include "slam/config/yaml_node.h"
#include "slam/eval/json_writer.h"
#include "slam/eval/map_score.h"
#include "slam/eval/run_timing.h"
#include "slam/eval/trajectory_metrics.h"
#include "slam/fusion/consistency.h"
#include "slam/io/atomic_file.h"
#include "slam/io/log_perturbation.h"
#include "slam/io/log_reader.h"
#include "slam/io/map_image.h"
#include "slam/io/map_server.h"
#include "slam/io/tum_io.h"
#include "slam/odometry/scan_sync.h"
#include "slam/pipeline/estimator_runner.h"
#include "slam/types/error.h"

namespace slamrig::app {
namespace {

using Clock = std::chrono::steady_clock;

std::string Fixed(double v, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*f", digits, v);
  return buffer;
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

std::string CloudLines(double time_s, const slam::EstimatorView& view) {
  std::string out;
  char line[160];
  for (std::size_t i = 0; i < view.particles.size(); ++i) {
    const slam::WeightedPose& p = view.particles[i];
    std::snprintf(line, sizeof(line), "%.9f,%zu,%.6f,%.6f,%.6f,%.9g\n", time_s, i, p.pose.x(),
                  p.pose.y(), p.pose.theta(), p.weight);
    out += line;
  }
  return out;
}

// The configuration the command line asks for: an algorithm, its preset, and field values from
// the shorthand flags and --set, read by the algorithm's own field table (so a key it does not
// have is an error naming the flag).
slam::EstimatorConfig ConfigFromFlags(
    const std::string& algorithm, const std::string& preset,
    const std::vector<std::pair<std::string, std::string>>& fields, const std::string& odometry,
    bool no_gyro) {
  YamlNode node = YamlNode::LoadString("{}", "slamrig slam");
  node.Override("algorithm", algorithm, "--algorithm " + algorithm);
  if (!preset.empty()) node.Override("preset", preset, "--preset " + preset);
  for (const auto& [key, origin] : fields) {
    const std::size_t eq = key.find('=');
    if (eq == std::string::npos || eq == 0) throw ConfigError(origin + ": expected KEY=VALUE");
    node.Override(key.substr(0, eq), key.substr(eq + 1), origin);
  }
  node.Override("odometry.source", odometry, "--odometry " + odometry);
  if (no_gyro) node.Override("odometry.use_gyro", "false", "--no-gyro");
  slam::EstimatorConfig config = slam::ParseEstimatorConfig(algorithm, node);
  node.CheckAllKeysUsed();
  return config;
}

}  // namespace

int RunSlamCommand(const std::vector<std::string>& args) {
  std::string log_path, out_dir, algorithm = "pf", preset, odometry = "auto";
  std::string truth_map_path, particles, threads, resolution;
  std::vector<std::string> sets, topic_flags, perturb_flags;
  int clouds = 0, max_scans = 0;
  std::uint64_t seed = 1;
  bool no_gyro = false, lenient = false, quiet = false, strict = false;
  ArgParser parser(
      "slamrig slam", "LOG --out DIR [options]",
      "Runs one estimator on a log and writes, into DIR: trajectory.tum (one pose per scan,\n"
      "stamped with the scan's own time; the final trajectory, revised where the estimator\n"
      "revises its past), map.pgm + map.yaml (ROS map_server), map.png (with the reference\n"
      "trajectory when the log has one) and metrics.json (ATE/RPE against the reference,\n"
      "dead reckoning alongside, timing, statistics, the resolved configuration).\n"
      "LOG is a CARMEN log (plain or .gz; real, or written by `slamrig simulate`), a ROS 2\n"
      "bag (MCAP or sqlite3 folder or file: /scan, /imu, /joint_states, /odom,\n"
      "/ground_truth/odom) or an ECE276A dataset (DIR/20, or one of its Encoders/Imu/Hokuyo\n"
      "files).\n"
      "Algorithms: " +
          slam::AlgorithmNames());
  parser.AddPositional("LOG", "log path; a path, or relative to SLAMRIG_DATA_DIR", &log_path);
  parser.AddOption("out", "DIR", "output folder (created)", &out_dir);
  parser.AddOption("algorithm", "NAME", slam::AlgorithmNames(), &algorithm);
  parser.AddOption("preset", "NAME", "the algorithm's preset (pf: default or reports)", &preset);
  parser.AddRepeated("set", "KEY=VALUE",
                     "set a field of the algorithm, as in a scenario's slam: entry "
                     "(particles=30, map.resolution_m=0.1, correlation.yaw_half_steps=2)",
                     &sets);
  parser.AddOption("particles", "N", "shorthand for --set particles=N", &particles);
  parser.AddOption("threads", "N", "shorthand for --set threads=N", &threads);
  parser.AddOption("resolution", "M", "shorthand for --set map.resolution_m=M", &resolution);
  parser.AddOption("seed", "N", "random seed (same seed, same result)", &seed);
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
  parser.AddFlag("strict",
                 "refuse a log cut short (a crashed recording) instead of reading it up to the cut",
                 &strict);
  parser.AddRepeated("topic", "KEY=NAME",
                     "a ROS 2 bag's topic to read, e.g. scan=/front/scan (keys: " +
                         std::string(slam::BagTopicNames::Keys()) + ")",
                     &topic_flags);
  parser.AddRepeated("perturb", "KEY=VALUE",
                     "perturb the log's records as read, seeded by --seed (odometry.noise_per_m, "
                     "odometry.noise_per_rad, odometry.scale, odometry.bias_rad_per_m, "
                     "odometry.lost=[[T0, T1]], scans.drop_fraction, range.noise_m, range.max_m, "
                     "beams.drop_every, beams.drop_fraction); the reference is not perturbed",
                     &perturb_flags);
  parser.AddFlag("quiet", "no progress output", &quiet);
  if (!parser.Parse(args)) return 0;
  if (out_dir.empty()) throw ConfigError("slamrig slam: --out DIR is required");
  slam::CheckOutputFolder(out_dir);
  if (max_scans < 0)
    throw ConfigError("slamrig slam: --max-scans = " + std::to_string(max_scans) +
                      "; must be >= 0");
  if (clouds < 0)
    throw ConfigError("slamrig slam: --clouds = " + std::to_string(clouds) + "; must be >= 0");
  std::vector<std::pair<std::string, std::string>> fields;
  if (!particles.empty()) fields.push_back({"particles=" + particles, "--particles " + particles});
  if (!threads.empty()) fields.push_back({"threads=" + threads, "--threads " + threads});
  if (!resolution.empty())
    fields.push_back({"map.resolution_m=" + resolution, "--resolution " + resolution});
  for (const std::string& s : sets) fields.push_back({s, "--set " + s});
  const slam::EstimatorConfig base = ConfigFromFlags(algorithm, preset, fields, odometry, no_gyro);
  const slam::LogPerturbation perturbation = slam::LogPerturbationFromFlags(perturb_flags);

  // Read and run everything before creating any output, so bad input leaves nothing behind.
  slam::LogReadOptions read;
  read.lenient = lenient;
  read.strict = strict;
  read.topics = ParseTopicFlags("slamrig slam", topic_flags);
  const std::string path = slam::ResolveLogPath(log_path);
  slam::Dataset data = slam::ReadLog(path, read);
  if (!data.truncated.empty()) std::fprintf(stderr, "note: %s\n", data.truncated.c_str());
  slam::ApplyLogPerturbation(&data, perturbation, seed, base.odometry.robot);
  slam::EstimatorConfig config = base;
  Trajectory reference;
  for (const GroundTruthPose& g : data.reference) reference.Append(g.time, g.map_from_base);
  const std::string log_name = std::filesystem::path(path).filename().string();
  std::optional<slam::OccupancyGrid> truth_map;
  if (!truth_map_path.empty()) {
    if (reference.empty()) {
      throw ConfigError("slamrig slam: --truth-map needs a log with a reference trajectory");
    }
    truth_map = slam::GridFromMapImage(slam::ReadMapServerMap(truth_map_path));
  }
  const bool has_scans = std::any_of(data.records.begin(), data.records.end(), [](const Record& r) {
    return std::holds_alternative<LaserScan>(r);
  });

  slam::RunLimits limits;
  limits.max_scans = static_cast<std::size_t>(max_scans);
  slam::RunTiming timing;
  const auto start = Clock::now();
  Progress progress(!quiet);
  std::size_t total_scans = 0;
  for (const Record& r : data.records) total_scans += std::holds_alternative<LaserScan>(r);
  if (limits.max_scans > 0) total_scans = std::min(total_scans, limits.max_scans);
  std::string cloud_csv;
  if (clouds > 0) cloud_csv = "# time_s,particle,x_m,y_m,yaw_rad,weight\n";
  slam::EstimatorRun run;
  bool encoder_only = false;
  if (!has_scans) {
    // Logs without a lidar (the shared ECE276A data): the trajectory an estimator reports at its
    // records' rate (dead reckoning and the EKF, from encoders and gyro, one pose per encoder
    // record).
    const slam::OdometrySource source =
        slam::ResolveOdometrySource(data.records, config.odometry.source);
    slam::EstimatorRunner runner(config, source, seed);
    for (const Record& r : data.records) runner.Add(r);
    runner.Finish();
    run = runner.TakeResult();
    if (!run.record_rate.empty()) {
      run.final = run.online = run.record_rate;
      run.covariances = run.record_rate_covariances;
    } else {
      throw ParseError(path + ": no laser scans; " + config.algorithm +
                       " needs them (dead-reckoning and ekf run on encoder records alone)");
    }
    if (run.final.empty()) throw ParseError(path + ": no laser scans and no wheel encoder records");
    run.odometry_source = slam::OdometrySource::kWheelTicks;
    encoder_only = true;
  } else {
    const slam::OdometrySource source =
        slam::ResolveOdometrySource(data.records, config.odometry.source);
    slam::EstimatorRunner runner(config, source, seed);
    runner.SetScanCallback(
        [&](std::size_t i, const slam::SyncedScan& s, const slam::ScanEstimate&) {
          progress(i + 1, total_scans);
          if (clouds > 0 && i % static_cast<std::size_t>(clouds) == 0) {
            cloud_csv += CloudLines(s.scan.time.seconds(), runner.estimator().View());
          }
        });
    std::size_t scans = 0;
    for (const Record& r : data.records) {
      if (std::holds_alternative<LaserScan>(r) && limits.max_scans > 0 &&
          ++scans > limits.max_scans)
        break;
      runner.Add(r);
    }
    runner.Finish();
    run = runner.TakeResult();
  }
  timing.wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  timing.scans = static_cast<int>(encoder_only ? 0 : run.final.size());
  if (run.final.size() >= 2) {
    Time first = run.final[0].time, last = run.final[0].time;
    for (const StampedPose& p : run.final.poses()) {
      first = std::min(first, p.time);
      last = std::max(last, p.time);
    }
    timing.data_s = SecondsBetween(last, first);
  }

  // Scores against the reference (pose k with reference pose k: the same scans), with dead
  // reckoning alongside for comparison.
  std::optional<slam::TrajectoryMetrics> metrics, mean_metrics, online_metrics, dr_metrics;
  if (!reference.empty()) {
    if (!encoder_only && reference.size() > run.final.size()) {
      std::vector<StampedPose> head(reference.poses().begin(),
                                    reference.poses().begin() + run.final.size());
      reference = Trajectory(std::move(head));
    }
    metrics = slam::EvaluateTrajectory(run.final, reference);
    if (!run.mean.empty()) mean_metrics = slam::EvaluateTrajectory(run.mean, reference);
    if (run.final.poses() != run.online.poses())
      online_metrics = slam::EvaluateTrajectory(run.online, reference);
    if (config.algorithm != "dead-reckoning" && !encoder_only) {
      slam::EstimatorConfig dr = slam::DefaultEstimatorConfig("dead_reckoning", "dead-reckoning");
      dr.odometry = config.odometry;
      dr_metrics = slam::EvaluateTrajectory(
          slam::RunEstimator(dr, data.records, seed, limits).final, reference);
    }
  }
  // Map scores: against the same scans inserted at the reference poses, and against the true
  // world's map when given, both in the reference frame through the ATE alignment.
  std::optional<slam::MapScore> map_vs_reference, map_vs_truth;
  if (metrics && !encoder_only) {
    slam::OccupancyGrid reference_map(run.map.options());
    std::size_t k = 0;
    for (const Record& r : data.records) {
      const auto* scan = std::get_if<LaserScan>(&r);
      if (scan == nullptr) continue;
      if (k >= reference.size()) break;
      reference_map.InsertScan(*scan, reference[k++].pose);
    }
    map_vs_reference = slam::ScoreMap(run.map, metrics->ate.reference_from_estimate, reference_map);
    if (truth_map) {
      map_vs_truth = slam::ScoreMap(run.map, metrics->ate.reference_from_estimate, *truth_map);
    }
  }

  std::filesystem::create_directories(out_dir);
  const std::string dir = out_dir + "/";
  // metrics.json, written last, marks a complete folder (as for `slamrig run`).
  std::filesystem::remove(dir + "metrics.json");
  slam::WriteTum(dir + "trajectory.tum", run.final);
  if (!run.mean.empty()) slam::WriteTum(dir + "trajectory_mean.tum", run.mean);
  if (online_metrics) slam::WriteTum(dir + "trajectory_online.tum", run.online);
  if (!reference.empty()) slam::WriteTum(dir + "reference.tum", reference);
  if (clouds > 0) slam::WriteFileAtomically(dir + "particles.csv", cloud_csv);
  if (!run.covariances.empty()) {
    slam::WriteFileAtomically(dir + "covariance.csv",
                              slam::CovarianceCsv(run.online, run.covariances));
  }
  if (encoder_only) {
    // No map to draw the trajectory on: the path itself, x against y.
    scenario::PlotSeries path_xy{"trajectory", {}, {}, {}, {}, scenario::PaletteColour(0)};
    for (const StampedPose& p : run.final.poses()) {
      path_xy.x.push_back(p.pose.x());
      path_xy.y.push_back(p.pose.y());
    }
    scenario::PlotOptions plot;
    plot.title = log_name + ": " + config.name + " from the encoders and gyro";
    plot.x_label = "x [m]";
    plot.y_label = "y [m]";
    plot.y_from_zero = false;
    slam::WriteFileAtomically(dir + "trajectory.png", scenario::RenderLinePlotPng({path_xy}, plot));
  }
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
    overlays.push_back({&run.final, config.algorithm, 200, 60, 0});
    slam::MapImageOptions image_options;
    image_options.title = log_name + ": " + config.algorithm;
    slam::WriteMapPng(dir + "map.png", run.map, overlays, image_options);
  }

  slam::JsonWriter json;
  json.String("log", path).String("log_format", data.format).String("algorithm", config.algorithm);
  json.String("odometry_source", encoder_only ? "wheel_ticks (encoder records, no scans)"
                                              : SourceName(run.odometry_source))
      .Integer("seed", static_cast<long long>(seed))
      .Integer("scans", timing.scans)
      .Integer("poses", static_cast<long long>(run.final.size()))
      .Number("wall_time_s", timing.wall_s)
      .Number("data_time_s", timing.data_s)
      .Number("real_time_factor", timing.RealTimeFactor())
      .Number("ms_per_scan", timing.MillisecondsPerScan())
      .Integer("gyro_fallbacks", run.gyro_fallbacks)
      .Integer("scans_without_odometry", run.scans_without_odometry)
      .Integer("out_of_order_stamps", run.final.out_of_order());
  json.BeginObject("statistics");
  for (const auto& [name, value] : run.statistics) json.Number(name, value);
  json.EndObject();
  json.BeginObject("config");
  slam::WriteEstimatorConfigJson(config, &json);
  json.EndObject();
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
    if (online_metrics) {
      json.BeginObject("online_trajectory");
      slam::WriteTrajectoryMetrics(json, *online_metrics);
      json.EndObject();
    }
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
  std::vector<std::string> notes = data.notes;
  if (run.final.out_of_order() > 0) {
    notes.push_back(std::to_string(run.final.out_of_order()) +
                    " poses are stamped earlier than the one before them (the log's own scan "
                    "stamps); kept in scan order");
  }
  json.StringArray("notes", notes);
  slam::WriteFileAtomically(dir + "metrics.json", json.Finish());

  std::string line =
      log_name + ": " + config.algorithm + " on " +
      (encoder_only ? std::to_string(run.final.size()) + " encoder records (no scans)"
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
  for (const std::string& note : notes) std::printf("  note: %s\n", note.c_str());
  return 0;
}

}  // namespace slamrig::app
