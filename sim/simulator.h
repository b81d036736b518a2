#pragma once

#include <cstdint>
#include <deque>
#include <list>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sim/driver.h"
#include "sim/encoder_model.h"
#include "sim/imu_model.h"
#include "sim/lidar_model.h"
#include "sim/ray_caster.h"
#include "sim/robot.h"
#include "sim/robot_spec.h"
#include "sim/truth_sample.h"
#include "sim/world.h"
#include "sim/world_spec.h"
#include "slam/types/records.h"

namespace slamrig::sim {

/// Everything a simulated run needs.
struct SimulatorOptions {
  WorldSpec world;                 ///< geometry, zones, obstacles, spawn, default drive
  RobotSpec robot;                 ///< body, wheels, motors and sensors
  std::uint64_t seed = 1;          ///< every noise stream derives from it
  double physics_rate_hz = 200.0;  ///< Box2D and tyre steps per second
  int traction_iterations = 10;    ///< sequential-impulse passes over the wheels per step
  int velocity_iterations = 8;     ///< Box2D contact solver
  int position_iterations = 3;     ///< Box2D contact solver

  /// One message per broken rule, field names as in the files ("robot.motor.kp_n_m_s_rad = ...").
  std::vector<std::string> Validate() const;
};

/// What one Step() releases: sensor records in time order, each with the ground truth at its
/// time (truth[i] belongs to records[i]). Records come out in non-decreasing time over the whole
/// run; a lidar scan is stamped with its first beam's time (REP-117), so records after that time
/// are held back until the scan is complete.
struct StepResult {
  Time time;                       ///< simulation time after the step
  std::vector<Record> records;     ///< time-ordered sensor records
  std::vector<TruthSample> truth;  ///< the ground truth at each record's time
};

/// A headless simulated run on its own clock (no wall time): Box2D world, robot, driver and
/// sensors (wheel encoders, IMU, lidar), advanced one physics step at a time so that a caller
/// (the scenario runner, SLAM in-process) consumes the records on the same clock. Each noise source
/// has its own random stream derived from the seed, so equal options give bit-identical records.
/// Sensor k of a kind with rate f fires at k / f seconds (k >= 1; lidar scans start at k >= 0).
class Simulator {
 public:
  /// Builds the world and the robot; `options` must be valid (checked), and an imported map must
  /// be readable (ParseError).
  explicit Simulator(const SimulatorOptions& options);
  ~Simulator();
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  /// Advances one physics step and returns the records released by it.
  StepResult Step();
  /// Releases the records still held back at the end of a run (an unfinished scan is dropped).
  StepResult Flush();

  /// Moves the robot to `map_from_base` at rest, now (a kidnapping, for relocalisation tests).
  /// Records up to now keep the old pose; interpolation never sweeps across the jump.
  void Teleport(const Pose2& map_from_base);

  /// Drive with this command instead of the world's driver (nullopt: back to the driver).
  void SetCommandOverride(std::optional<VelocityCommand> command) { override_ = command; }

  /// Current simulation time (0 at the start).
  Time time() const { return time_; }
  /// Every record stamped before this time has been released by Step() (a scan in progress holds
  /// the later ones back); a source that merges its own records into the stream waits for it.
  Time released_before() const;
  /// The physics step length, seconds.
  double step_s() const { return step_s_; }
  /// Ground truth now.
  TruthSample Truth() const;
  /// True once the world's driver has completed its path or schedule.
  bool drive_finished() const { return driver_.finished(); }

  /// The options it was built with.
  const SimulatorOptions& options() const { return options_; }
  /// The Box2D world (walls, obstacles, zones).
  const World& world() const { return *world_; }
  /// The robot (body and wheel state).
  const Robot& robot() const { return *robot_; }
  /// The world's driver (progress, laps).
  const Driver& driver() const { return driver_; }

 private:
  struct Snapshot {
    Time time;
    double x_m = 0.0, y_m = 0.0, yaw_rad = 0.0;  // yaw unwrapped
    Eigen::Vector2d velocity_m_s = Eigen::Vector2d::Zero();
    double yaw_rate_rad_s = 0.0;
    std::vector<WheelState> wheels;
    bool jump_before = false;  // a teleport happened in the interval ending here
  };
  struct Pending {
    Record record;
    TruthSample truth;
  };

  Snapshot TakeSnapshot() const;
  // The history interval holding `time` and the fraction into it.
  std::pair<std::size_t, double> Locate(Time time) const;
  TruthSample TruthAt(Time time) const;
  void Emit(Record record, std::vector<float> true_ranges_m = {});
  void MeasureEncoders();
  void MeasureImu();
  void MeasureLidar();
  Time ScanStart(std::int64_t k) const;
  Time ScanEnd(std::int64_t k) const;
  StepResult Release(bool all);

  SimulatorOptions options_;
  std::unique_ptr<World> world_;
  std::unique_ptr<Robot> robot_;
  std::unique_ptr<RayCaster> caster_;
  Driver driver_;
  std::optional<EncoderModel> encoders_;
  std::optional<ImuModel> imu_;
  std::optional<LidarModel> lidar_;
  std::optional<VelocityCommand> override_;

  Time time_;
  std::int64_t step_ns_ = 0;
  double step_s_ = 0.0;
  std::deque<Snapshot> history_;
  std::int64_t encoder_period_ns_ = 0, imu_period_ns_ = 0, scan_period_ns_ = 0;
  std::int64_t next_encoder_ = 1, next_imu_ = 1, next_scan_ = 0;
  std::list<Pending> pending_;  // sorted by time
  bool teleported_ = false;     // the next snapshot follows a jump
  std::vector<Ray> rays_;
  std::vector<double> true_ranges_;
};

}  // namespace slamrig::sim
