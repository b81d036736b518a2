#include "slam/io/bag/bag_writer.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <stdexcept>

#include "slam/io/atomic_file.h"
#include "slam/io/bag/ros_messages.h"
#include "slam/io/bag/sqlite_bag_writer.h"
#include "slam/types/error.h"
#include "slam/types/validation.h"

namespace slamrig::slam {
namespace {

// offered_qos_profiles as rosbag2 (metadata version < 9) stores it: a YAML list, as a string.
// Reliable, keep-last history, volatile (or transient-local for latched /tf_static), every
// duration "infinite".
std::string QosProfile(bool latched) {
  constexpr const char* kInfinite = "    sec: 9223372036\n    nsec: 854775807\n";
  std::string s = "- history: 3\n  depth: 0\n  reliability: 1\n  durability: ";
  s += latched ? "1" : "2";
  s += "\n  deadline:\n";
  s += kInfinite;
  s += "  lifespan:\n";
  s += kInfinite;
  s += "  liveliness: 1\n  liveliness_lease_duration:\n";
  s += kInfinite;
  s += "  avoid_ros_namespace_conventions: false";
  return s;
}

// A YAML double-quoted scalar.
std::string Quote(std::string_view s) {
  std::string q = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') {
      q += '\\';
      q += c;
    } else if (c == '\n') {
      q += "\\n";
    } else {
      q += c;
    }
  }
  return q + "\"";
}

// An absolute ROS topic name: "/" and at least one more character, no trailing "/", no
// blanks or quotes.
bool IsTopicName(const std::string& name) {
  return name.size() >= 2 && name[0] == '/' && name.back() != '/' &&
         name.find_first_of(" \t\n\"'") == std::string::npos;
}

}  // namespace

std::string BagWriter::TicksText() const {
  char text[32];
  std::snprintf(text, sizeof(text), "%.17g", options_.ticks_per_revolution);
  return text;
}

std::string_view BagStorageName(BagStorage storage) {
  return storage == BagStorage::kMcap ? "mcap" : "sqlite3";
}

std::vector<std::string> BagTopicNames::Validate() const {
  Rules rules;
  const std::vector<std::pair<const char*, const std::string*>> names = {
      {"topics.scan", &scan},
      {"topics.imu", &imu},
      {"topics.joint_states", &joint_states},
      {"topics.odom", &odom},
      {"topics.ground_truth", &ground_truth},
      {"topics.tf", &tf},
      {"topics.tf_static", &tf_static},
      {"topics.clock", &clock},
      {"topics.rgb", &rgb},
      {"topics.depth", &depth},
      {"topics.camera_info", &camera_info}};
  for (std::size_t i = 0; i < names.size(); ++i) {
    const auto& [field, name] = names[i];
    rules.Require(IsTopicName(*name), field, "'" + *name + "'",
                  "must be an absolute ROS topic name");
    for (std::size_t j = 0; j < i; ++j) {
      rules.Require(*name != *names[j].second, field, "'" + *name + "'",
                    std::string("must differ from ") + names[j].first);
    }
  }
  return rules.errors();
}

std::string* BagTopicNames::Find(std::string_view key) {
  const std::pair<std::string_view, std::string*> fields[] = {{"scan", &scan},
                                                              {"imu", &imu},
                                                              {"joint_states", &joint_states},
                                                              {"odom", &odom},
                                                              {"ground_truth", &ground_truth},
                                                              {"tf", &tf},
                                                              {"tf_static", &tf_static},
                                                              {"clock", &clock},
                                                              {"rgb", &rgb},
                                                              {"depth", &depth},
                                                              {"camera_info", &camera_info}};
  for (const auto& [name, field] : fields) {
    if (name == key) return field;
  }
  return nullptr;
}

const char* BagTopicNames::Keys() {
  return "scan, imu, joint_states, odom, ground_truth, tf, tf_static, clock, rgb, depth, "
         "camera_info";
}

std::vector<std::string> BagFrames::Validate() const {
  Rules rules;
  for (const auto& [field, value] :
       {std::pair{"map", &map}, std::pair{"odom", &odom}, std::pair{"base", &base},
        std::pair{"laser", &laser}, std::pair{"imu", &imu}, std::pair{"camera", &camera},
        std::pair{"depth", &depth}}) {
    rules.Require(!value->empty(), field, "''", "must not be empty");
  }
  return PrefixErrors("frames", rules.errors());
}

