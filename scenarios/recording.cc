#include "scenarios/recording.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "sim/camera/camera_rig.h"
#include "sim/robot_yaml.h"
#include "sim/world_yaml.h"
#include "slam/io/atomic_file.h"
#include "slam/io/bag/bag_sink.h"
#include "slam/io/carmen_sink.h"
#include "slam/io/ece276a_writer.h"
#include "slam/io/tum_io.h"
#include "slam/odometry/robot_odometry.h"
#include "slam/types/check.h"
#include "slam/types/error.h"
#include "slam/types/interrupt.h"
#include "slam/types/thread_pool.h"
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
  Rules rules;
  rules.NonNegative("duration_s", duration_s).Positive("max_duration_s", max_duration_s);
  return rules.errors();
}

std::vector<std::pair<std::string, std::string>> CarmenLogParams(
    const sim::SimulatorOptions& options) {
  const sim::RobotSpec& robot = options.robot;
  return {{"robot_front_laser_max", FormatNumber(robot.lidar.range_max_m)},
          {"robot_frontlaser_offset", FormatNumber(robot.lidar.mount.x_m)},
          // ROBOTLASER1 has no field for these; slamrig's reader applies them to every laser line.
          {"laser_time_increment_s", FormatNumber(robot.lidar.time_increment_s())},
          {"laser_range_min_m", FormatNumber(robot.lidar.range_min_m)},
          {"slamrig_world", options.world.name.empty() ? "unnamed" : options.world.name},
          {"slamrig_robot", robot.name.empty() ? "unnamed" : robot.name},
          {"slamrig_seed", std::to_string(options.seed)}};
}

namespace {

// The one sink of a recording, by format; the concrete one is kept for its counters.
struct RecordSinks {
  std::unique_ptr<slam::CarmenSink> carmen;
  std::unique_ptr<slam::BagSink> bag;
  std::unique_ptr<slam::Ece276aSink> ece276a;
  // The ECE276A layout has no odometry: the summary's comes from the same integration.
  std::optional<slam::RobotOdometry> ece276a_odometry;

  slam::RecordSink& log() {
    return carmen    ? static_cast<slam::RecordSink&>(*carmen)
           : ece276a ? static_cast<slam::RecordSink&>(*ece276a)
                     : *bag;
  }
};

// Opens the sink of `recording.format` in `out_dir` (the log named `run_name`).
void OpenSinks(const sim::SimulatorOptions& options, const RecordingOptions& recording,
               const slam::WheelOdometryOptions& odometry, const std::string& out_dir,
               const std::string& run_name, RecordSinks* sinks) {
  namespace fs = std::filesystem;
  const std::string dir = fs::path(out_dir).string() + "/";
  const sim::RobotSpec& robot = options.robot;
  if (recording.format == RecordingFormat::kEce276a) {
    sinks->ece276a = std::make_unique<slam::Ece276aSink>(
        out_dir, slam::Ece276aWriteOptions{.dataset = recording.ece276a_dataset});
    sinks->ece276a_odometry.emplace(odometry);
  } else if (recording.format == RecordingFormat::kCarmen) {
    slam::CarmenSinkOptions carmen;
    carmen.odometry = odometry;
    carmen.params = CarmenLogParams(options);
    sinks->carmen = std::make_unique<slam::CarmenSink>(dir + run_name, carmen);
  } else {
    slam::BagSinkOptions bag;
    bag.writer.storage = recording.format == RecordingFormat::kMcap ? slam::BagStorage::kMcap
                                                                    : slam::BagStorage::kSqlite3;
    bag.writer.compression = recording.compression;
    bag.writer.topics = recording.topics;
    bag.writer.ticks_per_revolution = robot.encoders.ticks_per_revolution;
    bag.odometry = odometry;
    // A bag from an earlier run is replaced; anything else in the way is an error (BagWriter).
    if (fs::exists(fs::path(dir + run_name) / "metadata.yaml")) fs::remove_all(dir + run_name);
    sinks->bag = std::make_unique<slam::BagSink>(dir + run_name, bag);
  }
}

// The sink's counts of what it wrote, and the odometry's last pose.
void CountRecords(const RecordSinks& sinks, RunSummary* summary) {
  if (sinks.ece276a) {
    summary->num_scans = sinks.ece276a->scans();
    summary->num_odometry = sinks.ece276a->encoder_readings();
    summary->num_imu = sinks.ece276a->imu_samples();
    summary->final_odometry = sinks.ece276a_odometry->pose();
  } else {
    summary->num_scans = sinks.carmen ? sinks.carmen->scans() : sinks.bag->scans();
    summary->num_odometry =
        sinks.carmen ? sinks.carmen->odometry_lines() : sinks.bag->odometry_messages();
    summary->num_imu = sinks.carmen ? sinks.carmen->imu_samples() : sinks.bag->imu_samples();
    summary->final_odometry =
        sinks.carmen ? sinks.carmen->odometry_pose() : sinks.bag->odometry_pose();
  }
}

}  // namespace

