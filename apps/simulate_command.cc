// `slamrig simulate WORLD --out DIR`: a simulated run written as a CARMEN log plus ground truth,
// or (`--format mcap|sqlite3`) as a ROS 2 bag.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <string>

#include "apps/cli_args.h"
#include "apps/commands.h"
#include "scenarios/recording.h"
#include "sim/presets.h"
#include "sim/robot_yaml.h"
#include "sim/world_yaml.h"
#include "slam/io/atomic_file.h"
#include "slam/io/bag/bag_writer.h"
#include "slam/odometry/wheel_odometry.h"
#include "slam/types/error.h"

namespace slamrig::app {
namespace {

// The run as a ROS 2 bag DIR/run (see slam::BagWriter): the sensor records, the robot's own
// encoder + gyro odometry (as WriteSimulationRun computes it for run.log) and the ground truth
// at every scan; plus the resolved world.yaml and robot.yaml.
scenario::RunSummary WriteSimulationBag(const sim::SimulatorOptions& options,
                                        const scenario::RunOptions& run,
                                   const std::string& out_dir, slam::BagStorage storage) {
  namespace fs = std::filesystem;
  fs::create_directories(out_dir);
  const std::string bag = (fs::path(out_dir) / "run").string();
  // A bag from an earlier run is replaced; anything else in the way is an error (BagWriter).
  if (fs::exists(fs::path(bag) / "metadata.yaml")) fs::remove_all(bag);
  const sim::RobotSpec& robot = options.robot;
  slam::BagWriterOptions bag_options;
  bag_options.storage = storage;
  bag_options.ticks_per_revolution = robot.encoders.ticks_per_revolution;
  slam::BagWriter writer(bag, bag_options);
  slam::WheelOdometryOptions odometry_options;
  odometry_options.robot = sim::NominalOdometry(robot);
  odometry_options.use_gyro = robot.imu.enabled;
  slam::WheelOdometry odometry(odometry_options);

  sim::Simulator sim(options);
  scenario::RunSummary summary;
  auto consume = [&](const sim::StepResult& step) {
    for (std::size_t i = 0; i < step.records.size(); ++i) {
      const Record& record = step.records[i];
      writer.Write(record);
      if (const auto* imu = std::get_if<ImuSample>(&record)) {
        odometry.AddImu(*imu);
        ++summary.num_imu;
      } else if (const auto* ticks = std::get_if<WheelTicks>(&record)) {
        writer.Write(Record{odometry.AddTicks(*ticks)});
        ++summary.num_odometry;
      } else if (std::holds_alternative<LaserScan>(record)) {
        writer.Write(step.truth[i].ToGroundTruthPose());
        ++summary.num_scans;
      }
    }
  };
  const double limit_s = run.duration_s > 0.0 ? run.duration_s : run.max_duration_s;
  Pose2 previous = sim.Truth().map_from_base;
  while (sim.time().seconds() < limit_s - 0.5 * sim.step_s()) {
    if (run.duration_s == 0.0 && sim.drive_finished()) break;
    consume(sim.Step());
    const Pose2 now = sim.Truth().map_from_base;
    summary.path_length_m += (now.translation() - previous.translation()).norm();
    previous = now;
  }
  consume(sim.Flush());
  writer.Commit();
  summary.duration_s = sim.time().seconds();
  summary.drive_finished = sim.drive_finished();
  summary.final_truth = sim.Truth().map_from_base;
  summary.final_odometry = odometry.pose();
  slam::WriteFileAtomically((fs::path(out_dir) / "world.yaml").string(),
                            sim::WorldSpecToYaml(options.world));
  slam::WriteFileAtomically((fs::path(out_dir) / "robot.yaml").string(),
                            sim::RobotSpecToYaml(options.robot));
  return summary;
}

}  // namespace

int RunSimulateCommand(const std::vector<std::string>& args) {
  std::string world_arg, robot_arg = "ece276a", out_dir, format = "carmen";
  double duration_s = 0.0, physics_rate_hz = 200.0;
  std::uint64_t seed = 1;
  int laps = 0;
  bool no_noise = false;
  ArgParser parser(
      "slamrig simulate", "WORLD [--robot R] [--duration S] [--seed N] --out DIR [options]",
      "Simulates a robot driving through a world (Box2D physics with wheel slip, encoders, IMU,\n"
      "lidar) and writes DIR/run.log (CARMEN: ODOM from the robot's own encoder + gyro\n"
      "odometry, ROBOTLASER1, TRUEPOS), DIR/truth.tum (ground truth at every scan), and the\n"
      "resolved DIR/world.yaml, DIR/robot.yaml and DIR/sim.yaml. Same arguments, same bytes.\n"
      "--format mcap or sqlite3 writes a ROS 2 bag DIR/run instead of run.log and truth.tum\n"
      "(/scan, /imu, /joint_states, /odom, /tf, /tf_static, /clock, /ground_truth/odom).");
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
  parser.AddOption("format", "F", "carmen (run.log), mcap or sqlite3 (ROS 2 bag DIR/run)", &format);
  if (!parser.Parse(args)) return 0;
  if (out_dir.empty()) throw ConfigError("slamrig simulate: --out DIR is required");
  if (format != "carmen" && format != "mcap" && format != "sqlite3") {
    throw ConfigError("slamrig simulate: --format: expected carmen, mcap or sqlite3, got '" +
                      format + "'");
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

  const auto start = std::chrono::steady_clock::now();
  const scenario::RunSummary summary =
      format == "carmen" ? scenario::RecordSimulation(options, run, out_dir)
                         : WriteSimulationBag(options, run, out_dir,
                                              format == "mcap" ? slam::BagStorage::kMcap
                                                               : slam::BagStorage::kSqlite3);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const Pose2 error = summary.final_truth.Between(options.world.spawn * summary.final_odometry);
  std::printf(
      "%s with %s, seed %llu: %.1f s simulated%s, %.1f m driven, %d scans, %d odometry, %d IMU "
      "samples; odometry ends %.2f m / %.1f deg off; %.2f s (%.0fx real time) -> %s\n",
      options.world.name.c_str(), options.robot.name.c_str(), static_cast<unsigned long long>(seed),
      summary.duration_s, summary.drive_finished ? " (drive done)" : "", summary.path_length_m,
      summary.num_scans, summary.num_odometry, summary.num_imu, error.translation().norm(),
      std::abs(error.theta()) * 180.0 / std::numbers::pi, seconds,
      summary.duration_s / std::max(seconds, 1e-9), out_dir.c_str());
  return 0;
}

}  // namespace slamrig::app