std::vector<std::string> BagWriterOptions::Validate() const {
  Rules rules;
  rules.Nested("", topics.Validate())
      .Nested("", frames.Validate())
      .AtLeast("chunk_size_bytes", chunk_size_bytes, decltype(chunk_size_bytes){1024})
      .Require(!single_file || storage == BagStorage::kMcap, "single_file", "true",
               "needs storage mcap")
      .Require(ticks_per_revolution > 0.0 && std::isfinite(ticks_per_revolution),
               "ticks_per_revolution", ticks_per_revolution, "must be finite and > 0")
      .Require(clock_rate_hz >= 0.0 && std::isfinite(clock_rate_hz), "clock_rate_hz", clock_rate_hz,
               "must be finite and >= 0");
  return rules.errors();
}

std::vector<std::string> WheelJointNames(std::size_t right, std::size_t left) {
  if (right == 1 && left == 1) return {"right_wheel", "left_wheel"};
  if (right == 2 && left == 2) return {"wheel_fr", "wheel_rr", "wheel_fl", "wheel_rl"};
  std::vector<std::string> names;
  for (std::size_t i = 0; i < right; ++i) names.push_back("wheel_right_" + std::to_string(i));
  for (std::size_t i = 0; i < left; ++i) names.push_back("wheel_left_" + std::to_string(i));
  return names;
}

std::optional<bool> WheelJointIsRight(std::string_view name) {
  if (name == "right_wheel" || name == "wheel_fr" || name == "wheel_rr" ||
      name.starts_with("wheel_right_")) {
    return true;
  }
  if (name == "left_wheel" || name == "wheel_fl" || name == "wheel_rl" ||
      name.starts_with("wheel_left_")) {
    return false;
  }
  return std::nullopt;
}

BagWriter::BagWriter(std::string folder, BagWriterOptions options)
    : folder_(std::move(folder)), options_(std::move(options)) {
  const std::vector<std::string> errors = options_.Validate();
  if (!errors.empty()) throw ConfigError("bag writer: " + errors.front());
  namespace fs = std::filesystem;
  while (folder_.size() > 1 && folder_.back() == '/') folder_.pop_back();
  if (options_.single_file) {
    McapWriterOptions mcap_options;
    mcap_options.compression = options_.compression;
    mcap_options.chunk_size_bytes = options_.chunk_size_bytes;
    mcap_ = std::make_unique<McapWriter>(folder_, mcap_options);
    if (options_.clock_rate_hz > 0.0) {
      clock_period_ns_ = std::max<std::int64_t>(1, std::llround(1e9 / options_.clock_rate_hz));
    }
    return;
  }
  if (fs::exists(folder_)) throw std::runtime_error(folder_ + ": already exists");
  tmp_folder_ = folder_ + ".tmp" + std::to_string(::getpid());
  fs::remove_all(tmp_folder_);
  std::error_code ec;
  fs::create_directories(tmp_folder_, ec);
  if (ec) throw OutputError(tmp_folder_ + ": cannot create: " + ec.message());
  const std::string name = fs::path(folder_).filename().string();
  file_name_ = name + (options_.storage == BagStorage::kMcap ? "_0.mcap" : "_0.db3");
  const std::string path = tmp_folder_ + "/" + file_name_;
  if (options_.storage == BagStorage::kMcap) {
    McapWriterOptions mcap_options;
    mcap_options.compression = options_.compression;
    mcap_options.chunk_size_bytes = options_.chunk_size_bytes;
    mcap_ = std::make_unique<McapWriter>(path, mcap_options);
  } else {
    sqlite_ = std::make_unique<SqliteBagWriter>(path);
  }
  if (options_.clock_rate_hz > 0.0) {
    clock_period_ns_ = std::max<std::int64_t>(1, std::llround(1e9 / options_.clock_rate_hz));
  }
}

BagWriter::BagWriter(McapWriter::Output output, BagWriterOptions options)
    : options_(std::move(options)) {
  std::vector<std::string> errors = options_.Validate();
  if (options_.storage != BagStorage::kMcap) errors.push_back("storage: a stream is MCAP");
  if (!errors.empty()) throw ConfigError("bag writer: " + errors.front());
  mcap_ = std::make_unique<McapWriter>(std::move(output), McapWriterOptions{});
  if (options_.clock_rate_hz > 0.0) {
    clock_period_ns_ = std::max<std::int64_t>(1, std::llround(1e9 / options_.clock_rate_hz));
  }
}

BagWriter::BagWriter(BagWriterOptions options) : options_(std::move(options)) {
  const std::vector<std::string> errors = options_.Validate();
  if (!errors.empty()) throw ConfigError("bag writer: " + errors.front());
  if (options_.clock_rate_hz > 0.0) {
    clock_period_ns_ = std::max<std::int64_t>(1, std::llround(1e9 / options_.clock_rate_hz));
  }
}

