// Writes the bags the Foxglove cross-check (bag_foxglove_test.sh) reads: one synthetic run as
// MCAP with zstd, lz4 and no compression and as sqlite3, plus expected.json: every message each
// topic must hold, as the ROS 2 message fields an independent decoder must find, computed here
// from the records and the mapping BagWriter documents (not from its encoder).
//
// Usage: slamrig_write_test_bags OUT_DIR [DURATION_S]

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <map>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "slam/io/bag/bag_writer.h"
#include "slam/io/bag/ros_messages.h"
#include "slam/io/bag/testing/synthetic_records.h"

namespace slamrig::slam {
namespace {

std::string Num(double v) {
  char b[40];
  std::snprintf(b, sizeof(b), "%.17g", v);
  return b;
}
std::string F32(double v) { return Num(static_cast<double>(static_cast<float>(v))); }
std::string Str(const std::string& s) { return "\"" + s + "\""; }

std::string Stamp(Time t) {
  return "{\"sec\":" + std::to_string(t.ns / 1'000'000'000) +
         ",\"nanosec\":" + std::to_string(t.ns % 1'000'000'000) + "}";
}
std::string Header(Time t, const std::string& frame) {
  return "{\"stamp\":" + Stamp(t) + ",\"frame_id\":" + Str(frame) + "}";
}
std::string Zeros(int n, double first = 0.0) {
  std::string s = "[";
  for (int i = 0; i < n; ++i) s += (i ? "," : "") + Num(i == 0 ? first : 0.0);
  return s + "]";
}
std::string Vec3(double x, double y, double z) {
  return "{\"x\":" + Num(x) + ",\"y\":" + Num(y) + ",\"z\":" + Num(z) + "}";
}
std::string YawQuat(double yaw) {
  return "{\"x\":0,\"y\":0,\"z\":" + Num(std::sin(0.5 * yaw)) +
         ",\"w\":" + Num(std::cos(0.5 * yaw)) + "}";
}
std::string Odometry(Time t, const std::string& frame, const std::string& child, const Pose2& p) {
  return "{\"header\":" + Header(t, frame) + ",\"child_frame_id\":" + Str(child) +
         ",\"pose\":{\"pose\":{\"position\":" + Vec3(p.x(), p.y(), 0) +
         ",\"orientation\":" + YawQuat(p.theta()) + "},\"covariance\":" + Zeros(36) +
         "},\"twist\":{\"twist\":{\"linear\":" + Vec3(0, 0, 0) + ",\"angular\":" + Vec3(0, 0, 0) +
         "},\"covariance\":" + Zeros(36) + "}}";
}
std::string Tf(Time t, const std::string& parent, const std::string& child, const Pose2& p) {
  return "{\"transforms\":[{\"header\":" + Header(t, parent) + ",\"child_frame_id\":" + Str(child) +
         ",\"transform\":{\"translation\":" + Vec3(p.x(), p.y(), 0) +
         ",\"rotation\":" + YawQuat(p.theta()) + "}}]}";
}

std::string Bytes(const std::uint8_t* data, std::size_t n) {
  std::string s = "[";
  for (std::size_t i = 0; i < n; ++i) s += (i ? "," : "") + std::to_string(data[i]);
  return s + "]";
}
std::string Doubles(std::initializer_list<double> values) {
  std::string s = "[";
  bool first = true;
  for (double v : values) {
    s += (first ? "" : ",") + Num(v);
    first = false;
  }
  return s + "]";
}
// A geometry_msgs/TransformStamped of a 3-D transform: the rotation as Eigen's quaternion with
// w >= 0, the convention BagWriter documents.
std::string Tf3d(Time t, const std::string& parent, const std::string& child,
                 const Eigen::Isometry3d& x) {
  Eigen::Quaterniond q(x.linear());
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const Eigen::Vector3d p = x.translation();
  return "{\"header\":" + Header(t, parent) + ",\"child_frame_id\":" + Str(child) +
         ",\"transform\":{\"translation\":" + Vec3(p.x(), p.y(), p.z()) +
         ",\"rotation\":{\"x\":" + Num(q.x()) + ",\"y\":" + Num(q.y()) + ",\"z\":" + Num(q.z()) +
         ",\"w\":" + Num(q.w()) + "}}}";
}
std::string Image(const RgbdFrame& f, const std::string& frame, const std::string& encoding,
                  int bytes_per_pixel, const std::uint8_t* data) {
  const std::size_t n = static_cast<std::size_t>(f.width) * f.height * bytes_per_pixel;
  return "{\"header\":" + Header(f.time, frame) + ",\"height\":" + std::to_string(f.height) +
         ",\"width\":" + std::to_string(f.width) + ",\"encoding\":" + Str(encoding) +
         ",\"is_bigendian\":0,\"step\":" + std::to_string(bytes_per_pixel * f.width) +
         ",\"data\":" + Bytes(data, n) + "}";
}

// Three small RGB-D frames for the Image, CameraInfo and /tf_static messages: the first before
// any scan (the laser's transform joins the camera's later), the camera remounted for the last.
void AddFrames(Dataset* data) {
  const Time start = RecordTime(data->records.front());
  for (int k = 0; k < 3; ++k) {
    RgbdFrame f;
    f.time = Time::FromNanoseconds(start.ns - 1'000'000 + k * 1'000'000'000LL + 1'234);
    f.width = 5;
    f.height = 3;
    for (int i = 0; i < 15; ++i) {
      f.rgb.insert(f.rgb.end(), {static_cast<std::uint8_t>(17 * i + k), 200, 3});
      f.depth_m.push_back(i == 4 ? 0.0f : 0.5f + 0.25f * static_cast<float>(i));
    }
    f.intrinsics = {4.5, 4.5, 2.25, 1.0};
    f.depth_offset_x_m = 0.025;
    if (k == 2) f.base_from_camera.pitch_rad = 0.5;
    const auto at = std::upper_bound(data->records.begin(), data->records.end(), f.time,
                                     [](Time t, const Record& r) { return t < RecordTime(r); });
    data->records.insert(at, std::move(f));
  }
}

struct Expected {
  std::map<std::string, std::string> type;
  std::map<std::string, std::vector<std::pair<Time, std::string>>> messages;
  void Add(const std::string& topic, const std::string& ros_type, Time t, std::string msg) {
    type[topic] = ros_type;
    messages[topic].emplace_back(t, std::move(msg));
  }
};

Expected Expect(const Dataset& data, const BagWriterOptions& o) {
  Expected e;
  const BagTopicNames& n = o.topics;
  const BagFrames& f = o.frames;
  std::int64_t last_clock = -1;
  const auto clock = [&](Time t) {
    if (last_clock < 0 || t.ns >= last_clock + 10'000'000) {
      last_clock = t.ns;
      e.Add(n.clock, "rosgraph_msgs/msg/Clock", t, "{\"clock\":" + Stamp(t) + "}");
    }
  };
  std::vector<std::int64_t> totals(4, 0);
  bool static_sent = false;
  std::optional<Pose2> laser;
  std::optional<Eigen::Isometry3d> camera, depth_camera;
  // Every static transform known in one message: the laser's planar one (its yaw quaternion)
  // first, then the two optical frames.
  const auto static_tf = [&](Time t) {
    if (!camera) {
      e.Add(n.tf_static, "tf2_msgs/msg/TFMessage", t, Tf(t, f.base, f.laser, *laser));
      return;
    }
    std::string tf = "{\"transforms\":[";
    if (laser) {
      const std::string planar = Tf(t, f.base, f.laser, *laser);
      tf += planar.substr(15, planar.size() - 15 - 2) + ",";
    }
    tf += Tf3d(t, f.base, f.camera, *camera) + "," + Tf3d(t, f.base, f.depth, *depth_camera) + "]}";
    e.Add(n.tf_static, "tf2_msgs/msg/TFMessage", t, tf);
  };
  std::size_t g = 0;
  const auto truth_until = [&](Time t, bool inclusive) {
    while (g < data.reference.size() &&
           (data.reference[g].time < t || (inclusive && data.reference[g].time == t))) {
      const GroundTruthPose& p = data.reference[g++];
      clock(p.time);
      e.Add(n.ground_truth, "nav_msgs/msg/Odometry", p.time,
            Odometry(p.time, f.map, f.base, p.map_from_base));
    }
  };
  for (const Record& r : data.records) {
    const Time t = RecordTime(r);
    truth_until(t, false);
    clock(t);
    if (const auto* s = std::get_if<LaserScan>(&r)) {
      if (!static_sent) {
        static_sent = true;
        laser = s->base_from_laser;
        static_tf(t);
      }
      const double count = static_cast<double>(s->ranges_m.size());
      std::string ranges = "[";
      for (std::size_t i = 0; i < s->ranges_m.size(); ++i) {
        ranges += (i ? "," : "") + F32(s->ranges_m[i]);
      }
      e.Add(n.scan, "sensor_msgs/msg/LaserScan", t,
            "{\"header\":" + Header(t, f.laser) + ",\"angle_min\":" + F32(s->angle_min_rad) +
                ",\"angle_max\":" + F32(s->angle_min_rad + (count - 1.0) * s->angle_increment_rad) +
                ",\"angle_increment\":" + F32(s->angle_increment_rad) + ",\"time_increment\":" +
                F32(s->time_increment_s) + ",\"scan_time\":" + F32(count * s->time_increment_s) +
                ",\"range_min\":" + F32(s->range_min_m) + ",\"range_max\":" + F32(s->range_max_m) +
                ",\"ranges\":" + ranges + "],\"intensities\":[]}");
    } else if (const auto* imu = std::get_if<ImuSample>(&r)) {
      const auto& w = imu->angular_velocity_rad_s;
      const auto& a = imu->linear_acceleration_m_s2;
      e.Add(n.imu, "sensor_msgs/msg/Imu", t,
            "{\"header\":" + Header(t, f.imu) +
                ",\"orientation\":{\"x\":0,\"y\":0,\"z\":0,\"w\":1},\"orientation_covariance\":" +
                Zeros(9, -1.0) + ",\"angular_velocity\":" + Vec3(w.x(), w.y(), w.z()) +
                ",\"angular_velocity_covariance\":" + Zeros(9) +
                ",\"linear_acceleration\":" + Vec3(a.x(), a.y(), a.z()) +
                ",\"linear_acceleration_covariance\":" + Zeros(9) + "}");
    } else if (const auto* ticks = std::get_if<WheelTicks>(&r)) {
      const std::int32_t inc[4] = {ticks->right_ticks[0], ticks->right_ticks[1],
                                   ticks->left_ticks[0], ticks->left_ticks[1]};
      std::string pos = "[";
      for (int i = 0; i < 4; ++i) {
        totals[i] += inc[i];
        pos += (i ? "," : "") + Num(static_cast<double>(totals[i]) *
                                    (2.0 * std::numbers::pi / o.ticks_per_revolution));
      }
      e.Add(n.joint_states, "sensor_msgs/msg/JointState", t,
            "{\"header\":" + Header(t, "") +
                ",\"name\":[\"wheel_fr\",\"wheel_rr\",\"wheel_fl\",\"wheel_rl\"],\"position\":" +
                pos + "],\"velocity\":[],\"effort\":[]}");
    } else if (const auto* frame = std::get_if<RgbdFrame>(&r)) {
      const Eigen::Isometry3d rgb = frame->BaseFromRgbOptical();
      if (!camera || camera->matrix() != rgb.matrix()) {
        camera = rgb;
        depth_camera = frame->BaseFromDepthOptical();
        static_tf(t);
      }
      e.Add(n.rgb, "sensor_msgs/msg/Image", t,
            Image(*frame, f.camera, "rgb8", 3, frame->rgb.data()));
      e.Add(n.depth, "sensor_msgs/msg/Image", t,
            Image(*frame, f.depth, "32FC1", 4,
                  reinterpret_cast<const std::uint8_t*>(frame->depth_m.data())));
      const CameraIntrinsics& k = frame->intrinsics;
      e.Add(n.camera_info, "sensor_msgs/msg/CameraInfo", t,
            "{\"header\":" + Header(t, f.camera) + ",\"height\":" + std::to_string(frame->height) +
                ",\"width\":" + std::to_string(frame->width) +
                ",\"distortion_model\":\"plumb_bob\",\"d\":" + Zeros(5) +
                ",\"k\":" + Doubles({k.fx_px, 0, k.cx_px, 0, k.fy_px, k.cy_px, 0, 0, 1}) +
                ",\"r\":" + Doubles({1, 0, 0, 0, 1, 0, 0, 0, 1}) +
                ",\"p\":" + Doubles({k.fx_px, 0, k.cx_px, 0, 0, k.fy_px, k.cy_px, 0, 0, 0, 1, 0}) +
                ",\"binning_x\":0,\"binning_y\":0,\"roi\":{\"x_offset\":0,\"y_offset\":0,"
                "\"height\":0,\"width\":0,\"do_rectify\":false}}");
    } else if (const auto* odom = std::get_if<OdometryPose>(&r)) {
      e.Add(n.odom, "nav_msgs/msg/Odometry", t, Odometry(t, f.odom, f.base, odom->odom_from_base));
      e.Add(n.tf, "tf2_msgs/msg/TFMessage", t, Tf(t, f.odom, f.base, odom->odom_from_base));
    }
    truth_until(t, true);
  }
  truth_until(Time{INT64_MAX}, true);
  return e;
}

int Main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s OUT_DIR [DURATION_S]\n", argv[0]);
    return 2;
  }
  const std::filesystem::path out = argv[1];
  const double duration = argc > 2 ? std::stod(argv[2]) : 3.0;
  std::filesystem::remove_all(out);
  std::filesystem::create_directories(out);
  Dataset data = testing::SyntheticRun(duration, 7);
  AddFrames(&data);
  BagWriterOptions options;
  options.chunk_size_bytes = 64 * 1024;  // many chunks, so the indexes get exercised
  std::vector<std::string> bags;
  for (const auto& [name, storage, compression] :
       {std::tuple{"mcap_zstd", BagStorage::kMcap, McapCompression::kZstd},
        std::tuple{"mcap_lz4", BagStorage::kMcap, McapCompression::kLz4},
        std::tuple{"mcap_none", BagStorage::kMcap, McapCompression::kNone},
        std::tuple{"sqlite3", BagStorage::kSqlite3, McapCompression::kNone}}) {
    options.storage = storage;
    options.compression = compression;
    WriteBag(data, (out / name).string(), options);
    bags.push_back(name);
  }
  const Expected e = Expect(data, options);
  std::string json = "{\"bags\":[";
  for (std::size_t i = 0; i < bags.size(); ++i) json += (i ? "," : "") + Str(bags[i]);
  json += "],\"topics\":{";
  bool first = true;
  for (const auto& [topic, messages] : e.messages) {
    json +=
        (first ? "" : ",") + Str(topic) + ":{\"type\":" + Str(e.type.at(topic)) + ",\"messages\":[";
    first = false;
    for (std::size_t i = 0; i < messages.size(); ++i) {
      json += (i ? ",\n" : "\n") + std::string("{\"log_time\":\"") +
              std::to_string(messages[i].first.ns) + "\",\"msg\":" + messages[i].second + "}";
    }
    json += "]}";
  }
  json += "}}\n";
  std::ofstream(out / "expected.json") << json;
  std::printf("wrote %zu bags and expected.json to %s\n", bags.size(), out.c_str());
  return 0;
}

}  // namespace
}  // namespace slamrig::slam

int main(int argc, char** argv) { return slamrig::slam::Main(argc, argv); }
