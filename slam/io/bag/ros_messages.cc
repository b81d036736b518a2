#include "slam/io/bag/ros_messages.h"

#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <map>
#include <set>
#include <stdexcept>

#include "slam/io/bag/cdr.h"

namespace slamrig::slam {
namespace {

constexpr std::int64_t kNsPerSecond = 1'000'000'000;

// builtin_interfaces/Time: int32 sec, uint32 nanosec.
void WriteStamp(Time t, CdrWriter* w) {
  if (t.ns < 0 || t.ns / kNsPerSecond > INT32_MAX) {
    throw std::invalid_argument("time " + std::to_string(t.ns) +
                                " ns does not fit builtin_interfaces/Time (0 .. 2^31 s)");
  }
  w->Int32(static_cast<std::int32_t>(t.ns / kNsPerSecond));
  w->Uint32(static_cast<std::uint32_t>(t.ns % kNsPerSecond));
}

Time ReadStamp(CdrReader* r) {
  const std::int64_t sec = r->Int32();
  const std::int64_t nanosec = r->Uint32();
  return Time{sec * kNsPerSecond + nanosec};
}

void WriteHeader(Time t, std::string_view frame_id, CdrWriter* w) {
  WriteStamp(t, w);
  w->String(frame_id);
}

Time ReadHeader(CdrReader* r, std::string* frame_id) {
  const Time t = ReadStamp(r);
  std::string frame = r->String();
  if (frame_id != nullptr) *frame_id = std::move(frame);
  return t;
}

// geometry_msgs/Quaternion of a rotation by `yaw` about z.
void WriteYawQuaternion(double yaw, CdrWriter* w) {
  w->Float64(0.0);
  w->Float64(0.0);
  w->Float64(std::sin(0.5 * yaw));
  w->Float64(std::cos(0.5 * yaw));
}

double ReadYawQuaternion(CdrReader* r) {
  const double x = r->Float64(), y = r->Float64(), z = r->Float64(), w = r->Float64();
  return YawFromQuaternion(x, y, z, w);
}

struct TypeInfo {
  const char* name;    // ROS 2 name
  const char* fields;  // .msg text
};

// The .msg texts (field types and names of ROS 2 Humble's common_interfaces, comments dropped).
const std::map<std::string, std::string>& NestedDefinitions() {
  static const std::map<std::string, std::string> defs = {
      {"builtin_interfaces/Time", "int32 sec\nuint32 nanosec\n"},
      {"std_msgs/Header", "builtin_interfaces/Time stamp\nstring frame_id\n"},
      {"geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z\n"},
      {"geometry_msgs/Point", "float64 x\nfloat64 y\nfloat64 z\n"},
      {"geometry_msgs/Quaternion", "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n"},
      {"geometry_msgs/Pose",
       "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n"},
      {"geometry_msgs/PoseWithCovariance", "geometry_msgs/Pose pose\nfloat64[36] covariance\n"},
      {"geometry_msgs/Twist", "geometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular\n"},
      {"geometry_msgs/TwistWithCovariance", "geometry_msgs/Twist twist\nfloat64[36] covariance\n"},
      {"geometry_msgs/Transform",
       "geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation\n"},
      {"sensor_msgs/RegionOfInterest",
       "uint32 x_offset\nuint32 y_offset\nuint32 height\nuint32 width\nbool do_rectify\n"},
      {"geometry_msgs/TransformStamped",
       "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform\n"},
      {"builtin_interfaces/Duration", "int32 sec\nuint32 nanosec\n"},
      {"geometry_msgs/PoseStamped", "std_msgs/Header header\ngeometry_msgs/Pose pose\n"},
      {"nav_msgs/MapMetaData",
       "builtin_interfaces/Time map_load_time\nfloat32 resolution\nuint32 width\nuint32 height\n"
       "geometry_msgs/Pose origin\n"},
      {"std_msgs/ColorRGBA", "float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n"},
      {"sensor_msgs/CompressedImage", "std_msgs/Header header\nstring format\nuint8[] data\n"},
      {"visualization_msgs/UVCoordinate", "float32 u\nfloat32 v\n"},
      {"visualization_msgs/MeshFile", "string filename\nuint8[] data\n"},
      {"visualization_msgs/Marker",
       "int32 ARROW=0\nint32 CUBE=1\nint32 SPHERE=2\nint32 CYLINDER=3\nint32 LINE_STRIP=4\n"
       "int32 LINE_LIST=5\nint32 CUBE_LIST=6\nint32 SPHERE_LIST=7\nint32 POINTS=8\n"
       "int32 TEXT_VIEW_FACING=9\nint32 MESH_RESOURCE=10\nint32 TRIANGLE_LIST=11\nint32 ADD=0\n"
       "int32 MODIFY=0\nint32 DELETE=2\nint32 DELETEALL=3\nstd_msgs/Header header\nstring ns\n"
       "int32 id\nint32 type\nint32 action\ngeometry_msgs/Pose pose\n"
       "geometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\n"
       "builtin_interfaces/Duration lifetime\nbool frame_locked\ngeometry_msgs/Point[] points\n"
       "std_msgs/ColorRGBA[] colors\nstring texture_resource\n"
       "sensor_msgs/CompressedImage texture\nvisualization_msgs/UVCoordinate[] uv_coordinates\n"
       "string text\nstring mesh_resource\nvisualization_msgs/MeshFile mesh_file\n"
       "bool mesh_use_embedded_materials\n"},
  };
  return defs;
}

constexpr std::size_t kTypeCount = std::size(kAllRosTypes);

const TypeInfo& Info(RosType type) {
  static const std::array<TypeInfo, kTypeCount> infos = {{
      {"sensor_msgs/msg/LaserScan",
       "std_msgs/Header header\nfloat32 angle_min\nfloat32 angle_max\nfloat32 angle_increment\n"
       "float32 time_increment\nfloat32 scan_time\nfloat32 range_min\nfloat32 range_max\n"
       "float32[] ranges\nfloat32[] intensities\n"},
      {"sensor_msgs/msg/Imu",
       "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\n"
       "float64[9] orientation_covariance\ngeometry_msgs/Vector3 angular_velocity\n"
       "float64[9] angular_velocity_covariance\ngeometry_msgs/Vector3 linear_acceleration\n"
       "float64[9] linear_acceleration_covariance\n"},
      {"sensor_msgs/msg/JointState",
       "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\n"
       "float64[] effort\n"},
      {"nav_msgs/msg/Odometry",
       "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose\n"
       "geometry_msgs/TwistWithCovariance twist\n"},
      {"tf2_msgs/msg/TFMessage", "geometry_msgs/TransformStamped[] transforms\n"},
      {"rosgraph_msgs/msg/Clock", "builtin_interfaces/Time clock\n"},
      {"sensor_msgs/msg/Image",
       "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\n"
       "uint8 is_bigendian\nuint32 step\nuint8[] data\n"},
      {"sensor_msgs/msg/CameraInfo",
       "std_msgs/Header header\nuint32 height\nuint32 width\nstring distortion_model\n"
       "float64[] d\nfloat64[9] k\nfloat64[9] r\nfloat64[12] p\nuint32 binning_x\n"
       "uint32 binning_y\nsensor_msgs/RegionOfInterest roi\n"},
      {"geometry_msgs/msg/PoseStamped", "std_msgs/Header header\ngeometry_msgs/Pose pose\n"},
      {"geometry_msgs/msg/PoseWithCovarianceStamped",
       "std_msgs/Header header\ngeometry_msgs/PoseWithCovariance pose\n"},
      {"nav_msgs/msg/Path", "std_msgs/Header header\ngeometry_msgs/PoseStamped[] poses\n"},
      {"geometry_msgs/msg/PoseArray", "std_msgs/Header header\ngeometry_msgs/Pose[] poses\n"},
      {"nav_msgs/msg/OccupancyGrid",
       "std_msgs/Header header\nnav_msgs/MapMetaData info\nint8[] data\n"},
      {"visualization_msgs/msg/MarkerArray", "visualization_msgs/Marker[] markers\n"},
      {"std_msgs/msg/String", "string data\n"},
      {"std_msgs/msg/Float64", "float64 data\n"},
      {"geometry_msgs/msg/Vector3Stamped",
       "std_msgs/Header header\ngeometry_msgs/Vector3 vector\n"},
  }};
  return infos[static_cast<std::size_t>(type)];
}

}  // namespace

std::string_view RosTypeName(RosType type) { return Info(type).name; }

std::optional<RosType> RosTypeFromName(std::string_view name) {
  for (RosType type : kAllRosTypes) {
    const std::string_view full = RosTypeName(type);
    if (name == full) return type;
    // "pkg/msg/Type" -> "pkg/Type"
    const std::size_t slash = full.find('/');
    std::string short_name(full.substr(0, slash));
    short_name += full.substr(full.rfind('/'));
    if (name == short_name) return type;
  }
  return std::nullopt;
}

namespace {

// The non-primitive field types of a .msg text, sorted and unique.
std::set<std::string> FieldTypes(std::string_view fields) {
  static const std::set<std::string_view> kPrimitive = {
      "bool",  "byte",   "char",  "float32", "float64", "int8",   "uint8",
      "int16", "uint16", "int32", "uint32",  "int64",   "uint64", "string"};
  std::set<std::string> types;
  std::size_t line = 0;
  while (line < fields.size()) {
    const std::size_t end = std::min(fields.find('\n', line), fields.size());
    std::string_view type = fields.substr(line, end - line);
    type = type.substr(0, std::min(type.find(' '), type.find('[')));
    if (!type.empty() && !kPrimitive.contains(type)) types.emplace(type);
    line = end + 1;
  }
  return types;
}

// Appends the definitions of the dependencies of `fields` depth first, each once, in sorted
// order at every level, after an empty line and the two-line delimiter (the layout of
// rosbag2_storage_mcap's message definition cache).
void AppendDependencies(std::string_view fields, std::set<std::string>* seen, std::string* text) {
  for (const std::string& type : FieldTypes(fields)) {
    if (!seen->insert(type).second) continue;
    const std::string& nested = NestedDefinitions().at(type);
    *text += "\n" + std::string(80, '=') + "\nMSG: " + type + "\n" + nested;
    AppendDependencies(nested, seen, text);
  }
}

}  // namespace

const std::string& RosMessageDefinition(RosType type) {
  static const std::array<std::string, kTypeCount> texts = [] {
    std::array<std::string, kTypeCount> t;
    for (RosType ty : kAllRosTypes) {
      std::string text = Info(ty).fields;
      std::set<std::string> seen;
      AppendDependencies(Info(ty).fields, &seen, &text);
      t[static_cast<std::size_t>(ty)] = std::move(text);
    }
    return t;
  }();
  return texts[static_cast<std::size_t>(type)];
}

double YawFromQuaternion(double x, double y, double z, double w) {
  if (x != 0.0 || y != 0.0) {
    return std::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
  }
  const double guess = 2.0 * std::atan2(z, w);
  // Try guess, then its neighbours 1, 2, ... ulps away, for the double that encodes to (z, w).
  double up = guess, down = guess;
  for (int i = 0; i < 8; ++i) {
    if (std::sin(0.5 * up) == z && std::cos(0.5 * up) == w) return up;
    if (std::sin(0.5 * down) == z && std::cos(0.5 * down) == w) return down;
    up = std::nextafter(up, INFINITY);
    down = std::nextafter(down, -INFINITY);
  }
  return guess;
}

namespace {

void WriteImage(const RgbdFrame& frame, std::string_view frame_id, const char* encoding,
                std::size_t bytes_per_pixel, std::span<const std::uint8_t> data, CdrWriter* w) {
  WriteHeader(frame.time, frame_id, w);
  w->Uint32(static_cast<std::uint32_t>(frame.height));
  w->Uint32(static_cast<std::uint32_t>(frame.width));
  w->String(encoding);
  w->Uint8(0);  // little-endian
  w->Uint32(static_cast<std::uint32_t>(bytes_per_pixel * static_cast<std::size_t>(frame.width)));
  w->ByteSequence(data);
}

}  // namespace

void EncodeRgbImage(const RgbdFrame& frame, std::string_view frame_id, std::string* out) {
  CdrWriter w(out);
  WriteImage(frame, frame_id, "rgb8", 3, frame.rgb, &w);
}

void EncodeDepthImage(const RgbdFrame& frame, std::string_view frame_id, std::string* out) {
  static_assert(std::endian::native == std::endian::little, "32FC1 data is written as stored");
  CdrWriter w(out);
  WriteImage(frame, frame_id, "32FC1", 4,
             {reinterpret_cast<const std::uint8_t*>(frame.depth_m.data()),
              frame.depth_m.size() * sizeof(float)},
             &w);
}

void EncodeCameraInfo(const RgbdFrame& frame, std::string_view frame_id, std::string* out) {
  CdrWriter w(out);
  WriteHeader(frame.time, frame_id, &w);
  w.Uint32(static_cast<std::uint32_t>(frame.height));
  w.Uint32(static_cast<std::uint32_t>(frame.width));
  w.String("plumb_bob");
  const std::array<double, 5> d = {0.0, 0.0, 0.0, 0.0, 0.0};
  w.Float64Sequence(d);
  const CameraIntrinsics& k = frame.intrinsics;
  const std::array<double, 9> kk = {k.fx_px, 0.0, k.cx_px, 0.0, k.fy_px, k.cy_px, 0.0, 0.0, 1.0};
  const std::array<double, 9> r = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
  const std::array<double, 12> p = {k.fx_px, 0.0, k.cx_px, 0.0, 0.0, k.fy_px,
                                    k.cy_px, 0.0, 0.0,     0.0, 1.0, 0.0};
  w.Float64Array(kk);
  w.Float64Array(r);
  w.Float64Array(p);
  w.Uint32(0);                              // binning_x
  w.Uint32(0);                              // binning_y
  for (int i = 0; i < 4; ++i) w.Uint32(0);  // roi: the whole image
  w.Uint8(0);                               // roi.do_rectify
}

void EncodeLaserScan(const LaserScan& scan, std::string_view frame_id, std::string* out) {
  CdrWriter w(out);
  WriteHeader(scan.time, frame_id, &w);
  const std::size_t n = scan.ranges_m.size();
  const double last = n > 0 ? static_cast<double>(n - 1) : 0.0;
  w.Float32(static_cast<float>(scan.angle_min_rad));
  w.Float32(static_cast<float>(scan.angle_min_rad + last * scan.angle_increment_rad));
  w.Float32(static_cast<float>(scan.angle_increment_rad));
  w.Float32(static_cast<float>(scan.time_increment_s));
  w.Float32(static_cast<float>(static_cast<double>(n) * scan.time_increment_s));
  w.Float32(static_cast<float>(scan.range_min_m));
  w.Float32(static_cast<float>(scan.range_max_m));
  w.Float32Sequence(scan.ranges_m);
  w.Float32Sequence({});
}

LaserScan DecodeLaserScan(std::string_view data, std::string* frame_id) {
  CdrReader r(data);
  LaserScan scan;
  scan.time = ReadHeader(&r, frame_id);
  scan.angle_min_rad = r.Float32();
  r.Float32();  // angle_max: implied by angle_min, the increment and the beam count
  scan.angle_increment_rad = r.Float32();
  scan.time_increment_s = r.Float32();
  r.Float32();  // scan_time
  scan.range_min_m = r.Float32();
  scan.range_max_m = r.Float32();
  scan.ranges_m = r.Float32Sequence();
  r.Float32Sequence();  // intensities
  return scan;
}

void EncodeImu(const ImuSample& imu, std::string_view frame_id, std::string* out) {
  CdrWriter w(out);
  WriteHeader(imu.time, frame_id, &w);
  for (double q : {0.0, 0.0, 0.0, 1.0}) w.Float64(q);
  w.Float64(-1.0);  // orientation_covariance[0] = -1: no orientation estimate (REP-145)
  w.ZeroFloat64Array(8);
  for (int i = 0; i < 3; ++i) w.Float64(imu.angular_velocity_rad_s[i]);
  w.ZeroFloat64Array(9);
  for (int i = 0; i < 3; ++i) w.Float64(imu.linear_acceleration_m_s2[i]);
  w.ZeroFloat64Array(9);
}

ImuSample DecodeImu(std::string_view data) {
  CdrReader r(data);
  ImuSample imu;
  imu.time = ReadHeader(&r, nullptr);
  r.SkipFloat64Array(4);  // orientation
  r.SkipFloat64Array(9);
  for (int i = 0; i < 3; ++i) imu.angular_velocity_rad_s[i] = r.Float64();
  r.SkipFloat64Array(9);
  for (int i = 0; i < 3; ++i) imu.linear_acceleration_m_s2[i] = r.Float64();
  r.SkipFloat64Array(9);
  return imu;
}

void EncodeJointState(Time time, const std::vector<std::string>& names,
                      std::span<const double> positions_rad, std::string* out) {
  CdrWriter w(out);
  WriteHeader(time, "", &w);
  w.Uint32(static_cast<std::uint32_t>(names.size()));
  for (const std::string& name : names) w.String(name);
  w.Float64Sequence(positions_rad);
  w.Float64Sequence({});
  w.Float64Sequence({});
}

RosJointState DecodeJointState(std::string_view data) {
  CdrReader r(data);
  RosJointState js;
  js.time = ReadHeader(&r, nullptr);
  const std::uint32_t n = r.SequenceLength(4);  // a string is at least its length field
  js.names.reserve(n);
  for (std::uint32_t i = 0; i < n; ++i) js.names.push_back(r.String());
  js.positions_rad = r.Float64Sequence();
  r.Float64Sequence();  // velocity
  r.Float64Sequence();  // effort
  return js;
}

void EncodeOdometry(const RosOdometry& odometry, std::string* out) {
  CdrWriter w(out);
  WriteHeader(odometry.time, odometry.frame_id, &w);
  w.String(odometry.child_frame_id);
  w.Float64(odometry.pose.x());
  w.Float64(odometry.pose.y());
  w.Float64(0.0);
  WriteYawQuaternion(odometry.pose.theta(), &w);
  w.ZeroFloat64Array(36);
  w.ZeroFloat64Array(6);  // twist
  w.ZeroFloat64Array(36);
}

RosOdometry DecodeOdometry(std::string_view data) {
  CdrReader r(data);
  RosOdometry odometry;
  odometry.time = ReadHeader(&r, &odometry.frame_id);
  odometry.child_frame_id = r.String();
  const double x = r.Float64(), y = r.Float64();
  r.Float64();  // z
  const double yaw = ReadYawQuaternion(&r);
  odometry.pose = Pose2(x, y, yaw);
  r.SkipFloat64Array(36);
  r.SkipFloat64Array(6);
  r.SkipFloat64Array(36);
  return odometry;
}

RosTransform3d RosTransform3d::From(Time time, std::string parent, std::string child,
                                    const Eigen::Isometry3d& t) {
  RosTransform3d out{time, std::move(parent), std::move(child), t.translation(),
                     Eigen::Quaterniond(t.linear())};
  out.rotation.normalize();
  if (out.rotation.w() < 0.0) out.rotation.coeffs() = -out.rotation.coeffs();
  return out;
}

RosTransform3d RosTransform3d::From(const RosTransform& t) {
  const double yaw = t.parent_from_child.theta();
  return {t.time, t.parent_frame, t.child_frame,
          Eigen::Vector3d(t.parent_from_child.x(), t.parent_from_child.y(), 0.0),
          Eigen::Quaterniond(std::cos(0.5 * yaw), 0.0, 0.0, std::sin(0.5 * yaw))};
}

void EncodeTfMessage(const std::vector<RosTransform3d>& transforms, std::string* out) {
  CdrWriter w(out);
  w.Uint32(static_cast<std::uint32_t>(transforms.size()));
  for (const RosTransform3d& t : transforms) {
    WriteHeader(t.time, t.parent_frame, &w);
    w.String(t.child_frame);
    for (int i = 0; i < 3; ++i) w.Float64(t.translation[i]);
    w.Float64(t.rotation.x());
    w.Float64(t.rotation.y());
    w.Float64(t.rotation.z());
    w.Float64(t.rotation.w());
  }
}

std::vector<RosTransform3d> DecodeTfMessage3d(std::string_view data) {
  CdrReader r(data);
  const std::uint32_t n = r.SequenceLength(72);
  std::vector<RosTransform3d> transforms(n);
  for (RosTransform3d& t : transforms) {
    t.time = ReadHeader(&r, &t.parent_frame);
    t.child_frame = r.String();
    for (int i = 0; i < 3; ++i) t.translation[i] = r.Float64();
    const double x = r.Float64(), y = r.Float64(), z = r.Float64(), w = r.Float64();
    t.rotation = Eigen::Quaterniond(w, x, y, z);
  }
  return transforms;
}

// The planar messages are the spatial ones with z = 0 and a yaw quaternion: one encoder and one
// decoder write and read the bytes, so the two can never disagree.
void EncodeTfMessage(const std::vector<RosTransform>& transforms, std::string* out) {
  std::vector<RosTransform3d> spatial;
  spatial.reserve(transforms.size());
  for (const RosTransform& t : transforms) spatial.push_back(RosTransform3d::From(t));
  EncodeTfMessage(spatial, out);
}

std::vector<RosTransform> DecodeTfMessage(std::string_view data) {
  const std::vector<RosTransform3d> spatial = DecodeTfMessage3d(data);
  std::vector<RosTransform> transforms;
  transforms.reserve(spatial.size());
  for (const RosTransform3d& t : spatial) {
    const Eigen::Quaterniond& q = t.rotation;
    transforms.push_back({t.time, t.parent_frame, t.child_frame,
                          Pose2(t.translation.x(), t.translation.y(),
                                YawFromQuaternion(q.x(), q.y(), q.z(), q.w()))});
  }
  return transforms;
}

namespace {

// geometry_msgs/Pose of a planar pose.
void WritePose(const Pose2& pose, CdrWriter* w) {
  w->Float64(pose.x());
  w->Float64(pose.y());
  w->Float64(0.0);
  WriteYawQuaternion(pose.theta(), w);
}

void WriteColor(const RosColor& c, CdrWriter* w) {
  w->Float32(c.r);
  w->Float32(c.g);
  w->Float32(c.b);
  w->Float32(c.a);
}

void WriteMarker(const RosMarker& m, CdrWriter* w) {
  WriteHeader(m.time, m.frame_id, w);
  w->String(m.ns);
  w->Int32(m.id);
  w->Int32(m.type);
  w->Int32(m.action);
  WritePose(m.pose, w);
  for (int i = 0; i < 3; ++i) w->Float64(m.scale[i]);
  WriteColor(m.color, w);
  w->Int32(0);   // lifetime.sec: 0 = forever
  w->Uint32(0);  // lifetime.nanosec
  w->Uint8(0);   // frame_locked
  w->Uint32(static_cast<std::uint32_t>(m.points.size()));
  for (const Eigen::Vector2d& p : m.points) {
    w->Float64(p.x());
    w->Float64(p.y());
    w->Float64(0.0);
  }
  w->Uint32(static_cast<std::uint32_t>(m.colors.size()));
  for (const RosColor& c : m.colors) WriteColor(c, w);
  w->String("");                // texture_resource
  WriteHeader(Time{0}, "", w);  // texture: an empty CompressedImage
  w->String("");                // texture.format
  w->ByteSequence({});          // texture.data
  w->Uint32(0);                 // uv_coordinates
  w->String(m.text);
  w->String("");        // mesh_resource
  w->String("");        // mesh_file.filename
  w->ByteSequence({});  // mesh_file.data
  w->Uint8(0);          // mesh_use_embedded_materials
}

}  // namespace

void EncodePoseStamped(Time time, std::string_view frame_id, const Pose2& pose, std::string* out) {
  CdrWriter w(out);
  WriteHeader(time, frame_id, &w);
  WritePose(pose, &w);
}

void EncodePoseWithCovarianceStamped(Time time, std::string_view frame_id, const Pose2& pose,
                                     const Eigen::Matrix3d& covariance, std::string* out) {
  CdrWriter w(out);
  WriteHeader(time, frame_id, &w);
  WritePose(pose, &w);
  // ROS order (x, y, z, rotation about x, y, z): the planar (x, y, yaw) sit at 0, 1 and 5.
  constexpr int kIndex[3] = {0, 1, 5};
  std::array<double, 36> full{};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c)
      full[static_cast<std::size_t>(kIndex[r] * 6 + kIndex[c])] = covariance(r, c);
  }
  w.Float64Array(full);
}