BagWriter::~BagWriter() {
  // A folder only when there is storage in one (not for a stream or a writer for sinks alone).
  if (!committed_ && !folder_.empty()) {
    mcap_.reset();
    sqlite_.reset();
    std::error_code ec;
    std::filesystem::remove_all(options_.single_file ? folder_ : tmp_folder_, ec);
  }
}

BagWriter::Topic& BagWriter::GetTopic(const std::string& name, int type, bool latched) {
  for (Topic& t : topics_) {
    if (t.name == name) return t;
  }
  const auto ros_type = static_cast<RosType>(type);
  Topic topic;
  topic.name = name;
  topic.type = std::string(RosTypeName(ros_type));
  topic.qos = QosProfile(latched);
  topic.ros_type = ros_type;
  topic.latched = latched;
  if (mcap_) {
    auto it = mcap_schemas_.find(type);
    if (it == mcap_schemas_.end()) {
      it = mcap_schemas_
               .emplace(type,
                        mcap_->AddSchema(topic.type, "ros2msg", RosMessageDefinition(ros_type)))
               .first;
    }
    std::map<std::string, std::string> metadata = {{"offered_qos_profiles", topic.qos}};
    if (ros_type == RosType::kJointState) metadata[kTicksKey] = TicksText();
    topic.mcap_channel = mcap_->AddChannel(it->second, name, "cdr", metadata);
  } else if (sqlite_) {
    topic.sqlite_id =
        sqlite_->AddTopic(name, topic.type, topic.qos, RosMessageDefinition(ros_type));
  }
  topics_.push_back(std::move(topic));
  return topics_.back();
}

void BagWriter::Emit(Topic& topic, Time time, std::string_view payload) {
  const auto t = static_cast<std::uint64_t>(time.ns);
  if (mcap_) {
    mcap_->WriteMessage(topic.mcap_channel, topic.sequence, t, t, payload);
  } else if (sqlite_) {
    sqlite_->WriteMessage(topic.sqlite_id, time.ns, payload);
  }
  for (MessageSink* sink : sinks_)
    sink->Message(topic.name, topic.ros_type, topic.latched, time, payload);
  ++topic.sequence;
  ++topic.count;
  if (message_count_ == 0 || time.ns < start_ns_) start_ns_ = time.ns;
  if (message_count_ == 0 || time.ns > end_ns_) end_ns_ = time.ns;
  ++message_count_;
}

bool BagWriter::Wants(const std::string& topic, RosType type, bool latched) {
  if (mcap_ || sqlite_) return true;
  bool wanted = false;
  for (MessageSink* sink : sinks_) wanted = sink->Wants(topic, type, latched) || wanted;
  return wanted;
}

void BagWriter::MaybeClock(Time time) {
  if (time.ns < 0) {
    throw std::invalid_argument("bag writer: record time " + std::to_string(time.ns) +
                                " ns is before 0");
  }
  if (clock_period_ns_ == 0) return;
  if (last_clock_ && time.ns < last_clock_->ns + clock_period_ns_) return;
  last_clock_ = time;
  if (!Wants(options_.topics.clock, RosType::kClock, false)) return;
  EncodeClock(time, &buffer_);
  Emit(GetTopic(options_.topics.clock, static_cast<int>(RosType::kClock), false), time);
}

