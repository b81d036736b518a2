#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "slam/types/records.h"
#include "slam/types/trajectory.h"

namespace slamrig::slam {

/// The ROS 2 message types slamrig writes to and reads from bags.
enum class RosType {
  kLaserScan,
  kImu,
  kJointState,
  kOdometry,
  kTfMessage,
  kClock,
  kImage,
  kCameraInfo,
  kPoseStamped,
  kPoseWithCovarianceStamped,
  kPath,
  kPoseArray,
  kOccupancyGrid,
  kMarkerArray,
  kString,
  kFloat64,
  kVector3Stamped
};

/// All types, in a fixed order.
inline constexpr RosType kAllRosTypes[] = {
    RosType::kLaserScan,     RosType::kImu,
    RosType::kJointState,    RosType::kOdometry,
    RosType::kTfMessage,     RosType::kClock,
    RosType::kImage,         RosType::kCameraInfo,
    RosType::kPoseStamped,   RosType::kPoseWithCovarianceStamped,
    RosType::kPath,          RosType::kPoseArray,
    RosType::kOccupancyGrid, RosType::kMarkerArray,
    RosType::kString,        RosType::kFloat64,
    RosType::kVector3Stamped};

/// The type's ROS 2 name, e.g. "sensor_msgs/msg/LaserScan".
std::string_view RosTypeName(RosType type);

/// The type for a ROS 2 name ("sensor_msgs/msg/LaserScan"; the ROS 1 style
/// "sensor_msgs/LaserScan" is accepted too), or nullopt.
std::optional<RosType> RosTypeFromName(std::string_view name);

/// The full message definition as rosbag2 stores it in MCAP schemas and the sqlite3
/// message_definitions table (encoding "ros2msg"): the type's fields, then every nested type
/// once, depth first and in sorted order at each level, each after an empty line, a line of 80
/// '=' and a `MSG: pkg/Type` line (the layout of rosbag2_storage_mcap's message definition
/// cache). Comments are left out; field types, names and order are the ROS 2 Humble ones.
const std::string& RosMessageDefinition(RosType type);

/// A rigid transform between two named frames at a time (geometry_msgs/TransformStamped, planar).
struct RosTransform {
  Time time;
  std::string parent_frame;
  std::string child_frame;
  Pose2 parent_from_child;
};

/// A transform in full 3-D (a camera's mounting): translation and unit quaternion as written.
struct RosTransform3d {
  Time time;
  std::string parent_frame;
  std::string child_frame;
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();