void EncodePath(Time time, std::string_view frame_id, std::span<const StampedPose> poses,
                std::string* out) {
  CdrWriter w(out);
  WriteHeader(time, frame_id, &w);
  w.Uint32(static_cast<std::uint32_t>(poses.size()));
  for (const StampedPose& p : poses) {
    WriteHeader(p.time, frame_id, &w);
    WritePose(p.pose, &w);
  }
}

void EncodePoseArray(Time time, std::string_view frame_id, std::span<const Pose2> poses,
                     std::string* out) {
  CdrWriter w(out);
  WriteHeader(time, frame_id, &w);
  w.Uint32(static_cast<std::uint32_t>(poses.size()));
  for (const Pose2& p : poses) WritePose(p, &w);
}

void EncodeOccupancyGrid(const RosOccupancyGrid& grid, std::string* out) {
  if (grid.data.size() != static_cast<std::size_t>(grid.width) * grid.height) {
    throw std::invalid_argument("occupancy grid: " + std::to_string(grid.data.size()) +
                                " cells for " + std::to_string(grid.width) + " x " +
                                std::to_string(grid.height));
  }
  CdrWriter w(out);
  WriteHeader(grid.time, grid.frame_id, &w);
  WriteStamp(grid.time, &w);
  w.Float32(grid.resolution_m);
  w.Uint32(grid.width);
  w.Uint32(grid.height);
  WritePose(grid.origin, &w);
  w.ByteSequence({reinterpret_cast<const std::uint8_t*>(grid.data.data()), grid.data.size()});
}

