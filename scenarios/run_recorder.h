#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "scenarios/scenario_result.h"
#include "slam/io/bag/bag_writer.h"
#include "slam/odometry/robot_odometry.h"
#include "slam/pipeline/estimator.h"
#include "slam/types/pose2.h"
#include "slam/types/records.h"

namespace slamrig::scenario {

/// Options of a RunRecorder.
struct RecorderOptions {
  /// Maps, graphs and landmarks are written every this many seconds of run time (and at the
  /// end); poses, transforms and health values with every scan.
  double map_period_s = 5.0;
  /// Particle clouds are written at most this often (seconds of run time).
  double particles_period_s = 0.1;
  /// The robot's own odometry on /odom from its wheel ticks (and gyro), as slamrig's bags have
  /// it (slam::BagSink); none when the geometry is unknown or invalid.
  std::optional<slam::WheelOdometryOptions> odometry;
};

/// Writes a whole scenario run as one MCAP file of ROS 2 messages (CDR, ros2msg schemas, zstd
/// chunks, summary and message indexes: slam::BagWriter in single-file mode) for Foxglove, on
/// the run's own clock (never the wall clock: the same run gives the same bytes). Frames:
///   map                     the reference (truth) frame; /truth/map, /events, errors;
///   truth/base_link         the true robot (/tf from map), which carries base_link (identity,
///                           /tf_static) and so the sensors' frames (laser, camera);
///   <config>/map            a configuration's results: its own frame placed at the reference
///                           pose of its first scan, so that its values equal <config>.tum; the
///                           static map -> <config>/map is the ATE alignment (known at the end),
///                           so that estimates overlay the truth;
///   <config>/base_link      its online pose (/tf from <config>/map).
/// Topics: the sensor streams as in slamrig's bags (/scan, /odom (the robot's own odometry,
/// from its wheel ticks or as a log has it), /imu, /joint_states, /clock,
/// /ground_truth/odom, camera images), /tf, /tf_static; per configuration /<config>/pose,
/// /<config>/health/<trace> (each scan), /<config>/particles (every particles_period_s),
/// /<config>/map, /<config>/graph,
/// /<config>/landmarks (every map_period_s and at the end), /<config>/path and
/// /<config>/error (at the end); /truth/map and /events. What is only known at the end (the
/// alignment, the errors against it, the true map, the events, the loop closures judged against
/// the truth) is written then, with its own times, in chunks of its own; readers order messages
/// by their indexes.
/// The file is written as `path` + ".partial" and stays there after Finish(); Commit() renames
/// it to `path`. A run killed before leaves only the .partial file (a chunked MCAP without a
/// summary that readers recover up to the last whole chunk); one that throws removes it.
/// The same messages, in the same order, also go to `live` (the run's live view over the
/// Foxglove WebSocket protocol), with or without a file: this class is the one source of a run's
/// messages for both. The live view alone also gets `/live/alignments` (tf2_msgs/TFMessage,
/// latched): `map -> <config>/map` as the identity for each configuration from its first scan, so
/// that its estimate shows in the map frame while the run goes (each is placed at the reference
/// pose of its first scan; the ATE alignment that the file's /tf_static carries is known only at
/// the end, and then comes on /tf_static to the live view too).
class RunRecorder {
 public:
  /// `config_names`: the configurations in runner order. An empty `path` writes no file (then
  /// `live` should be given). Throws OutputError if the file cannot be written.
  RunRecorder(std::string path, std::vector<std::string> config_names, RecorderOptions options,
              slam::MessageSink* live = nullptr);
  ~RunRecorder();
  RunRecorder(const RunRecorder&) = delete;
  RunRecorder& operator=(const RunRecorder&) = delete;

  /// One sensor record, in arrival order.
  void Record(const Record& record);
  /// The reference pose at `time` (map -> truth/base_link, /ground_truth/odom).
  void Truth(Time time, const Pose2& map_from_base);
  /// Configuration `index` took a scan at `time` and answered `estimate`; `map_from_estimator`
  /// places its frame (the reference pose of its first scan).
  void Scan(std::size_t index, Time time, const slam::ScanEstimate& estimate,
            const slam::Estimator& estimator, const Pose2& map_from_estimator);
  /// The end of the run: each configuration's final map, path, graph and landmarks, the
  /// alignments, errors, true map and events; closes the .partial file.
  void Finish(const ScenarioResult& result);
  /// Renames `path`.partial, which Finish() closed, to `path`.
  static void Commit(const std::string& path);

 private:
  struct Config {
    std::string name;
    std::optional<bool> has_covariance;  // decided by the first scan
    double next_map_s = 0.0;
    double next_particles_s = 0.0;
    Time last_time;
    bool announced = false;  // to the live view, in /live/alignments
  };
  struct Late {  // a message written at the end, with its own time
    Time time;
    std::string topic;
    slam::RosType type;
    bool latched;
    std::string payload;
  };

  void Write(const std::string& topic, slam::RosType type, Time time);
  void WriteSnapshot(Config& c, Time time, const slam::Estimator& estimator,
                     const slam::EstimatorView& view, const Pose2& map_from_estimator);
  void FinishConfig(const ScenarioResult& result, const ConfigResult& c, Time end,
                    std::vector<Late>* late);
  void Events(const ScenarioResult& result, std::vector<Late>* late);

  std::string path_;
  std::string created_dir_;  // the folder the constructor made, if it made one
  bool finished_ = false;
  RecorderOptions options_;
  std::unique_ptr<slam::BagWriter> writer_;
  slam::MessageSink* live_ = nullptr;
  std::optional<slam::RobotOdometry> odometry_;
  std::vector<Config> configs_;
  std::optional<Time> first_time_;
  Time last_time_;
  std::string buffer_;
};

/// The configuration's occupancy grid as a nav_msgs/OccupancyGrid in `frame_id`, placed by
/// `frame_from_grid` (the grid's own frame in frame_id), cropped to the box of observed cells:
/// cells with log-odds 0 are unknown (-1), the others their occupancy probability in percent,
/// rounded.
slam::RosOccupancyGrid ToRosGrid(const slam::OccupancyGrid& grid, Time time,
                                 const std::string& frame_id, const Pose2& frame_from_grid);

}  // namespace slamrig::scenario
