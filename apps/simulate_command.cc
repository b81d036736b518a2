// `slamrig simulate WORLD --out DIR`: a simulated run written as a CARMEN log plus ground truth,
// or (`--format mcap|sqlite3`) as a ROS 2 bag, or (`--format ece276a`) in the UCSD ECE276A
// layout; all through scenario::RecordSimulation.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "apps/cli_args.h"
#include "apps/commands.h"
#include "apps/topic_flags.h"
#include "scenarios/recording.h"
#include "sim/presets.h"
#include "sim/robot_yaml.h"
#include "sim/world_yaml.h"
#include "slam/io/atomic_file.h"
#include "slam/io/bag/bag_writer.h"
#include "slam/types/error.h"

namespace slamrig::app {

int RunSimulateCommand(const std::vector<std::string>& args) {
  std::string world_arg, robot_arg = sim::kDefaultRobot, out_dir, format = "carmen",
                         compression = "zstd";
  std::vector<std::string> topic_flags;
  double duration_s = 0.0, physics_rate_hz = 200.0;
  std::uint64_t seed = 1;
  int laps = 0, dataset = 20;
  bool no_noise = false, quiet = false;
  ArgParser parser(
      "slamrig simulate", "WORLD [--robot R] [--duration S] [--seed N] --out DIR [options]",
      "Simulates a robot driving through a world (Box2D physics with wheel slip, encoders, IMU,\n"
      "lidar) and writes DIR/run.log (CARMEN: ODOM from the robot's own encoder + gyro\n"
      "odometry, ROBOTLASER1, TRUEPOS), DIR/truth.tum (ground truth at every scan), and the\n"
      "resolved DIR/world.yaml, DIR/robot.yaml and DIR/sim.yaml. Same arguments, same bytes.\n"
      "--format mcap or sqlite3 writes a ROS 2 bag DIR/run instead of run.log (/scan, /imu,\n"
      "/joint_states, /odom and /tf from the same robot odometry, /tf_static, /clock,\n"
      "/ground_truth/odom). --format ece276a writes DIR/Encoders<N>.npz, Imu<N>.npz,\n"
      "Hokuyo<N>.npz and, with a camera, Kinect<N>.npz and dataRGBD/ as the ECE276A course\n"
      "data (N from --dataset). truth.tum and the yaml files are written for every format.");
  parser.AddPositional("WORLD", "world file, or a name in worlds/ (office, corridor, ...)",
                       &world_arg);
  parser.AddOption("robot", "R", "robot file, or a name in robots/ (ece276a, small_diff)",
                   &robot_arg);
  parser.AddOption("duration", "S", "simulated seconds (default: until the drive is done)",
                   &duration_s);
  parser.AddOption("seed", "N", "seed of every noise stream", &seed);
  parser.AddOption("laps", "N", "laps of the world's loop (default: the world's own)", &laps);
  parser.AddOption("physics-rate", "HZ", "physics steps per second", &physics_rate_hz);
  parser.AddFlag("no-noise", "switch off every sensor noise and calibration error", &no_noise);
  parser.AddOption("out", "DIR", "output folder (created)", &out_dir);
  parser.AddOption("format", "F",
                   "carmen (run.log), mcap or sqlite3 (ROS 2 bag DIR/run), ece276a (npz + PNG)",
                   &format);
  parser.AddOption("dataset", "N", "ece276a: the dataset number in the file names (20)", &dataset);
  parser.AddOption("compression", "C", "MCAP chunk compression: zstd, lz4 or none", &compression);
  parser.AddRepeated("topic", "KEY=NAME",
                     "a bag topic name, e.g. scan=/front/scan (keys: " +
                         std::string(slam::BagTopicNames::Keys()) + ")",
                     &topic_flags);
  parser.AddFlag("quiet", "print nothing but errors", &quiet);
  if (!parser.Parse(args)) return 0;
  if (out_dir.empty()) throw ConfigError("slamrig simulate: --out DIR is required");
  if (format != "carmen" && format != "mcap" && format != "sqlite3" && format != "ece276a") {
    throw ConfigError(
        "slamrig simulate: --format: expected carmen, mcap, sqlite3 or ece276a, got '" + format +
        "'");
  }
  scenario::RecordingOptions recording;
  recording.format = format == "carmen"    ? scenario::RecordingFormat::kCarmen
                     : format == "mcap"    ? scenario::RecordingFormat::kMcap
                     : format == "ece276a" ? scenario::RecordingFormat::kEce276a
                                           : scenario::RecordingFormat::kSqlite3;
  if (dataset < 0) {
    throw ConfigError("slamrig simulate: --dataset: expected a number >= 0, got " +
                      std::to_string(dataset));
  }
  if (dataset != 20 && recording.format != scenario::RecordingFormat::kEce276a) {
    throw ConfigError("slamrig simulate: --dataset needs --format ece276a");
  }
  recording.ece276a_dataset = dataset;
  if (compression == "zstd") {
    recording.compression = slam::McapCompression::kZstd;
  } else if (compression == "lz4") {
    recording.compression = slam::McapCompression::kLz4;
  } else if (compression == "none") {
    recording.compression = slam::McapCompression::kNone;
  } else {
    throw ConfigError("slamrig simulate: --compression: expected zstd, lz4 or none, got '" +
                      compression + "'");
  }
  recording.topics = ParseTopicFlags("slamrig simulate", topic_flags);
  const bool bag = recording.format == scenario::RecordingFormat::kMcap ||
                   recording.format == scenario::RecordingFormat::kSqlite3;
  if (!bag && (!topic_flags.empty() || compression != "zstd")) {
    throw ConfigError("slamrig simulate: --topic and --compression need --format mcap or sqlite3");
  }

  sim::SimulatorOptions options;
  options.world = sim::LoadWorldSpec(sim::FindPresetFile(world_arg, "worlds"));
  options.robot = sim::LoadRobotSpec(sim::FindPresetFile(robot_arg, "robots"));
  if (no_noise) options.robot = sim::WithoutNoise(options.robot);
  options.seed = seed;
  options.physics_rate_hz = physics_rate_hz;
  if (laps != 0) options.world.drive.laps = laps;
  for (const std::string& e : options.Validate()) throw ConfigError("slamrig simulate: " + e);
  scenario::RunOptions run;
  run.duration_s = duration_s;
  for (const std::string& e : run.Validate()) throw ConfigError("slamrig simulate: --" + e);
  if (duration_s == 0.0 && options.world.drive.mode == sim::DriveMode::kIdle) {
    throw ConfigError("slamrig simulate: world '" + options.world.name +
                      "' has no drive; give --duration S");
  }

  slam::CheckOutputFolder(out_dir);
  const auto start = std::chrono::steady_clock::now();
  const scenario::RunSummary summary = scenario::RecordSimulation(options, run, out_dir, recording);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (quiet) return 0;
  const Pose2 error = summary.final_truth.Between(options.world.spawn * summary.final_odometry);
  std::printf(
      "%s with %s, seed %llu: %.1f s simulated%s, %.1f m driven, %d scans, %d odometry, %d IMU "
      "samples; odometry ends %.2f m / %.1f deg off; %.2f s (%.0fx real time) -> %s\n",
      options.world.name.c_str(), options.robot.name.c_str(), static_cast<unsigned long long>(seed),
      summary.duration_s, summary.drive_finished ? " (drive done)" : "", summary.path_length_m,
      summary.num_scans, summary.num_odometry, summary.num_imu, error.translation().norm(),
      std::abs(error.theta()) * 180.0 / std::numbers::pi, seconds,
      summary.duration_s / std::max(seconds, 1e-9), out_dir.c_str());
  if (summary.num_frames > 0) {
    std::printf("%d RGB-D frames rendered, %d written%s\n", summary.num_frames,
                summary.num_frames - summary.frames_skipped,
                summary.frames_skipped ? " (a CARMEN log has no image line)" : "");
  }
  return 0;
}

}  // namespace slamrig::app