void BagWriter::Write(const Record& record) {
  const Time time = RecordTime(record);
  MaybeClock(time);
  const BagFrames& f = options_.frames;
  if (const auto* scan = std::get_if<LaserScan>(&record)) {
    if (!static_laser_ || !(*static_laser_ == scan->base_from_laser)) {
      static_laser_ = scan->base_from_laser;
      EmitStaticTransforms(time);
    }
    if (!Wants(options_.topics.scan, RosType::kLaserScan, false)) return;
    EncodeLaserScan(*scan, f.laser, &buffer_);
    Emit(GetTopic(options_.topics.scan, static_cast<int>(RosType::kLaserScan), false), time);
  } else if (const auto* imu = std::get_if<ImuSample>(&record)) {
    if (!Wants(options_.topics.imu, RosType::kImu, false)) return;
    EncodeImu(*imu, f.imu, &buffer_);
    Emit(GetTopic(options_.topics.imu, static_cast<int>(RosType::kImu), false), time);
  } else if (const auto* ticks = std::get_if<WheelTicks>(&record)) {
    const std::size_t n = ticks->right_ticks.size() + ticks->left_ticks.size();
    if (joint_names_.empty()) {
      right_wheels_ = ticks->right_ticks.size();
      joint_names_ = WheelJointNames(right_wheels_, ticks->left_ticks.size());
      tick_totals_.assign(n, 0);
      positions_.resize(n);
    } else if (ticks->right_ticks.size() != right_wheels_ || n != tick_totals_.size()) {
      throw std::invalid_argument("bag writer: WheelTicks at " + std::to_string(time.ns) +
                                  " ns has a different wheel count than the first one");
    }
    const double rad_per_tick = 2.0 * std::numbers::pi / options_.ticks_per_revolution;
    for (std::size_t i = 0; i < n; ++i) {
      tick_totals_[i] +=
          i < right_wheels_ ? ticks->right_ticks[i] : ticks->left_ticks[i - right_wheels_];
      positions_[i] = static_cast<double>(tick_totals_[i]) * rad_per_tick;
    }
    if (!Wants(options_.topics.joint_states, RosType::kJointState, false)) return;
    EncodeJointState(time, joint_names_, positions_, &buffer_);
    Emit(GetTopic(options_.topics.joint_states, static_cast<int>(RosType::kJointState), false),
         time);
  } else if (const auto* frame = std::get_if<RgbdFrame>(&record)) {
    const Eigen::Isometry3d rgb = frame->BaseFromRgbOptical();
    const Eigen::Isometry3d depth = frame->BaseFromDepthOptical();
    if (!static_rgb_ || static_rgb_->matrix() != rgb.matrix() ||
        static_depth_->matrix() != depth.matrix()) {
      static_rgb_ = rgb;
      static_depth_ = depth;
      EmitStaticTransforms(time);
    }
    if (Wants(options_.topics.rgb, RosType::kImage, false)) {
      EncodeRgbImage(*frame, f.camera, &buffer_);
      Emit(GetTopic(options_.topics.rgb, static_cast<int>(RosType::kImage), false), time);
    }
    if (Wants(options_.topics.depth, RosType::kImage, false)) {
      EncodeDepthImage(*frame, f.depth, &buffer_);
      Emit(GetTopic(options_.topics.depth, static_cast<int>(RosType::kImage), false), time);
    }
    if (Wants(options_.topics.camera_info, RosType::kCameraInfo, false)) {
      EncodeCameraInfo(*frame, f.camera, &buffer_);
      Emit(GetTopic(options_.topics.camera_info, static_cast<int>(RosType::kCameraInfo), false),
           time);
    }
  } else if (const auto* odom = std::get_if<OdometryPose>(&record)) {
    if (Wants(options_.topics.odom, RosType::kOdometry, false)) {
      EncodeOdometry({time, f.odom, f.base, odom->odom_from_base}, &buffer_);
      Emit(GetTopic(options_.topics.odom, static_cast<int>(RosType::kOdometry), false), time);
    }
    if (options_.write_tf && Wants(options_.topics.tf, RosType::kTfMessage, false)) {
      EncodeTfMessage({{time, f.odom, f.base, odom->odom_from_base}}, &buffer_);
      Emit(GetTopic(options_.topics.tf, static_cast<int>(RosType::kTfMessage), false), time);
    }
  }
}

void BagWriter::WriteMessage(const std::string& topic, RosType type, bool latched, Time time,
                             std::string_view cdr) {
  if (time.ns < 0) {
    throw std::invalid_argument("bag writer: " + topic + " at " + std::to_string(time.ns) +
                                " ns is before 0");
  }
  Emit(GetTopic(topic, static_cast<int>(type), latched), time, cdr);
}

void BagWriter::AddStaticTransform(const RosTransform& transform, Time time) {
  static_extra_.push_back(transform);
  EmitStaticTransforms(time);
}

void BagWriter::FlushChunk() {
  if (mcap_) mcap_->FlushChunk();
}

void BagWriter::AddMetadata(std::string_view name,
                            const std::map<std::string, std::string>& metadata) {
  if (!mcap_) throw std::logic_error("bag writer: metadata records need storage mcap");
  mcap_->AddMetadata(name, metadata);
}

