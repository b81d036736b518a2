// `slamrig slam LOG --algorithm NAME --out DIR`: any estimator of the pipeline on a log (CARMEN,
// real or written by `slamrig simulate`; a ROS 2 bag; an ECE276A robot log), scored against the
// log's reference when it has one. The flags make a scenario of one log (the configuration they
// ask for, with dead reckoning beside it), which runs and reports as `slamrig run` does; the
// files `slamrig slam` has always written (trajectory.tum, map.pgm, ...) join the report.

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <stdexcept>

#include "apps/cli_args.h"
#include "apps/commands.h"
#include "apps/live_flags.h"
#include "apps/topic_flags.h"
#include "scenarios/plot.h"
#include "scenarios/scenario_result.h"
#include "scenarios/scenario_runner.h"
#include "scenarios/scenario_spec.h"
#include "slam/config/yaml_node.h"
#include "slam/fusion/consistency.h"
#include "slam/io/atomic_file.h"
#include "slam/io/log_perturbation.h"
#include "slam/io/log_reader.h"
#include "slam/io/map_server.h"
#include "slam/io/tum_io.h"
#include "slam/pipeline/estimator_runner.h"
#include "slam/types/error.h"
#include "slam/types/format.h"

namespace slamrig::app {
namespace {

using Clock = std::chrono::steady_clock;

// Progress on stderr for logs that take a while: on a terminal one line rewritten every two
// seconds; otherwise (a file, a pipe, CI) a whole line every ten seconds, so that no progress
// ever runs into the lines that follow it.
class Progress {
 public:
  explicit Progress(bool enabled)
      : enabled_(enabled),
        terminal_(::isatty(STDERR_FILENO) != 0),
        period_(terminal_ ? 2 : 10),
        start_(Clock::now()),
        next_(start_ + period_) {}
  ~Progress() {
    if (open_line_) std::fputc('\n', stderr);
  }
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void operator()(std::size_t done, std::size_t total) {
    if (!enabled_) return;
    const auto now = Clock::now();
    if (now < next_ && (done < total || !terminal_)) return;
    next_ = now + period_;
    const double s = std::chrono::duration<double>(now - start_).count();
    std::fprintf(
        stderr, "%sslam: %zu/%zu scans (%.0f%%), %.1f s%s", terminal_ ? "\r" : "", done, total,
        100.0 * static_cast<double>(done) / static_cast<double>(std::max<std::size_t>(total, 1)), s,
        terminal_ && done < total ? "" : "\n");
    open_line_ = terminal_ && done < total;
    std::fflush(stderr);
  }

