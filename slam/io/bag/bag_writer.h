#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "slam/io/bag/mcap_writer.h"
#include "slam/io/bag/message_sink.h"
#include "slam/io/bag/ros_messages.h"
#include "slam/io/dataset.h"
#include "slam/types/records.h"

namespace slamrig::slam {

/// rosbag2's two storage plugins.
enum class BagStorage { kMcap, kSqlite3 };

/// "mcap" or "sqlite3", as metadata.yaml's storage_identifier spells it.
std::string_view BagStorageName(BagStorage storage);

/// Topic names of a bag, with the usual ROS defaults.
struct BagTopicNames {
  std::string scan = "/scan";                             ///< sensor_msgs/msg/LaserScan
  std::string imu = "/imu";                               ///< sensor_msgs/msg/Imu
  std::string joint_states = "/joint_states";             ///< sensor_msgs/msg/JointState (wheels)
  std::string odom = "/odom";                             ///< nav_msgs/msg/Odometry
  std::string ground_truth = "/ground_truth/odom";        ///< nav_msgs/msg/Odometry, map frame
  std::string tf = "/tf";                                 ///< tf2_msgs/msg/TFMessage, odom -> base
  std::string tf_static = "/tf_static";                   ///< tf2_msgs/msg/TFMessage, base -> laser
  std::string clock = "/clock";                           ///< rosgraph_msgs/msg/Clock
  std::string rgb = "/camera/color/image_raw";            ///< sensor_msgs/msg/Image, rgb8
  std::string depth = "/camera/depth/image_raw";          ///< sensor_msgs/msg/Image, 32FC1 metres
  std::string camera_info = "/camera/color/camera_info";  ///< sensor_msgs/msg/CameraInfo

  /// One RuleViolation() message per name that is not an absolute ROS name, or is repeated.
  std::vector<std::string> Validate() const;

  /// The name stored under `key` (scan, imu, joint_states, odom, ground_truth, tf, tf_static,
  /// clock: the field names), or nullptr for another key.
  std::string* Find(std::string_view key);
  /// The keys Find() knows, comma-separated, for error messages.
  static const char* Keys();
};

/// Frame names (REP-105).
struct BagFrames {
  std::string map = "map";
  std::string odom = "odom";
  std::string base = "base_link";
  std::string laser = "laser";
  std::string imu = "base_link";                      ///< the IMU is aligned with base_link
  std::string camera = "camera_color_optical_frame";  ///< RGB images and camera info
  std::string depth = "camera_depth_optical_frame";   ///< depth images

  /// One RuleViolation() message per empty name.
  std::vector<std::string> Validate() const;
};

/// Options of BagWriter.
struct BagWriterOptions {
  BagStorage storage = BagStorage::kMcap;
  /// MCAP chunk compression (the sqlite3 storage is never compressed).
  McapCompression compression = McapCompression::kZstd;
  /// MCAP chunk size before compression.
  std::size_t chunk_size_bytes = 768 * 1024;
  BagTopicNames topics;
  BagFrames frames;
  /// Encoder ticks per wheel revolution: JointState positions are ticks * 2 pi / this.
  double ticks_per_revolution = 360.0;
  /// /tf (odom -> base_link) with every odometry pose, /tf_static (base_link -> laser).
  bool write_tf = true;
  /// Rate of /clock messages, stamped with record times; 0 writes none.
  double clock_rate_hz = 100.0;
  /// MCAP only: write one .mcap file at the writer's path instead of a rosbag2 folder: no
  /// metadata.yaml and no rename; the caller picks a temporary name and renames it after
  /// Commit(). Destroying an uncommitted writer removes the file.
  bool single_file = false;

  /// One RuleViolation() message per broken rule; empty when valid.
  std::vector<std::string> Validate() const;
};

/// Names of the wheel joints in a JointState for `right` and `left` wheels per side, right side
/// first: (1, 1) gives right_wheel, left_wheel; (2, 2) gives wheel_fr, wheel_rr, wheel_fl,
/// wheel_rl (front to back, as WheelTicks orders them); other counts give wheel_right_<i>,
/// wheel_left_<i>.
std::vector<std::string> WheelJointNames(std::size_t right, std::size_t left);

/// Key under which a bag records the encoder ticks per revolution its JointState positions use:
/// in metadata.yaml's custom_data (also stored in the sqlite3 metadata table) and in the MCAP
/// channel metadata of the joint_states topic.
inline constexpr const char* kTicksKey = "slamrig.ticks_per_revolution";

/// Which side a joint named by WheelJointNames() is on: true right, false left, nullopt unknown.
std::optional<bool> WheelJointIsRight(std::string_view name);

/// A record sink that writes a ROS 2 bag folder, as `ros2 bag record` would: `metadata.yaml`
/// and `NAME_0.mcap` or `NAME_0.db3`, NAME being the folder's name. Records map to messages as:
///   LaserScan -> /scan (sensor_msgs/msg/LaserScan, float32 fields, see EncodeLaserScan);
///   RgbdFrame -> the rgb8 and 32FC1 sensor_msgs/msg/Image and the CameraInfo (see
///     EncodeRgbImage, EncodeDepthImage, EncodeCameraInfo);
///   /tf_static whenever base_from_laser or a frame's camera mounting changes: every static
///     transform known so far in one message (a late subscriber of the latched topic sees only
///     the last), base_link -> laser (planar) and base_link -> the colour and depth optical
///     frames (BaseFromRgbOptical, BaseFromDepthOptical; quaternion with w >= 0);
///   ImuSample -> /imu (sensor_msgs/msg/Imu, no orientation);
///   WheelTicks -> /joint_states (sensor_msgs/msg/JointState): each wheel's position in radians
///     is its accumulated ticks since the first record times 2 pi / ticks_per_revolution, so a
///     reader recovers the integer ticks exactly by rounding (position * ticks_per_revolution /
///     2 pi) for any count below 2^50;
///   OdometryPose -> /odom (nav_msgs/msg/Odometry, odom -> base_link) and /tf; the yaw as a
///     quaternion, which reads back within a few ulps (see YawFromQuaternion);
///   GroundTruthPose -> /ground_truth/odom (nav_msgs/msg/Odometry, map -> base_link);
///   and /clock at `clock_rate_hz`.
/// Each message's log time, publish time and header stamp are the record's time. Nothing
/// appears at `folder` until Commit(): the bag is written in a sibling temporary folder and
/// renamed into place; destroying an uncommitted writer removes it.
/// Every message written also goes to the sinks added with AddSink(), in the same order; a
/// writer made without a folder writes no file and only feeds its sinks.
class BagWriter {
 public:
  /// Throws ConfigError if the options are invalid, std::runtime_error if `folder` exists or
  /// cannot be written.
  BagWriter(std::string folder, BagWriterOptions options);
  /// The same messages as an MCAP stream through `output` (McapWriter's stream form: unchunked,
  /// no summary, no folder and no metadata.yaml); storage must be mcap. Commit() ends the
  /// stream (DataEnd, Footer, magic).
  BagWriter(McapWriter::Output output, BagWriterOptions options);
  /// A writer without storage: the messages go only to the sinks (options.storage and
  /// single_file do not matter). Throws ConfigError if the options are invalid.
  explicit BagWriter(BagWriterOptions options);
  ~BagWriter();
  BagWriter(const BagWriter&) = delete;
  BagWriter& operator=(const BagWriter&) = delete;