std::vector<std::string> RecordingOptions::Validate() const {
  Rules rules;
  if (format == RecordingFormat::kEce276a) {
    rules.NonNegative("ece276a_dataset", ece276a_dataset);
  } else if (format != RecordingFormat::kCarmen) {
    rules.Nested("", topics.Validate());
  }
  return rules.errors();
}

RunSummary RecordSimulation(const sim::SimulatorOptions& options, const RunOptions& run,
                            const std::string& out_dir, const RecordingOptions& recording) {
  SLAMRIG_CHECK_VALID(run, "RunOptions");
  if (const auto errors = recording.Validate(); !errors.empty()) {
    throw ConfigError("recording: " + errors.front());
  }
  namespace fs = std::filesystem;
  fs::create_directories(out_dir);
  const std::string dir = fs::path(out_dir).string() + "/";
  // sim.yaml, written last, marks a complete folder: an earlier recording's must not vouch for
  // a log this one only half replaced.
  fs::remove(dir + "sim.yaml");
  RunSummary summary;

  sim::Simulator sim(options);
  std::optional<sim::CameraRig> rig;
  if (options.robot.camera) rig.emplace(&sim, *options.robot.camera, options.seed);
  auto advance = [&](bool flush) {
    if (!rig) return flush ? sim.Flush() : sim.Step();
    return flush ? rig->Flush() : rig->Step();
  };
  const sim::RobotSpec& robot = options.robot;
  slam::WheelOdometryOptions odometry;
  odometry.robot = sim::NominalOdometry(robot);
  odometry.use_gyro = robot.imu.enabled;
  const std::string run_name = recording.format == RecordingFormat::kCarmen ? "run.log" : "run";
  RecordSinks sinks;
  OpenSinks(options, recording, odometry, out_dir, run_name, &sinks);
  slam::RecordSink& log = sinks.log();

  Trajectory truth_at_scans;
  auto consume = [&](const sim::StepResult& step) {
    for (std::size_t i = 0; i < step.records.size(); ++i) {
      const Record& record = step.records[i];
      const GroundTruthPose truth = step.truth[i].ToGroundTruthPose();
      if (sinks.ece276a_odometry) sinks.ece276a_odometry->Add(record);
      if (const auto* scan = std::get_if<LaserScan>(&record)) {
        truth_at_scans.Append(scan->time, truth.map_from_base);
        log.Add(record, &truth);
      } else {
        log.Add(record, nullptr);
      }
    }
  };

  // The sinks take the records on a thread of their own, a batch of steps at a time, while the
  // simulation makes the next batch: the same records in the same order, so the same bytes.
  // (Declared after what its tasks use: its destructor waits for the task in hand.)
  constexpr std::size_t kBatchSteps = 64;
  std::vector<sim::StepResult> batch;
  slam::BackgroundWorker writer(slam::DefaultThreadCount() > 1);
  auto hand_over = [&] {
    writer.Start([&consume, steps = std::move(batch)] {
      for (const sim::StepResult& step : steps) consume(step);
    });
    batch.clear();
  };

  const double limit_s = run.duration_s > 0.0 ? run.duration_s : run.max_duration_s;
  Pose2 previous = sim.Truth().map_from_base;
  while (sim.time().seconds() < limit_s - 0.5 * sim.step_s()) {
    ThrowIfInterrupted();  // the sinks' destructors remove their temporary files
    if (run.duration_s == 0.0 && sim.drive_finished()) break;
    batch.push_back(advance(false));
    if (batch.size() >= kBatchSteps) hand_over();
    const Pose2 now = sim.Truth().map_from_base;
    summary.path_length_m += (now.translation() - previous.translation()).norm();
    previous = now;
  }
  batch.push_back(advance(true));
  hand_over();
  writer.Wait();
  log.Commit();

  CountRecords(sinks, &summary);
  summary.num_frames = rig ? rig->frames() : 0;
  summary.frames_skipped = sinks.carmen ? sinks.carmen->frames_skipped() : 0;
  summary.duration_s = sim.time().seconds();
  summary.drive_finished = sim.drive_finished();
  summary.final_truth = sim.Truth().map_from_base;
  slam::WriteTum(dir + "truth.tum", truth_at_scans);
  slam::WriteFileAtomically(dir + "world.yaml", sim::WorldSpecToYaml(options.world));
  slam::WriteFileAtomically(dir + "robot.yaml", sim::RobotSpecToYaml(options.robot));
  slam::WriteFileAtomically(dir + "sim.yaml", SimSettingsYaml(options, summary));
  if (sinks.ece276a) {
    summary.files = sinks.ece276a->files();
  } else {
    summary.files.push_back(dir + run_name);
  }
  for (const std::string& name : {std::string("truth.tum"), std::string("world.yaml"),
                                  std::string("robot.yaml"), std::string("sim.yaml")}) {
    summary.files.push_back(dir + name);
  }
  return summary;
}

}  // namespace slamrig::scenario