Pose2 RosPoseStamped::Planar() const {
  return Pose2(position.x(), position.y(), YawFromQuaternion(qx, qy, qz, qw));
}

RosPoseStamped DecodePoseStamped(std::string_view data) {
  CdrReader r(data);
  RosPoseStamped pose;
  pose.time = ReadHeader(&r, &pose.frame_id);
  for (int i = 0; i < 3; ++i) pose.position[i] = r.Float64();
  pose.qx = r.Float64();
  pose.qy = r.Float64();
  pose.qz = r.Float64();
  pose.qw = r.Float64();
  return pose;
}

RosOccupancyGrid DecodeOccupancyGrid(std::string_view data) {
  CdrReader r(data);
  RosOccupancyGrid grid;
  grid.time = ReadHeader(&r, &grid.frame_id);
  ReadStamp(&r);  // map_load_time
  grid.resolution_m = r.Float32();
  grid.width = r.Uint32();
  grid.height = r.Uint32();
  const double x = r.Float64(), y = r.Float64();
  r.Float64();  // z
  grid.origin = Pose2(x, y, ReadYawQuaternion(&r));
  const std::string cells = r.ByteSequence();
  grid.data.resize(cells.size());
  std::memcpy(grid.data.data(), cells.data(), cells.size());
  return grid;
}

void EncodeMarkerArray(std::span<const RosMarker> markers, std::string* out) {
  CdrWriter w(out);
  w.Uint32(static_cast<std::uint32_t>(markers.size()));
  for (const RosMarker& m : markers) WriteMarker(m, &w);
}

void EncodeString(std::string_view text, std::string* out) {
  CdrWriter w(out);
  w.String(text);
}

void EncodeFloat64(double value, std::string* out) {
  CdrWriter w(out);
  w.Float64(value);
}

void EncodeVector3Stamped(Time time, std::string_view frame_id, const Eigen::Vector3d& v,
                          std::string* out) {
  CdrWriter w(out);
  WriteHeader(time, frame_id, &w);
  for (int i = 0; i < 3; ++i) w.Float64(v[i]);
}

void EncodeClock(Time time, std::string* out) {
  CdrWriter w(out);
  WriteStamp(time, &w);
}

Time DecodeClock(std::string_view data) {
  CdrReader r(data);
  return ReadStamp(&r);
}

}  // namespace slamrig::slam
