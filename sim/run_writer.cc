#include "sim/run_writer.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <optional>

#include "sim/robot_yaml.h"
#include "sim/world_yaml.h"
#include "slam/io/atomic_file.h"
#include "slam/io/carmen_writer.h"
#include "slam/io/tum_io.h"
#include "slam/odometry/wheel_odometry.h"
#include "slam/types/check.h"
#include "slam/types/trajectory.h"
#include "slam/types/validation.h"

namespace slamrig::sim {
namespace {

// Linear interpolation of odometry poses (angle along the shorter arc).
Pose2 Interpolate(const OdometryPose& a, const OdometryPose& b, Time time) {
  if (b.time <= a.time) return b.odom_from_base;
  const double f = SecondsBetween(time, a.time) / SecondsBetween(b.time, a.time);
  const Pose2& p = a.odom_from_base;
  const Pose2& q = b.odom_from_base;
  return Pose2(p.x() + f * (q.x() - p.x()), p.y() + f * (q.y() - p.y()),
               p.theta() + f * NormalizeAngle(q.theta() - p.theta()));
}

std::string SimSettingsYaml(const SimulatorOptions& options, const RunSummary& summary) {
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

RunSummary WriteSimulationRun(const SimulatorOptions& options, const RunOptions& run,
                              const std::string& out_dir) {
  SLAMRIG_CHECK(run.Validate().empty(), "invalid RunOptions");
  std::filesystem::create_directories(out_dir);
  const std::string dir = std::filesystem::path(out_dir).string() + "/";
  RunSummary summary;

  Simulator sim(options);
  const RobotSpec& robot = options.robot;
  slam::WheelOdometryOptions odometry_options;
  odometry_options.robot = NominalOdometry(robot);
  odometry_options.use_gyro = robot.imu.enabled;
  slam::WheelOdometry odometry(odometry_options);

  slam::CarmenWriter log(dir + "run.log");
  log.WriteParam("robot_front_laser_max", FormatNumber(robot.lidar.range_max_m));
  log.WriteParam("robot_frontlaser_offset", FormatNumber(robot.lidar.mount.x_m));
  // ROBOTLASER1 has no field for these; slamrig's reader applies them to every laser line.
  log.WriteParam("laser_time_increment_s", FormatNumber(robot.lidar.time_increment_s()));
  log.WriteParam("laser_range_min_m", FormatNumber(robot.lidar.range_min_m));
  log.WriteParam("slamrig_world", options.world.name.empty() ? "unnamed" : options.world.name);
  log.WriteParam("slamrig_robot", robot.name.empty() ? "unnamed" : robot.name);
  log.WriteParam("slamrig_seed", std::to_string(options.seed));

  Trajectory truth_at_scans;
  // The odometry before the held scans, and the scans waiting for the next odometry pose.
  std::optional<OdometryPose> last_odometry;
  std::vector<std::pair<LaserScan, TruthSample>> held_scans;
  auto write_scans = [&](const std::optional<OdometryPose>& next) {
    for (const auto& [scan, truth] : held_scans) {
      Pose2 odom_at_scan;
      if (last_odometry && next) {
        odom_at_scan = Interpolate(*last_odometry, *next, scan.time);
      } else if (last_odometry || next) {
        odom_at_scan = (last_odometry ? *last_odometry : *next).odom_from_base;
      }
      log.WriteLaser(scan, odom_at_scan);
      log.WriteTruePos(truth.ToGroundTruthPose(), odom_at_scan);
    }
    held_scans.clear();
  };
  auto consume = [&](const StepResult& step) {
    for (std::size_t i = 0; i < step.records.size(); ++i) {
      const Record& record = step.records[i];
      if (const auto* imu = std::get_if<ImuSample>(&record)) {
        odometry.AddImu(*imu);
        ++summary.num_imu;
      } else if (const auto* ticks = std::get_if<WheelTicks>(&record)) {
        const OdometryPose pose = odometry.AddTicks(*ticks);
        write_scans(pose);
        double tv = 0.0, rv = 0.0;
        if (last_odometry && pose.time > last_odometry->time) {
          const double dt = SecondsBetween(pose.time, last_odometry->time);
          const Pose2 delta = last_odometry->odom_from_base.Between(pose.odom_from_base);
          tv = std::copysign(delta.translation().norm(), delta.x()) / dt;
          rv = delta.theta() / dt;
        }
        log.WriteOdometry(pose, tv, rv);
        last_odometry = pose;
        ++summary.num_odometry;
      } else if (const auto* scan = std::get_if<LaserScan>(&record)) {
        held_scans.emplace_back(*scan, step.truth[i]);
        truth_at_scans.Append(scan->time, step.truth[i].map_from_base);
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
  write_scans(std::nullopt);
  log.Commit();

  summary.duration_s = sim.time().seconds();
  summary.drive_finished = sim.drive_finished();
  summary.final_truth = sim.Truth().map_from_base;
  summary.final_odometry = odometry.pose();
  slam::WriteTum(dir + "truth.tum", truth_at_scans);
  slam::WriteFileAtomically(dir + "world.yaml", WorldSpecToYaml(options.world));
  slam::WriteFileAtomically(dir + "robot.yaml", RobotSpecToYaml(options.robot));
  slam::WriteFileAtomically(dir + "sim.yaml", SimSettingsYaml(options, summary));
  for (const char* name : {"run.log", "truth.tum", "world.yaml", "robot.yaml", "sim.yaml"}) {
    summary.files.push_back(dir + name);
  }
  return summary;
}

}  // namespace slamrig::sim
