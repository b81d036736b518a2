#include "scenarios/recording.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>

#include "sim/robot_yaml.h"
#include "sim/world_yaml.h"
#include "slam/io/atomic_file.h"
#include "slam/io/carmen_sink.h"
#include "slam/io/tum_io.h"
#include "slam/types/check.h"
#include "slam/types/trajectory.h"
#include "slam/types/validation.h"

namespace slamrig::scenario {
namespace {

std::string SimSettingsYaml(const sim::SimulatorOptions& options, const RunSummary& summary) {
  YAML::Emitter out;
  out << YAML::Comment("slamrig simulate: run settings");
  out << YAML::BeginMap;
  out << YAML::Key << "world" << YAML::Value << options.world.name;
  out << YAML::Key << "robot" << YAML::Value << options.robot.name;
  out << YAML::Key << "seed" << YAML::Value << options.seed;
  out << YAML::Key << "physics_rate_hz" << YAML::Value << FormatNumber(options.physics_rate_hz);
  out << YAML::Key << "traction_iterations" << YAML::Value << options.traction_iterations;
  out << YAML::Key << "velocity_iterations" << YAML::Value << options.velocity_iterations;
  out << YAML::Key << "position_iterations" << YAML::Value << options.position_iterations;
  out << YAML::Key << "duration_s" << YAML::Value << FormatNumber(summary.duration_s);
  out << YAML::Key << "drive_finished" << YAML::Value << summary.drive_finished;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace

std::vector<std::string> RunOptions::Validate() const {
  std::vector<std::string> errors;
  if (!(duration_s >= 0.0))
    errors.push_back("duration_s = " + FormatNumber(duration_s) + "; must be >= 0");
  if (!(max_duration_s > 0.0)) {
    errors.push_back("max_duration_s = " + FormatNumber(max_duration_s) + "; must be > 0");
  }
  return errors;
}

RunSummary RecordSimulation(const sim::SimulatorOptions& options, const RunOptions& run,
                            const std::string& out_dir) {
  SLAMRIG_CHECK(run.Validate().empty(), "invalid RunOptions");
  std::filesystem::create_directories(out_dir);
  const std::string dir = std::filesystem::path(out_dir).string() + "/";
  RunSummary summary;

  sim::Simulator sim(options);
  const sim::RobotSpec& robot = options.robot;
  slam::CarmenSinkOptions carmen;
  carmen.odometry.robot = sim::NominalOdometry(robot);
  carmen.odometry.use_gyro = robot.imu.enabled;
  carmen.params = {
      {"robot_front_laser_max", FormatNumber(robot.lidar.range_max_m)},
      {"robot_frontlaser_offset", FormatNumber(robot.lidar.mount.x_m)},
      // ROBOTLASER1 has no field for these; slamrig's reader applies them to every laser line.
      {"laser_time_increment_s", FormatNumber(robot.lidar.time_increment_s())},
      {"laser_range_min_m", FormatNumber(robot.lidar.range_min_m)},
      {"slamrig_world", options.world.name.empty() ? "unnamed" : options.world.name},
      {"slamrig_robot", robot.name.empty() ? "unnamed" : robot.name},
      {"slamrig_seed", std::to_string(options.seed)}};
  slam::CarmenSink log(dir + "run.log", carmen);

  Trajectory truth_at_scans;
  auto consume = [&](const sim::StepResult& step) {
    for (std::size_t i = 0; i < step.records.size(); ++i) {
      const Record& record = step.records[i];
      const GroundTruthPose truth = step.truth[i].ToGroundTruthPose();
      if (const auto* scan = std::get_if<LaserScan>(&record)) {
        truth_at_scans.Append(scan->time, truth.map_from_base);
        log.Add(record, &truth);
      } else {
        log.Add(record, nullptr);
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
  log.Commit();

  summary.num_scans = log.scans();
  summary.num_odometry = log.odometry_lines();
  summary.num_imu = log.imu_samples();
  summary.duration_s = sim.time().seconds();
  summary.drive_finished = sim.drive_finished();
  summary.final_truth = sim.Truth().map_from_base;
  summary.final_odometry = log.odometry_pose();
  slam::WriteTum(dir + "truth.tum", truth_at_scans);
  slam::WriteFileAtomically(dir + "world.yaml", sim::WorldSpecToYaml(options.world));
  slam::WriteFileAtomically(dir + "robot.yaml", sim::RobotSpecToYaml(options.robot));
  slam::WriteFileAtomically(dir + "sim.yaml", SimSettingsYaml(options, summary));
  for (const char* name : {"run.log", "truth.tum", "world.yaml", "robot.yaml", "sim.yaml"}) {
    summary.files.push_back(dir + name);
  }
  return summary;
}

}  // namespace slamrig::scenario
