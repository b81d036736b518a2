#include "slam/io/bag/bag_reader.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <tuple>

#include "slam/config/yaml_node.h"
#include "slam/io/bag/cdr.h"
#include "slam/io/bag/mcap_records.h"
#include "slam/io/bag/raw_bag.h"
#include "slam/io/bag/ros_messages.h"
#include "slam/types/error.h"
#include "slam/types/validation.h"

namespace slamrig::slam {
namespace {

namespace fs = std::filesystem;

enum class FileKind { kMcap, kSqlite, kUnknown };

FileKind Sniff(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[16] = {};
  in.read(head, sizeof(head));
  const std::string_view h(head, static_cast<std::size_t>(in.gcount()));
  if (h.starts_with(std::string_view(mcap::kMagic, sizeof(mcap::kMagic)))) return FileKind::kMcap;
  if (h == std::string_view("SQLite format 3\0", 16)) return FileKind::kSqlite;
  return FileKind::kUnknown;
}

RawBag ReadFile(const std::string& path, std::string_view storage, bool recover_cut) {
  const FileKind kind = Sniff(path);
  if (kind == FileKind::kUnknown) {
    throw ParseError(path + ": byte 0: not a bag: no MCAP magic, no SQLite header");
  }
  if (!storage.empty() && (storage == "mcap") != (kind == FileKind::kMcap)) {
    throw ParseError(path + ": metadata.yaml says storage '" + std::string(storage) +
                     "' but the file is " + (kind == FileKind::kMcap ? "MCAP" : "sqlite3"));
  }
  return kind == FileKind::kMcap ? ReadMcapFile(path, recover_cut)
                                 : ReadSqliteBagFile(path, recover_cut);
}

// A topic as the bag holds it, over all its files.
struct SeenTopic {
  std::string type;
  std::size_t count = 0;
};

// "sensor_msgs/msg/LaserScan" -> "LaserScan".
std::string ShortType(const std::string& type) {
  const std::size_t slash = type.rfind('/');
  return type.empty() ? "no type" : slash == std::string::npos ? type : type.substr(slash + 1);
}

// "/front/scan (LaserScan, 2,400), /odom (Odometry, 2,400)".
std::string TopicList(const std::map<std::string, SeenTopic>& seen) {
  std::string list;
  for (const auto& [name, topic] : seen) {
    list += (list.empty() ? "" : ", ") + name + " (" + ShortType(topic.type) + ", " +
            GroupedCount(topic.count) + ")";
  }
  return list.empty() ? "no topics" : list;
}

// What the bag offers for the read topics that have no messages: per key whose topic is empty,
// the other topics with messages of its type that no key names, as `--topic KEY=NAME` flags
// (the first candidate), and the missing topics' descriptions.
struct TopicHints {
  std::vector<std::string> missing;  // "no sensor_msgs/msg/LaserScan on /scan"
  std::vector<std::string> flags;    // "--topic scan=/front/scan"
  bool scan_elsewhere = false;       // the scans are on another topic
};

TopicHints HintsFor(const BagTopicNames& n, const std::map<std::string, SeenTopic>& seen) {
  // Each key with the word that marks its likeliest candidates.
  const std::vector<std::tuple<const char*, const std::string*, RosType, const char*>> keys = {
      {"scan", &n.scan, RosType::kLaserScan, "scan"},
      {"joint_states", &n.joint_states, RosType::kJointState, "joint"},
      {"odom", &n.odom, RosType::kOdometry, "odom"},
      {"imu", &n.imu, RosType::kImu, "imu"},
      {"ground_truth", &n.ground_truth, RosType::kOdometry, "truth"}};
  TopicHints hints;
  for (const auto& [key, name, type, word] : keys) {
    const auto it = seen.find(*name);
    if (it != seen.end() && it->second.count > 0) continue;
    std::vector<std::string> candidates;
    for (const auto& [other, topic] : seen) {
      bool named = false;
      for (const auto& [k, read, t, w] : keys) named = named || *read == other;
      named = named || other == n.tf || other == n.tf_static || other == n.clock;
      if (!named && topic.count > 0 && RosTypeFromName(topic.type) == type) {
        candidates.push_back(other);
      }
    }
    // Any odometry could stand in for ground truth: that one is never guessed.
    if (candidates.empty() || std::string_view(key) == "ground_truth") continue;
    // Names with the key's word first ("/wheel/odom" before "/truth" for odom), else by name.
    // (A copy: clang 14 cannot capture a structured binding.)
    const std::string_view key_word = word;
    std::stable_partition(candidates.begin(), candidates.end(), [&](const std::string& c) {
      return c.find(key_word) != std::string::npos;
    });
    hints.missing.push_back("no " + std::string(RosTypeName(type)) + " on " + *name);
    hints.flags.push_back("--topic " + std::string(key) + "=" + candidates.front());
    hints.scan_elsewhere = hints.scan_elsewhere || type == RosType::kLaserScan;
  }
  return hints;
}

std::string Joined(const std::vector<std::string>& parts, const std::string& separator) {
  std::string out;
  for (const std::string& p : parts) out += (out.empty() ? "" : separator) + p;
  return out;
}

// Fails when the bag holds messages the reader would have read under other topic names (the
// scans, or any when nothing was read), naming what the bag has and the flags that map them;
// else notes the other topics that --topic would add.
void CheckTopics(const std::string& path, const BagTopicNames& n,
                 const std::map<std::string, SeenTopic>& seen, Dataset* data) {
  const TopicHints hints = HintsFor(n, seen);
  std::size_t messages = 0;
  for (const auto& [name, topic] : seen) messages += topic.count;
  const bool nothing_read = data->records.empty() && data->reference.empty() && messages > 0;
  if (hints.scan_elsewhere || (nothing_read && !hints.flags.empty())) {
    throw ParseError(path + ": " + Joined(hints.missing, ", ") + "; the bag has " +
                     TopicList(seen) + ": try " + Joined(hints.flags, " "));
  }
  for (std::size_t i = 0; i < hints.missing.size(); ++i) {
    data->notes.push_back(hints.missing[i] + " (try " + hints.flags[i] + ")");
  }
}

// The note for a file read up to its cut; throws when nothing before the cut could be read.
std::string CutNote(const std::string& file, const RawBagCut& cut, std::size_t messages,
                    std::size_t scans) {
  const std::string what =
      scans > 0 ? GroupedCount(scans) + " scans" : GroupedCount(messages) + " messages";
  if (cut.all_messages) return file + " " + cut.where + ", after its last message: all " + what;
  if (messages == 0) throw ParseError(file + ": " + cut.where + ", before its first message");
  return file + " " + cut.where + ": recovered " + what + " of an unknown total; the rest is lost";
}

// The storage files of a bag folder and its storage identifier ("" if unknown).
std::vector<std::string> BagFiles(const std::string& folder, std::string* storage,
                                  std::map<std::string, std::string>* custom_data) {
  const fs::path metadata = fs::path(folder) / "metadata.yaml";
  std::vector<std::string> files;
  if (fs::exists(metadata)) {
    try {
      const YamlNode root = YamlNode::LoadFile(metadata.string());
      const YamlNode info = root.Required("rosbag2_bagfile_information");
      *storage = info.Get<std::string>("storage_identifier");
      if (const auto custom = info.Optional("custom_data"); custom && custom->IsMap()) {
        for (const std::string& key : custom->Keys()) {
          (*custom_data)[key] = custom->Get<std::string>(key);
        }
      }
      if (*storage != "mcap" && *storage != "sqlite3") {
        throw ParseError(info.Required("storage_identifier").Where() + ": storage_identifier: '" +
                         *storage + "' is not mcap or sqlite3");
      }
      for (const YamlNode& f : info.Required("relative_file_paths").Elements()) {
        const auto name = f.As<std::string>();
        if (name.empty() || fs::path(name).is_absolute() || name.find("..") != std::string::npos) {
          throw ParseError(f.Where() + ": relative_file_paths: '" + name +
                           "' is not a file inside the bag");
        }
        files.push_back((fs::path(folder) / name).string());
        if (!fs::is_regular_file(files.back())) {
          throw ParseError(f.Where() + ": relative_file_paths: " + files.back() + " not found");
        }
      }
    } catch (const ConfigError& e) {
      throw ParseError(e.what());
    }
    if (files.empty()) throw ParseError(metadata.string() + ": relative_file_paths is empty");
    return files;
  }
  for (const auto& entry : fs::directory_iterator(folder)) {
    const std::string ext = entry.path().extension().string();
    if (ext == ".mcap" || ext == ".db3") files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  if (files.size() != 1) {
    throw ParseError(folder + ": no metadata.yaml and " + std::to_string(files.size()) +
                     " .mcap/.db3 files (expected one)");
  }
  return files;
}

// Turns messages into records; keeps the state that spans messages (and files of one bag).
struct Decoder {
  Decoder(const BagReaderOptions& o, Dataset* d) : options(o), data(d) {}

  std::string file;
  const BagReaderOptions& options;
  double ticks_per_revolution = 360.0;
  Dataset* data;
  std::map<std::string, Pose2> static_tf;  // child frame -> base_from_child
  std::vector<std::int64_t> tick_totals;
  std::vector<bool> joint_is_right;
  std::vector<std::string> joint_names;
  bool warned_no_tf = false;

  std::string Where(const std::string& topic, std::size_t index) const {
    return file + ": topic " + topic + ": message " + std::to_string(index) + ": ";
  }

  void JointState(const std::string& topic, std::size_t index, std::string_view payload) {
    const RosJointState js = DecodeJointState(payload);
    if (js.names.size() != js.positions_rad.size()) {
      throw ParseError(Where(topic, index) + std::to_string(js.names.size()) + " names but " +
                       std::to_string(js.positions_rad.size()) + " positions");
    }
    if (joint_names.empty()) {
      joint_names = js.names;
      for (const std::string& name : js.names) {
        std::optional<bool> right = WheelJointIsRight(name);
        if (!right && name.find("right") != std::string::npos) right = true;
        if (!right && name.find("left") != std::string::npos) right = false;
        if (!right) {
          throw ParseError(Where(topic, index) + "joint '" + name +
                           "' is not a wheel of a known side");
        }
        joint_is_right.push_back(*right);
      }
      tick_totals.assign(js.names.size(), 0);
    } else if (js.names != joint_names) {
      throw ParseError(Where(topic, index) + "joint names differ from the first message's");
    }
    WheelTicks ticks;
    ticks.time = js.time;
    const double ticks_per_rad = ticks_per_revolution / (2.0 * std::numbers::pi);
    for (std::size_t i = 0; i < js.names.size(); ++i) {
      const double t = js.positions_rad[i] * ticks_per_rad;
      if (!std::isfinite(t) || std::abs(t) > 0x1.0p50) {
        throw ParseError(Where(topic, index) + "position[" + std::to_string(i) +
                         "] is not a usable wheel angle");
      }
      const std::int64_t total = std::llround(t);
      const std::int64_t increment = total - tick_totals[i];
      tick_totals[i] = total;
      if (increment > INT32_MAX || increment < INT32_MIN) {
        throw ParseError(Where(topic, index) + "position[" + std::to_string(i) +
                         "] jumps by more than 2^31 ticks");
      }
      (joint_is_right[i] ? ticks.right_ticks : ticks.left_ticks)
          .push_back(static_cast<std::int32_t>(increment));
    }
    data->records.push_back(std::move(ticks));
  }

  void Decode(const std::string& topic, std::size_t index, RosType type, std::string_view payload) {
    const BagTopicNames& n = options.topics;
    if (topic == n.scan) {
      std::string frame;
      LaserScan scan = DecodeLaserScan(payload, &frame);
      const auto it = static_tf.find(frame);
      if (it != static_tf.end()) {
        scan.base_from_laser = it->second;
      } else if (!warned_no_tf) {
        warned_no_tf = true;
        data->notes.push_back("no /tf_static transform " + options.base_frame + " -> '" + frame +
                              "': scans mounted at base_link");
      }
      data->records.push_back(std::move(scan));
    } else if (topic == n.imu) {
      data->records.push_back(DecodeImu(payload));
    } else if (topic == n.joint_states) {
      JointState(topic, index, payload);
    } else if (topic == n.odom) {
      const RosOdometry odom = DecodeOdometry(payload);
      data->records.push_back(OdometryPose{odom.time, odom.pose});
    } else if (topic == n.ground_truth) {
      const RosOdometry odom = DecodeOdometry(payload);
      data->reference.push_back({odom.time, odom.pose});
    } else if (topic == n.tf_static && type == RosType::kTfMessage) {
      for (const RosTransform& t : DecodeTfMessage(payload)) {
        if (t.parent_frame == options.base_frame) static_tf[t.child_frame] = t.parent_from_child;
      }
    }
  }
};

}  // namespace

std::vector<std::string> BagReaderOptions::Validate() const {
  Rules rules;
  rules.Nested("", topics.Validate())
      .Require(ticks_per_revolution >= 0.0 && std::isfinite(ticks_per_revolution),
               "ticks_per_revolution", ticks_per_revolution,
               "must be finite and > 0 (or 0: from the bag)")
      .Require(!base_frame.empty(), "base_frame", "''", "must not be empty");
  return rules.errors();
}

Dataset ReadBag(const std::string& path, const BagReaderOptions& options) {
  const std::vector<std::string> errors = options.Validate();
  if (!errors.empty()) throw ConfigError("bag reader: " + errors.front());
  if (!fs::exists(path)) throw ParseError(path + ": no such file or folder");
  std::string storage;
  std::map<std::string, std::string> custom_data;
  const std::vector<std::string> files = fs::is_directory(path)
                                             ? BagFiles(path, &storage, &custom_data)
                                             : std::vector<std::string>{path};

  Dataset data;
  data.source = path;
  const BagTopicNames& n = options.topics;
  // What each read topic must be.
  const std::map<std::string, RosType> wanted = {
      {n.scan, RosType::kLaserScan},          {n.imu, RosType::kImu},
      {n.joint_states, RosType::kJointState}, {n.odom, RosType::kOdometry},
      {n.ground_truth, RosType::kOdometry},   {n.tf_static, RosType::kTfMessage}};
  std::map<std::string, std::size_t> skipped;
  std::map<std::string, std::string> skipped_type;
  Decoder decoder(options, &data);
  std::map<std::string, SeenTopic> seen;
  for (const std::string& file : files) {
    RawBag bag = ReadFile(file, storage, !options.strict);
    if (bag.cut && file != files.back()) {
      throw ParseError(file + ": " + bag.cut->where + ", and it is not the bag's last file");
    }
    custom_data.merge(bag.custom_data);  // metadata.yaml's entries win
    decoder.ticks_per_revolution = options.ticks_per_revolution;
    if (decoder.ticks_per_revolution == 0.0) {
      decoder.ticks_per_revolution = 360.0;
      if (const auto it = custom_data.find(kTicksKey); it != custom_data.end()) {
        char* end = nullptr;
        const double v = std::strtod(it->second.c_str(), &end);
        if (end == it->second.c_str() || *end != '\0' || !(v > 0.0) || !std::isfinite(v)) {
          throw ParseError(path + ": " + kTicksKey + ": '" + it->second +
                           "' is not a positive number");
        }
        decoder.ticks_per_revolution = v;
      }
    }
    std::vector<std::optional<RosType>> topic_type(bag.topics.size());
    for (std::size_t i = 0; i < bag.topics.size(); ++i) {
      const RawBagTopic& t = bag.topics[i];
      const auto it = wanted.find(t.name);
      if (it == wanted.end()) continue;
      if (RosTypeFromName(t.type) != it->second) {
        throw ParseError(file + ": topic " + t.name + ": type '" + t.type + "', expected " +
                         std::string(RosTypeName(it->second)));
      }
      if (!t.encoding.empty() && t.encoding != "cdr") {
        throw ParseError(file + ": topic " + t.name + ": encoding '" + t.encoding +
                         "', expected cdr");
      }
      topic_type[i] = it->second;
    }
    // Header stamps give the order (equal to log times for bags BagWriter wrote). Decode
    // first, then sort the decoded messages stably by their stamp.
    struct Item {
      std::int64_t time;
      std::size_t message;
      std::size_t index;
    };
    std::vector<std::size_t> per_topic(bag.topics.size(), 0);
    std::size_t scans = 0;
    std::vector<Item> items;
    items.reserve(bag.messages.size());
    for (std::size_t m = 0; m < bag.messages.size(); ++m) {
      const RawBagMessage& msg = bag.messages[m];
      const std::size_t index = per_topic[msg.topic]++;
      scans += topic_type[msg.topic] == RosType::kLaserScan;
      if (!topic_type[msg.topic]) {
        ++skipped[bag.topics[msg.topic].name];
        skipped_type[bag.topics[msg.topic].name] = bag.topics[msg.topic].type;
        continue;
      }
      items.push_back({msg.log_time_ns, m, index});
    }
    std::stable_sort(items.begin(), items.end(),
                     [](const Item& a, const Item& b) { return a.time < b.time; });
    decoder.file = file;
    for (const Item& item : items) {
      const RawBagMessage& msg = bag.messages[item.message];
      const std::string& topic = bag.topics[msg.topic].name;
      try {
        decoder.Decode(topic, item.index, *topic_type[msg.topic], msg.data);
      } catch (const CdrError& e) {
        throw ParseError(decoder.Where(topic, item.index) + e.what());
      }
    }
    for (std::size_t i = 0; i < bag.topics.size(); ++i) {
      SeenTopic& topic = seen[bag.topics[i].name];
      topic.type = bag.topics[i].type;
      topic.count += per_topic[i];
    }
    if (bag.cut) {
      data.truncated = CutNote(file, *bag.cut, bag.messages.size(), scans);
      data.notes.push_back(data.truncated);
    }
  }
  std::stable_sort(data.records.begin(), data.records.end(),
                   [](const Record& a, const Record& b) { return RecordTime(a) < RecordTime(b); });
  std::stable_sort(
      data.reference.begin(), data.reference.end(),
      [](const GroundTruthPose& a, const GroundTruthPose& b) { return a.time < b.time; });
  if (!data.reference.empty()) data.reference_kind = "ground truth (" + n.ground_truth + ")";
  for (const auto& [topic, count] : skipped) {
    data.notes.push_back("skipped topic " + topic + " (" + skipped_type[topic] +
                         "): " + std::to_string(count) + " messages");
  }
  CheckTopics(path, n, seen, &data);
  return data;
}

bool LooksLikeBag(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    if (fs::exists(fs::path(path) / "metadata.yaml", ec)) return true;
    for (const auto& entry : fs::directory_iterator(path, ec)) {
      const std::string ext = entry.path().extension().string();
      if (ext == ".mcap" || ext == ".db3") return true;
    }
    return false;
  }
  return fs::is_regular_file(path, ec) && Sniff(path) != FileKind::kUnknown;
}

}  // namespace slamrig::slam