  /// `t` with its rotation as the quaternion with w >= 0 (Eigen's conversion, sign fixed).
  static RosTransform3d From(Time time, std::string parent, std::string child,
                             const Eigen::Isometry3d& t);
  /// A planar transform exactly as EncodeTfMessage writes it (z = 0, yaw quaternion).
  static RosTransform3d From(const RosTransform& t);
};

/// A nav_msgs/Odometry message reduced to what slamrig carries: stamp, frames and planar pose.
struct RosOdometry {
  Time time;
  std::string frame_id;
  std::string child_frame_id;
  Pose2 pose;
};

/// A sensor_msgs/JointState message's stamp, names and positions (velocity and effort dropped).
struct RosJointState {
  Time time;
  std::vector<std::string> names;
  std::vector<double> positions_rad;
};

// Encoders: each clears `out` and writes one CDR payload. A time before 0 or past 2^31 s cannot
// be a builtin_interfaces/Time and throws std::invalid_argument.

/// sensor_msgs/msg/LaserScan. angle_min, angle_max (= angle_min + (n-1) * increment),
/// angle_increment, time_increment, scan_time (= n * time_increment), range_min and range_max
/// are float32 on the wire: a scan reads back equal only if those values are float-representable.
/// Intensities are left empty.
void EncodeLaserScan(const LaserScan& scan, std::string_view frame_id, std::string* out);
/// sensor_msgs/msg/Imu without orientation (orientation_covariance[0] = -1, REP-145).
void EncodeImu(const ImuSample& imu, std::string_view frame_id, std::string* out);
/// sensor_msgs/msg/JointState with names and positions; velocity and effort empty.
void EncodeJointState(Time time, const std::vector<std::string>& names,
                      std::span<const double> positions_rad, std::string* out);
/// nav_msgs/msg/Odometry with the planar pose (z = 0, yaw quaternion), zero twist and covariances.
void EncodeOdometry(const RosOdometry& odometry, std::string* out);
/// tf2_msgs/msg/TFMessage.
void EncodeTfMessage(const std::vector<RosTransform>& transforms, std::string* out);
/// tf2_msgs/msg/TFMessage of 3-D transforms.
void EncodeTfMessage(const std::vector<RosTransform3d>& transforms, std::string* out);
/// rosgraph_msgs/msg/Clock.
void EncodeClock(Time time, std::string* out);
/// sensor_msgs/Image of `frame`'s colour image ("rgb8", top row first).
void EncodeRgbImage(const RgbdFrame& frame, std::string_view frame_id, std::string* out);
/// sensor_msgs/Image of `frame`'s depth image ("32FC1", metres, 0 = no reading; REP-118 would
/// have NaN there, but 0 is what the depth_image_proc drivers of a Kinect publish).
void EncodeDepthImage(const RgbdFrame& frame, std::string_view frame_id, std::string* out);
/// sensor_msgs/CameraInfo of `frame`'s intrinsics: no distortion ("plumb_bob", five zeros),
/// R identity, P = [K | 0].
void EncodeCameraInfo(const RgbdFrame& frame, std::string_view frame_id, std::string* out);

// The visualisation messages of a recorded run (slamrig run --record): planar poses at z = 0
// with a yaw quaternion, as in EncodeOdometry.

/// geometry_msgs/msg/PoseStamped.
void EncodePoseStamped(Time time, std::string_view frame_id, const Pose2& pose, std::string* out);
/// geometry_msgs/msg/PoseWithCovarianceStamped; `covariance` of (x, y, yaw) fills the rows and
/// columns x, y and rotation about z of the 6x6 matrix, the rest is zero.
void EncodePoseWithCovarianceStamped(Time time, std::string_view frame_id, const Pose2& pose,
                                     const Eigen::Matrix3d& covariance, std::string* out);
/// nav_msgs/msg/Path: each pose a PoseStamped with its own time, all in `frame_id`.
void EncodePath(Time time, std::string_view frame_id, std::span<const StampedPose> poses,
                std::string* out);
/// geometry_msgs/msg/PoseArray.
void EncodePoseArray(Time time, std::string_view frame_id, std::span<const Pose2> poses,
                     std::string* out);

/// A nav_msgs/OccupancyGrid: cells row by row from the origin cell, row = y; values 0..100
/// (occupancy probability in percent) or -1 (unknown).
struct RosOccupancyGrid {
  Time time;
  std::string frame_id;
  float resolution_m = 0.05f;
  std::uint32_t width = 0, height = 0;
  Pose2 origin;  ///< the corner of cell (0, 0) in frame_id
  std::vector<std::int8_t> data;
};
/// nav_msgs/msg/OccupancyGrid (map_load_time = time).
void EncodeOccupancyGrid(const RosOccupancyGrid& grid, std::string* out);

/// An RGBA colour, each in [0, 1].
struct RosColor {
  float r = 0.0f, g = 0.0f, b = 0.0f, a = 1.0f;
};

/// A visualization_msgs/Marker reduced to what slamrig draws: points in the marker's frame
/// (z = 0), a pose, scale, colour, optional per-point colours and text.
struct RosMarker {
  /// Marker::type values (visualization_msgs/Marker's constants).
  enum Type : std::int32_t {
    kArrow = 0,
    kCube = 1,
    kSphere = 2,
    kCylinder = 3,
    kLineStrip = 4,
    kLineList = 5,
    kSphereList = 7,
    kPoints = 8,
    kText = 9,
  };
  Time time;
  std::string frame_id;
  std::string ns;
  std::int32_t id = 0;
  std::int32_t type = kSphere;
  std::int32_t action = 0;  ///< 0 ADD, 2 DELETE, 3 DELETEALL
  Pose2 pose;
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
  RosColor color;
  std::vector<Eigen::Vector2d> points;
  std::vector<RosColor> colors;  ///< one per point, or empty
  std::string text;
};
/// visualization_msgs/msg/MarkerArray (ROS 2 Humble's Marker, lifetime 0 = forever, no
/// texture or mesh).
void EncodeMarkerArray(std::span<const RosMarker> markers, std::string* out);

/// std_msgs/msg/String.
void EncodeString(std::string_view text, std::string* out);
/// std_msgs/msg/Float64.
void EncodeFloat64(double value, std::string* out);
/// geometry_msgs/msg/Vector3Stamped.
void EncodeVector3Stamped(Time time, std::string_view frame_id, const Eigen::Vector3d& v,
                          std::string* out);

// Decoders: throw CdrError (slam/io/bag/cdr.h) when the payload is too short or a length is bad.

/// sensor_msgs/msg/LaserScan into a LaserScan (base_from_laser left at identity); the frame id
/// goes to `frame_id` when given.
LaserScan DecodeLaserScan(std::string_view data, std::string* frame_id = nullptr);
/// sensor_msgs/msg/Imu into an ImuSample (orientation ignored).
ImuSample DecodeImu(std::string_view data);
/// sensor_msgs/msg/JointState.
RosJointState DecodeJointState(std::string_view data);
/// nav_msgs/msg/Odometry. The yaw is recovered from the quaternion (see YawFromQuaternion).
RosOdometry DecodeOdometry(std::string_view data);
/// tf2_msgs/msg/TFMessage.
std::vector<RosTransform> DecodeTfMessage(std::string_view data);
/// tf2_msgs/msg/TFMessage with each transform in full.
std::vector<RosTransform3d> DecodeTfMessage3d(std::string_view data);
/// rosgraph_msgs/msg/Clock.
Time DecodeClock(std::string_view data);

/// A geometry_msgs/msg/PoseStamped as written: stamp, frame and the 3-D position and quaternion,
/// for a reader that checks the pose is planar before taking Planar().
struct RosPoseStamped {
  Time time;
  std::string frame_id;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double qx = 0.0, qy = 0.0, qz = 0.0, qw = 1.0;

  /// (x, y, yaw), the yaw by YawFromQuaternion.
  Pose2 Planar() const;
};
/// geometry_msgs/msg/PoseStamped.
RosPoseStamped DecodePoseStamped(std::string_view data);
/// nav_msgs/msg/OccupancyGrid (map_load_time is not kept; the origin's yaw from its quaternion).
RosOccupancyGrid DecodeOccupancyGrid(std::string_view data);

/// Yaw of the quaternion (x, y, z, w) about z. For a planar quaternion the doubles around
/// 2 atan2(z, w) are searched for one whose (sin(t/2), cos(t/2)) is exactly (z, w), as the
/// encoders write it. That is the yaw that was written in about 96% of cases; otherwise a
/// neighbour within a few ulps that encodes to the very same quaternion (sin and cos of doubles
/// are not injective), so write -> read -> write is byte-identical but a yaw may differ by ulps.
double YawFromQuaternion(double x, double y, double z, double w);

}  // namespace slamrig::slam