  /// Writes one sensor record. Throws std::invalid_argument for a time before 0 or a WheelTicks
  /// whose wheel count differs from the first one's.
  void Write(const Record& record);
  /// Writes one reference pose to the ground-truth topic.
  void Write(const GroundTruthPose& truth);
  /// Writes one CDR payload of `type` on `topic` (registered on first use; transient-local QoS
  /// when `latched`), with log, publish and header time `time`. Messages may be written out of
  /// time order: MCAP readers order them by their indexes.
  void WriteMessage(const std::string& topic, RosType type, bool latched, Time time,
                    std::string_view cdr);
  /// Adds a planar transform to the ones /tf_static carries, and writes /tf_static at `time`.
  void AddStaticTransform(const RosTransform& transform, Time time);
  /// Gives every message from now on also to `sink`, which must outlive the writer.
  void AddSink(MessageSink* sink) { sinks_.push_back(sink); }
  /// Whether a message on `topic` would be used: always with storage, else when a sink wants it
  /// (MessageSink::Wants, asked of every sink). Messages no one wants are not even encoded.
  bool Wants(const std::string& topic, RosType type, bool latched);
  /// MCAP only: closes the open chunk, so that what follows is in chunks of its own.
  void FlushChunk();
  /// MCAP only: one Metadata record `name` with the text pairs of `metadata`.
  void AddMetadata(std::string_view name, const std::map<std::string, std::string>& metadata);
  /// Closes the storage file, writes metadata.yaml and renames the folder into place.
  void Commit();

  /// Messages written so far.
  std::uint64_t message_count() const { return message_count_; }
  /// The time of the last /tf_static message, if one was written.
  std::optional<Time> static_time() const { return static_time_; }

 private:
  struct Topic {
    std::string name;
    std::string type;
    std::string qos;
    RosType ros_type = RosType::kLaserScan;
    bool latched = false;
    std::uint16_t mcap_channel = 0;
    std::int64_t sqlite_id = 0;
    std::uint32_t sequence = 0;
    std::uint64_t count = 0;
  };

  Topic& GetTopic(const std::string& name, int type, bool latched);
  void Emit(Topic& topic, Time time) { Emit(topic, time, buffer_); }
  void Emit(Topic& topic, Time time, std::string_view payload);
  void MaybeClock(Time time);
  std::string MetadataYaml() const;
  std::string TicksText() const;

  std::string folder_;
  std::string tmp_folder_;
  std::string file_name_;
  BagWriterOptions options_;
  std::unique_ptr<class McapWriter> mcap_;
  std::unique_ptr<class SqliteBagWriter> sqlite_;
  std::vector<Topic> topics_;
  std::map<int, std::uint16_t> mcap_schemas_;
  std::vector<MessageSink*> sinks_;
  std::string buffer_;
  void EmitStaticTransforms(Time time);
  std::optional<Pose2> static_laser_;
  std::optional<Eigen::Isometry3d> static_rgb_;    // base_from_optical of the colour camera
  std::optional<Eigen::Isometry3d> static_depth_;  // and of the depth camera
  std::vector<RosTransform> static_extra_;         // AddStaticTransform's
  std::optional<Time> static_time_;
  std::vector<std::int64_t> tick_totals_;
  std::size_t right_wheels_ = 0;
  std::vector<std::string> joint_names_;
  std::vector<double> positions_;
  std::optional<Time> last_clock_;
  std::int64_t clock_period_ns_ = 0;
  std::uint64_t message_count_ = 0;
  std::int64_t start_ns_ = 0, end_ns_ = 0;
  bool committed_ = false;
};

/// Writes `data` as a bag folder: its records and reference poses merged in time order (a
/// reference pose after the records of the same time), then commits.
void WriteBag(const Dataset& data, const std::string& folder, const BagWriterOptions& options);

}  // namespace slamrig::slam