 private:
  bool enabled_;
  bool terminal_;
  std::chrono::seconds period_;
  bool open_line_ = false;
  Clock::time_point start_, next_;
};

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

// The command line.
struct SlamFlags {
  std::string log_path, out_dir, algorithm = "pf", preset, odometry = "auto";
  std::string truth_map, particles, threads, resolution;
  std::vector<std::string> sets, topics;
  int clouds = 0, max_scans = 0;
  std::uint64_t seed = 1;
  std::vector<std::string> perturb;
  bool no_gyro = false, lenient = false, quiet = false, strict = false, record = false;
  LiveFlags live;
};

// Reads the flags and checks the output folder; false when help was asked for.
bool ParseSlamFlags(std::vector<std::string> args, SlamFlags* f) {
  TakeLivePort(&args, &f->live);
  ArgParser parser(
      "slamrig slam", "LOG --out DIR [options]",
      "Runs one estimator on a log, with dead reckoning beside it, and writes DIR as\n"
      "`slamrig run` writes a report (report.html, metrics.json, config.yaml, which `slamrig\n"
      "run` repeats, <name>.tum and maps in the reference's frame, plots), and besides:\n"
      "trajectory.tum (one pose per scan, stamped with the scan's own time, in the estimator's\n"
      "frame; the final trajectory, revised where the estimator revises its past),\n"
      "map.pgm + map.yaml (ROS map_server) and reference.tum when the log has a reference.\n"
      "LOG is a CARMEN log (plain or .gz; real, or written by `slamrig simulate`), a ROS 2\n"
      "bag (MCAP or sqlite3 folder or file: /scan, /imu, /joint_states, /odom,\n"
      "/ground_truth/odom) or an ECE276A dataset (DIR/20, or one of its Encoders/Imu/Hokuyo\n"
      "files).\n"
      "Algorithms: " +
          slam::AlgorithmNames());
  parser.AddPositional("LOG", "log path; a path, or relative to SLAMRIG_DATA_DIR", &f->log_path);
  parser.AddOption("out", "DIR", "output folder (created)", &f->out_dir);
  parser.AddOption("algorithm", "NAME", slam::AlgorithmNames(), &f->algorithm);
  parser.AddOption("preset", "NAME", "the algorithm's preset (pf: default or reports)", &f->preset);
  parser.AddRepeated("set", "KEY=VALUE",
                     "set a field of the algorithm, as in a scenario's slam: entry "
                     "(particles=30, map.resolution_m=0.1, correlation.yaw_half_steps=2)",
                     &f->sets);
  parser.AddOption("particles", "N", "shorthand for --set particles=N", &f->particles);
  parser.AddOption("threads", "N", "shorthand for --set threads=N", &f->threads);
  parser.AddOption("resolution", "M", "shorthand for --set map.resolution_m=M", &f->resolution);
  parser.AddOption("seed", "N", "random seed (same seed, same result)", &f->seed);
  parser.AddOption("odometry", "SOURCE", "auto, wheel_ticks, poses or none", &f->odometry);
  parser.AddFlag("no-gyro", "yaw from the wheel encoders even when the log has a gyro",
                 &f->no_gyro);
  parser.AddOption("clouds", "N",
                   "write the particle cloud every N scans to particles.csv (0: never)",
                   &f->clouds);
  parser.AddOption("max-scans", "N", "stop after N scans (0: all)", &f->max_scans);
  parser.AddOption("truth-map", "YAML",
                   "map_server map of the true world: the map the estimated maps are scored "
                   "against (aligned by the ATE alignment; needs a log with a reference)",
                   &f->truth_map);
  parser.AddFlag("lenient", "skip and count malformed CARMEN lines instead of failing",
                 &f->lenient);
  parser.AddRepeated("topic", "KEY=NAME",
                     "a ROS 2 bag's topic to read, e.g. scan=/front/scan (keys: " +
                         std::string(slam::BagTopicNames::Keys()) + ")",
                     &f->topics);
  parser.AddFlag("strict",
                 "refuse a log cut short (a crashed recording) instead of reading it up to the cut",
                 &f->strict);
  parser.AddRepeated("perturb", "KEY=VALUE",
                     "perturb the log's records as read, seeded by --seed (odometry.noise_per_m, "
                     "odometry.noise_per_rad, odometry.scale, odometry.bias_rad_per_m, "
                     "odometry.lost=[[T0, T1]], scans.drop_fraction, range.noise_m, range.max_m, "
                     "beams.drop_every, beams.drop_fraction); the reference is not perturbed",
                     &f->perturb);
  parser.AddFlag("record", "also write DIR/run.mcap, the run for Foxglove (docs/foxglove.md)",
                 &f->record);
  parser.AddFlag("quiet", "no progress output", &f->quiet);
  AddLiveFlags(&parser, &f->live);
  if (!parser.Parse(args)) return false;
  if (f->out_dir.empty()) throw ConfigError("slamrig slam: --out DIR is required");
  slam::CheckOutputFolder(f->out_dir);
  if (f->max_scans < 0)
    throw ConfigError("slamrig slam: --max-scans = " + std::to_string(f->max_scans) +
                      "; must be >= 0");
  if (f->clouds < 0)
    throw ConfigError("slamrig slam: --clouds = " + std::to_string(f->clouds) + "; must be >= 0");
  return true;
}

// The scenario the flags describe: the log, the configuration they ask for and, beside any other
// algorithm, dead reckoning on the same odometry for comparison.
scenario::ScenarioSpec SlamScenario(const SlamFlags& f) {
  std::vector<std::pair<std::string, std::string>> fields;
  if (!f.particles.empty())
    fields.push_back({"particles=" + f.particles, "--particles " + f.particles});
  if (!f.threads.empty()) fields.push_back({"threads=" + f.threads, "--threads " + f.threads});
  if (!f.resolution.empty())
    fields.push_back({"map.resolution_m=" + f.resolution, "--resolution " + f.resolution});
  for (const std::string& s : f.sets) fields.push_back({s, "--set " + s});
  std::vector<slam::EstimatorConfig> configs = {
      ConfigFromFlags(f.algorithm, f.preset, fields, f.odometry, f.no_gyro)};
  scenario::LogSource log;
  log.read.lenient = f.lenient;
  log.read.strict = f.strict;
  log.perturb = slam::LogPerturbationFromFlags(f.perturb);
  log.read.topics = ParseTopicFlags("slamrig slam", f.topics);
  log.path = slam::ResolveLogPath(f.log_path);
  log.max_scans = static_cast<std::size_t>(f.max_scans);
  log.truth_map = f.truth_map;
  if (configs.front().algorithm != "dead-reckoning") {
    slam::EstimatorConfig dr = slam::DefaultEstimatorConfig("dead_reckoning", "dead-reckoning");
    dr.odometry = configs.front().odometry;
    configs.push_back(std::move(dr));
  }
  return scenario::LogScenario(log, std::move(configs), f.seed, "slamrig slam");
}

// The files `slamrig slam` writes beside the report, of its configuration (the first) in the
// estimator's own frame: trajectories, covariances, map (or, on a log without scans, a plot of
// the path), the reference and the particle clouds. metrics.json goes first: the report writes
// it last, to mark the folder complete.
void WriteSlamFiles(const scenario::ScenarioResult& r, const std::string& out_dir,
                    const std::string& clouds_csv) {
  const slam::EstimatorRun& run = r.configs.front().run;
  std::filesystem::create_directories(out_dir);
  const std::string dir = out_dir + "/";
  std::filesystem::remove(dir + "metrics.json");
  slam::WriteTum(dir + "trajectory.tum", run.final);
  if (!run.mean.empty()) slam::WriteTum(dir + "trajectory_mean.tum", run.mean);
  if (run.final.poses() != run.online.poses())
    slam::WriteTum(dir + "trajectory_online.tum", run.online);
  if (!r.truth.empty()) slam::WriteTum(dir + "reference.tum", r.truth);
  if (!clouds_csv.empty()) slam::WriteFileAtomically(dir + "particles.csv", clouds_csv);
  if (!run.covariances.empty()) {
    slam::WriteFileAtomically(dir + "covariance.csv",
                              slam::CovarianceCsv(run.online, run.covariances));
  }
  if (r.scans > 0) {
    slam::WriteMapServerMap(run.map, dir + "map");
    return;
  }
  // No map to draw the trajectory on: the path itself, x against y.
  scenario::PlotSeries path_xy{"trajectory", {}, {}, {}, {}, scenario::PaletteColour(0)};
  for (const StampedPose& p : run.final.poses()) {
    path_xy.x.push_back(p.pose.x());
    path_xy.y.push_back(p.pose.y());
  }
  scenario::PlotOptions plot;
  plot.title = r.spec->name + ": " + run.name + " from the encoders and gyro";
  plot.x_label = "x [m]";
  plot.y_label = "y [m]";
  plot.y_from_zero = false;
  slam::WriteFileAtomically(dir + "trajectory.png", scenario::RenderLinePlotPng({path_xy}, plot));
}

// The one line printed at the end: what ran, how fast, how well, where the files are.
std::string SummaryLine(const scenario::ScenarioResult& r, const std::string& out_dir) {
  const scenario::ConfigResult& c = r.configs.front();
  const auto metric = [](const scenario::ConfigResult& config, const char* name) {
    const auto it = config.metrics.find(name);
    return it == config.metrics.end() ? std::optional<double>() : it->second;
  };
  std::string line =
      r.spec->name + ": " + c.algorithm + " on " +
      (r.scans == 0 ? std::to_string(c.estimate.size()) + " encoder records (no scans)"
                    : std::to_string(c.estimate.size()) + " scans") +
      " in " + Fixed(c.run.wall_s, 2) + " s";
  if (r.times_synthesised) {
    line += " (times synthesised from line order; no real-time factor)";
  } else if (r.scans > 0 && metric(c, "realtime_factor")) {
    line += " (" + Fixed(*metric(c, "realtime_factor"), 1) + "x real time)";
  }
  if (const auto ate = metric(c, "ate_rmse_m")) {
    line += "; ATE RMSE " + Fixed(*ate, 3) + " m";
    if (r.configs.size() > 1 && r.scans > 0) {
      if (const auto dr = metric(r.configs[1], "ate_rmse_m"))
        line += " (dead reckoning " + Fixed(*dr, 3) + " m)";
    }
    if (const auto f1 = metric(c, "map_f1")) line += "; map F1 " + Fixed(*f1, 3);
  }
  return line + " -> " + out_dir;
}

}  // namespace

int RunSlamCommand(const std::vector<std::string>& args) {
  SlamFlags flags;
  if (!ParseSlamFlags(args, &flags)) return 0;
  const scenario::ScenarioSpec spec = SlamScenario(flags);

  // Reads and runs everything before creating any output, so bad input leaves nothing behind.
  Progress progress(!flags.quiet);
  std::string clouds;
  if (flags.clouds > 0) clouds = "# time_s,particle,x_m,y_m,yaw_rad,weight\n";
  scenario::RunnerOptions options;
  if (flags.record) options.record_path = flags.out_dir + "/run.mcap";
  const std::unique_ptr<scenario::LiveServer> live =
      StartLive("slamrig slam", flags.live, &options);
  options.on_scan = [&](std::size_t done, std::size_t total, const slam::SyncedScan& scan,
                        const slam::EstimatorRunner& runner) {
    progress(done, total);
    if (flags.clouds > 0 && (done - 1) % static_cast<std::size_t>(flags.clouds) == 0)
      clouds += CloudLines(scan.scan.time.seconds(), runner.estimator().View());
  };
  options.work_dir = flags.out_dir;
  scenario::ScenarioResult result = scenario::RunScenario(spec, options);
  // One configuration: when it failed there is nothing to write but why.
  if (!result.failures.empty()) throw std::runtime_error(result.failures.front().message);
  if (!result.truncated.empty()) std::fprintf(stderr, "note: %s\n", result.truncated.c_str());
  if (const auto late = result.configs.front().run.final.out_of_order(); late > 0) {
    result.notes.push_back(std::to_string(late) +
                           " poses are stamped earlier than the one before them (the log's own "
                           "scan stamps); kept in scan order");
  }
  WriteSlamFiles(result, flags.out_dir, clouds);
  scenario::WriteReport(result, flags.out_dir);
  FinishLive(live.get(), flags.quiet);

  std::puts(SummaryLine(result, flags.out_dir).c_str());
  for (const std::string& note : result.notes) std::printf("  note: %s\n", note.c_str());
  return 0;
}

}  // namespace slamrig::app