void BagWriter::EmitStaticTransforms(Time time) {
  const BagFrames& f = options_.frames;
  static_time_ = time;
  if (!static_extra_.empty()) {
    std::vector<RosTransform3d> all;
    if (static_laser_) {
      all.push_back(RosTransform3d::From(RosTransform{time, f.base, f.laser, *static_laser_}));
    }
    if (static_rgb_) {
      all.push_back(RosTransform3d::From(time, f.base, f.camera, *static_rgb_));
      all.push_back(RosTransform3d::From(time, f.base, f.depth, *static_depth_));
    }
    for (RosTransform t : static_extra_) {
      t.time = time;
      all.push_back(RosTransform3d::From(t));
    }
    EncodeTfMessage(all, &buffer_);
  } else if (!static_rgb_) {
    // The laser alone: the planar message every bag without a camera has always had.
    EncodeTfMessage({{time, f.base, f.laser, *static_laser_}}, &buffer_);
  } else {
    std::vector<RosTransform3d> all;
    if (static_laser_) {
      all.push_back(RosTransform3d::From(RosTransform{time, f.base, f.laser, *static_laser_}));
    }
    all.push_back(RosTransform3d::From(time, f.base, f.camera, *static_rgb_));
    all.push_back(RosTransform3d::From(time, f.base, f.depth, *static_depth_));
    EncodeTfMessage(all, &buffer_);
  }
  Emit(GetTopic(options_.topics.tf_static, static_cast<int>(RosType::kTfMessage), true), time);
}

void BagWriter::Write(const GroundTruthPose& truth) {
  MaybeClock(truth.time);
  if (!Wants(options_.topics.ground_truth, RosType::kOdometry, false)) return;
  EncodeOdometry({truth.time, options_.frames.map, options_.frames.base, truth.map_from_base},
                 &buffer_);
  Emit(GetTopic(options_.topics.ground_truth, static_cast<int>(RosType::kOdometry), false),
       truth.time);
}

std::string BagWriter::MetadataYaml() const {
  const std::string storage(BagStorageName(options_.storage));
  const std::string start = std::to_string(start_ns_);
  const std::string duration = std::to_string(end_ns_ - start_ns_);
  const std::string count = std::to_string(message_count_);
  std::string y = "rosbag2_bagfile_information:\n";
  y += "  version: 6\n";
  y += "  storage_identifier: " + storage + "\n";
  y += "  duration:\n    nanoseconds: " + duration + "\n";
  y += "  starting_time:\n    nanoseconds_since_epoch: " + start + "\n";
  y += "  message_count: " + count + "\n";
  y += "  topics_with_message_count:";
  if (topics_.empty()) y += " []";
  y += "\n";
  for (const Topic& t : topics_) {
    y += "    - topic_metadata:\n";
    y += "        name: " + t.name + "\n";
    y += "        type: " + t.type + "\n";
    y += "        serialization_format: cdr\n";
    y += "        offered_qos_profiles: " + Quote(t.qos) + "\n";
    y += "      message_count: " + std::to_string(t.count) + "\n";
  }
  y += "  compression_format: \"\"\n";
  y += "  custom_data:\n    " + std::string(kTicksKey) + ": " + Quote(TicksText()) + "\n";
  y += "  compression_mode: \"\"\n";
  y += "  relative_file_paths:\n    - " + file_name_ + "\n";
  y += "  files:\n";
  y += "    - path: " + file_name_ + "\n";
  y += "      starting_time:\n        nanoseconds_since_epoch: " + start + "\n";
  y += "      duration:\n        nanoseconds: " + duration + "\n";
  y += "      message_count: " + count + "\n";
  return y;
}

void BagWriter::Commit() {
  if (committed_) return;
  if (!mcap_ && !sqlite_) {  // no storage: nothing to close
    committed_ = true;
    return;
  }
  if (options_.single_file || folder_.empty()) {  // one file, or a stream
    mcap_->Close();
    mcap_.reset();
    committed_ = true;
    return;
  }
  const std::string metadata = MetadataYaml();
  if (mcap_) {
    mcap_->Close();
    mcap_.reset();
  } else {
    sqlite_->Close(metadata, 6);
    sqlite_.reset();
  }
  WriteFileAtomically(tmp_folder_ + "/metadata.yaml", metadata);
  std::error_code ec;
  std::filesystem::rename(tmp_folder_, folder_, ec);
  if (ec) throw OutputError(folder_ + ": cannot rename into place: " + ec.message());
  committed_ = true;
}

void WriteBag(const Dataset& data, const std::string& folder, const BagWriterOptions& options) {
  BagWriter writer(folder, options);
  std::size_t r = 0;
  for (const GroundTruthPose& truth : data.reference) {
    while (r < data.records.size() && RecordTime(data.records[r]) <= truth.time) {
      writer.Write(data.records[r++]);
    }
    writer.Write(truth);
  }
  while (r < data.records.size()) writer.Write(data.records[r++]);
  writer.Commit();
}

}  // namespace slamrig::slam
