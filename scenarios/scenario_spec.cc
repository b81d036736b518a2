#include "scenarios/scenario_spec.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <sstream>
#include <system_error>

#include "sim/presets.h"
#include "sim/robot_yaml.h"
#include "sim/world_yaml.h"
#include "sim/worldgen/worldgen.h"
#include "slam/config/fields.h"
#include "slam/io/ece276a_reader.h"
#include "slam/types/error.h"

namespace slamrig::scenario {
namespace {

namespace fs = std::filesystem;

// A world or robot given by file name (relative to the scenario), preset name, or inline map.
YamlNode WorldOrRobot(const YamlNode& node, const std::string& scenario_path, const char* folder) {
  if (node.IsMap()) return node;
  const std::string text = node.As<std::string>();
  fs::path p = text;
  if (p.is_relative()) p = fs::path(scenario_path).parent_path() / p;
  std::error_code error;  // e.g. a name too long for the OS: not there either
  if (fs::is_regular_file(p, error)) return YamlNode::LoadFile(p.lexically_normal().string());
  try {
    return YamlNode::LoadFile(sim::FindPresetFile(text, folder));
  } catch (const ConfigError& e) {
    node.Fail("file '" + p.lexically_normal().string() +
              "' does not exist, nor a preset: " + e.what());
  }
}

// The log of `source:`: relative to the scenario file, else to SLAMRIG_DATA_DIR.
std::string ResolveLog(const YamlNode& node, const std::string& scenario_path) {
  const std::string text = node.As<std::string>();
  const fs::path beside = fs::path(scenario_path).parent_path() / text;
  std::error_code error;
  if (fs::path(text).is_relative() && fs::exists(beside, error)) {
    return beside.lexically_normal().string();
  }
  const std::string resolved = slam::ResolveLogPath(text);
  if (!fs::exists(resolved, error) && !slam::LooksLikeEce276a(resolved)) {
    node.Fail("no such log '" + text +
              "' (looked beside the scenario and in SLAMRIG_DATA_DIR = " + slam::DataDir() + ")");
  }
  return resolved;
}

Pose2 ReadPose(const YamlNode& node) {
  return Pose2(node.Get<double>("x_m"), node.Get<double>("y_m"), node.Get<double>("yaw_rad"));
}

// People walking the robot's closed drive path the other way round, evenly spaced, offset to
// the side so that they pass the robot in a corridor.
std::vector<sim::ObstacleSpec> MakeCrowd(const YamlNode& node, const sim::DriveOptions& drive) {
  int count = 4;
  double speed = 0.7, radius = 0.25, offset = 0.8;
  node.Read("count", &count);
  node.Read("speed_m_s", &speed);
  node.Read("radius_m", &radius);
  node.Read("lateral_offset_m", &offset);
  if (count < 1 || count > 200)
    node.Fail("count = " + std::to_string(count) + "; must be in [1, 200]");
  if (!(speed > 0.0)) node.Fail("speed_m_s must be > 0");
  if (!(radius > 0.0)) node.Fail("radius_m must be > 0");
  if (drive.waypoints_m.size() < 2)
    node.Fail("a crowd walks the drive path: the world needs waypoints");
  // The path reversed and shifted to its right-hand side as walked (the robot's left).
  std::vector<Eigen::Vector2d> path(drive.waypoints_m.rbegin(), drive.waypoints_m.rend());
  const std::size_t n = path.size();
  std::vector<Eigen::Vector2d> shifted(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d in = (path[i] - path[(i + n - 1) % n]).normalized();
    const Eigen::Vector2d out = (path[(i + 1) % n] - path[i]).normalized();
    Eigen::Vector2d normal = Eigen::Vector2d(in.y(), -in.x()) + Eigen::Vector2d(out.y(), -out.x());
    normal = normal.norm() > 1e-9 ? normal.normalized() : Eigen::Vector2d(out.y(), -out.x());
    const double cos_half = std::max(0.3, normal.dot(Eigen::Vector2d(out.y(), -out.x())));
    shifted[i] = path[i] + normal * (offset / cos_half);
  }
  double length = 0.0;
  for (std::size_t i = 0; i < n; ++i) length += (shifted[(i + 1) % n] - shifted[i]).norm();
  std::vector<sim::ObstacleSpec> crowd;
  for (int k = 0; k < count; ++k) {
    // Start person k a fraction k / count along the loop: rotate the vertex list to the segment
    // holding that point and start there.
    const double start = length * (k + 0.5) / count;
    double s = 0.0;
    std::size_t seg = 0;
    while (seg < n && s + (shifted[(seg + 1) % n] - shifted[seg]).norm() < start) {
      s += (shifted[(seg + 1) % n] - shifted[seg]).norm();
      ++seg;
    }
    seg = std::min(seg, n - 1);
    const Eigen::Vector2d a = shifted[seg], b = shifted[(seg + 1) % n];
    const Eigen::Vector2d first = a + (b - a).normalized() * (start - s);
    sim::ObstacleSpec person;
    person.name = "crowd_" + std::to_string(k);
    person.shape.type = sim::ShapeType::kCircle;
    person.shape.radius_m = radius;
    person.speed_m_s = speed;
    person.loop = true;
    person.path_m.push_back(first);
    for (std::size_t i = 1; i <= n; ++i) person.path_m.push_back(shifted[(seg + i) % n]);
    crowd.push_back(person);
  }
  return crowd;
}

}  // namespace

}  // namespace slamrig::scenario

namespace slamrig::slam {

// The scenario's `texture:` block; the extents come from the world's floor texture.
template <typename V>
void VisitFields(V& v, TextureMapOptions& t) {
  v("resolution_m", t.resolution_m);
  v("floor_height_threshold_m", t.floor_height_threshold_m);
  v("max_depth_m", t.max_depth_m);
  v("pixel_stride", t.pixel_stride);
}

}  // namespace slamrig::slam

namespace slamrig::scenario {

const std::vector<std::string>& KnownMetrics() {
  static const std::vector<std::string> metrics = {"ate_rmse_m",
                                                   "ate_mean_m",
                                                   "ate_median_m",
                                                   "ate_max_m",
                                                   "ate_rot_rmse_rad",
                                                   "online_ate_rmse_m",
                                                   "mean_ate_rmse_m",
                                                   "rpe_m_per_scan",
                                                   "rpe_m_per_1m",
                                                   "rpe_m_per_10m",
                                                   "rpe_rad_per_10m",
                                                   "final_error_m",
                                                   "recovery_time_s",
                                                   "map_f1",
                                                   "map_iou",
                                                   "map_precision",
                                                   "map_recall",
                                                   "realtime_factor",
                                                   "scans",
                                                   "mean_nees",
                                                   "final_nees",
                                                   "nees_lower_95",
                                                   "nees_upper_95",
                                                   "texture_psnr_db",
                                                   "texture_mean_abs_error",
                                                   "texture_coverage",
                                                   "texture_frames",
                                                   "texture_psnr_loss_db",
                                                   "texture_psnr_anchored_db",
                                                   "texture_psnr_loss_slow_db",
                                                   "texture_psnr_loss_jitter_db"};
  return metrics;
}

const std::vector<std::string>& LoopMetrics() {
  static const std::vector<std::string> metrics = {"loop_precision", "loop_recall",
                                                   "false_loop_closures"};
  return metrics;
}

const std::vector<std::string>& TruthMetrics() {
  static const std::vector<std::string> metrics = {"texture_psnr_db", "texture_mean_abs_error",
                                                   "texture_coverage", "texture_frames"};
  return metrics;
}

const std::vector<std::string>& LandmarkMetrics() {
  static const std::vector<std::string> metrics = {"pillars",
                                                   "pillars_mapped",
                                                   "spurious_landmarks",
                                                   "landmark_error_max_m",
                                                   "landmark_error_mean_m",
                                                   "landmark_anees",
                                                   "landmark_anees_lower_95",
                                                   "landmark_anees_upper_95",
                                                   "landmark_sightings",
                                                   "wrong_associations"};
  return metrics;
}

const std::vector<std::string>& HealthMetrics() {
  static const std::vector<std::string> metrics = {"lost_intervals", "lost_s"};
  return metrics;
}

std::vector<std::string> MetricsOf(const slam::EstimatorConfig& config) {
  std::vector<std::string> metrics = KnownMetrics();
  if (const slam::Algorithm* a = slam::FindAlgorithm(config.algorithm)) {
    metrics.insert(metrics.end(), a->statistics.begin(), a->statistics.end());
    // An estimator that judges itself declares `diverged` (and `lost`); the runner adds its
    // lost intervals.
    if (std::find(a->statistics.begin(), a->statistics.end(), "diverged") != a->statistics.end())
      metrics.insert(metrics.end(), HealthMetrics().begin(), HealthMetrics().end());
    if (a->closes_loops) metrics.insert(metrics.end(), LoopMetrics().begin(), LoopMetrics().end());
    if (a->maps_landmarks)
      metrics.insert(metrics.end(), LandmarkMetrics().begin(), LandmarkMetrics().end());
  }
  return metrics;
}

std::string FindScenarioFile(const std::string& name_or_path) {
  return sim::FindPresetFile(name_or_path, "scenarios");
}

namespace {

void ReadFaults(const YamlNode& faults, SimulatedSource* source) {
  sim::WorldSpec& world = source->options.world;
  if (auto patches = faults.Optional("slip_patches")) {
    for (const YamlNode& z : patches->Elements()) {
      sim::ZoneSpec zone;
      zone.name = "slip_patch";
      z.Read("name", &zone.name);
      const YamlNode shape = z.Required("shape");
      const std::string type = shape.Get<std::string>("type");
      if (type == "box") {
        zone.shape.type = sim::ShapeType::kBox;
        const auto c = shape.Required("center_m").Elements();
        const auto size = shape.Required("size_m").Elements();
        if (c.size() != 2 || size.size() != 2) shape.Fail("center_m and size_m need 2 numbers");
        zone.shape.center_m = {c[0].As<double>(), c[1].As<double>()};
        zone.shape.size_m = {size[0].As<double>(), size[1].As<double>()};
        shape.Read("angle_rad", &zone.shape.angle_rad);
      } else if (type == "circle") {
        zone.shape.type = sim::ShapeType::kCircle;
        const auto c = shape.Required("center_m").Elements();
        if (c.size() != 2) shape.Fail("center_m needs 2 numbers");
        zone.shape.center_m = {c[0].As<double>(), c[1].As<double>()};
        zone.shape.radius_m = shape.Get<double>("radius_m");
      } else {
        shape.Required("type").Fail("slip patches are box or circle, got '" + type + "'");
      }
      zone.surface.mu = z.Get<double>("mu");
      z.Read("rolling_resistance", &zone.surface.rolling_resistance);
      z.ThrowIfInvalid(zone.Validate());
      world.zones.push_back(zone);
    }
  }
  if (auto crowd = faults.Optional("crowd")) {
    for (auto& person : MakeCrowd(*crowd, world.drive)) world.obstacles.push_back(person);
  }
  if (auto kidnaps = faults.Optional("kidnap")) {
    for (const YamlNode& k : kidnaps->Elements()) {
      KidnapFault fault{k.Get<double>("at_s"), ReadPose(k.Required("to"))};
      if (!(fault.at_s > 0.0)) k.Required("at_s").Fail("must be > 0");
      source->kidnaps.push_back(fault);
    }
  }
  if (auto blackouts = faults.Optional("lidar_blackout")) {
    for (const YamlNode& b : blackouts->Elements()) {
      BlackoutFault fault{b.Get<double>("from_s"), b.Get<double>("to_s")};
      if (!(fault.from_s >= 0.0 && fault.to_s > fault.from_s)) {
        b.Fail("needs 0 <= from_s < to_s");
      }
      source->blackouts.push_back(fault);
    }
  }
}

void ReadExpectations(const YamlNode& expect, ScenarioSpec* spec) {
  for (const std::string& config : expect.Keys()) {
    const YamlNode block = expect.Required(config);
    const auto it = std::find_if(spec->configs.begin(), spec->configs.end(),
                                 [&](const slam::EstimatorConfig& c) { return c.name == config; });
    const bool truth = it == spec->configs.end() && config == "truth";
    if (it == spec->configs.end() && !truth)
      block.Fail("no SLAM configuration named '" + config + "' in slam: (nor 'truth')");
    const std::vector<std::string> known = truth ? TruthMetrics() : MetricsOf(*it);
    for (const std::string& key : block.Keys()) {
      const YamlNode value = block.Required(key);
      Expectation e;
      e.config = config;
      const bool is_max = key.size() > 4 && key.substr(key.size() - 4) == "_max";
      const bool is_min = key.size() > 4 && key.substr(key.size() - 4) == "_min";
      e.metric = key.substr(0, key.size() - 4);
      if ((!is_max && !is_min) || std::find(known.begin(), known.end(), e.metric) == known.end()) {
        std::string names;
        for (const auto& m : known) names += (names.empty() ? "" : ", ") + m;
        value.Fail("unknown expectation; use <metric>_max or <metric>_min with a metric of: " +
                   names);
      }
      e.is_max = is_max;
      e.threshold = value.As<double>();
      spec->expectations.push_back(e);
    }
  }
}

// The resolved scenario in the input schema: world and robot inline with every field, faults
// that are not part of the world, every configuration resolved, the expectations.
std::string ResolvedYaml(const ScenarioSpec& spec, const std::vector<std::string>& overrides) {
  YAML::Emitter out;
  std::string comment = "Resolved from " + spec.path;
  for (const auto& o : overrides) comment += "\n--set " + o;
  comment += "\n`slamrig run` on this file repeats the run bit for bit.";
  out << YAML::Comment(comment) << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << spec.name;
  out << YAML::Key << "description" << YAML::Value << spec.description;
  out << YAML::Key << "seed" << YAML::Value << spec.seed;
  if (spec.record) out << YAML::Key << "record" << YAML::Value << true;
  if (spec.simulated || spec.has_duration) {
    out << YAML::Key << "duration_s" << YAML::Value << FormatNumber(spec.duration_s);
  }
  if (spec.simulated) {
    const SimulatedSource& s = *spec.simulated;
    out << YAML::Key << "world" << YAML::Value << YAML::Load(sim::WorldSpecToYaml(s.options.world));
    out << YAML::Key << "robot" << YAML::Value << YAML::Load(sim::RobotSpecToYaml(s.options.robot));
    if (!s.kidnaps.empty() || !s.blackouts.empty()) {
      out << YAML::Key << "faults" << YAML::Value << YAML::BeginMap;
      if (!s.kidnaps.empty()) {
        out << YAML::Key << "kidnap" << YAML::Value << YAML::BeginSeq;
        for (const KidnapFault& k : s.kidnaps) {
          out << YAML::Flow << YAML::BeginMap << YAML::Key << "at_s" << YAML::Value
              << FormatNumber(k.at_s) << YAML::Key << "to" << YAML::Value << YAML::BeginMap
              << YAML::Key << "x_m" << YAML::Value << FormatNumber(k.to.x()) << YAML::Key << "y_m"
              << YAML::Value << FormatNumber(k.to.y()) << YAML::Key << "yaw_rad" << YAML::Value
              << FormatNumber(k.to.theta()) << YAML::EndMap << YAML::EndMap;
        }
        out << YAML::EndSeq;
      }
      if (!s.blackouts.empty()) {
        out << YAML::Key << "lidar_blackout" << YAML::Value << YAML::BeginSeq;
        for (const BlackoutFault& b : s.blackouts) {
          out << YAML::Flow << YAML::BeginMap << YAML::Key << "from_s" << YAML::Value
              << FormatNumber(b.from_s) << YAML::Key << "to_s" << YAML::Value
              << FormatNumber(b.to_s) << YAML::EndMap;
        }
        out << YAML::EndSeq;
      }
      out << YAML::EndMap;
    }
  } else {
    out << YAML::Key << "source" << YAML::Value << YAML::BeginMap << YAML::Key << "log"
        << YAML::Value << fs::absolute(spec.log->path).lexically_normal().string() << YAML::Key
        << "lenient" << YAML::Value << spec.log->read.lenient << YAML::Key << "strict"
        << YAML::Value << spec.log->read.strict;
    if (spec.log->max_scans > 0)
      out << YAML::Key << "max_scans" << YAML::Value << spec.log->max_scans;
    if (!spec.log->truth_map.empty()) {
      out << YAML::Key << "truth_map" << YAML::Value
          << fs::absolute(spec.log->truth_map).lexically_normal().string();
    }
    // Bag topic names, every one (the defaults too), so that the resolved file is complete.
    slam::BagTopicNames topics = spec.log->read.topics;
    out << YAML::Key << "topics" << YAML::Value << YAML::BeginMap;
    for (const char* key : {"scan", "imu", "joint_states", "odom", "ground_truth", "tf",
                            "tf_static", "clock", "rgb", "depth", "camera_info"}) {
      out << YAML::Key << key << YAML::Value << *topics.Find(key);
    }
    out << YAML::EndMap;
    if (spec.log->perturb.Active()) {
      out << YAML::Key << "perturb" << YAML::Value << YAML::BeginMap;
      FieldWriter writer(&out);
      slam::LogPerturbation perturb = spec.log->perturb;
      VisitFields(writer, perturb);
      out << YAML::EndMap;
    }
    out << YAML::EndMap;
  }
  if (spec.simulated && spec.simulated->options.robot.camera) {
    out << YAML::Key << "texture" << YAML::Value << YAML::Load(ToYaml(spec.texture, ""));
  }
  out << YAML::Key << "slam" << YAML::Value << YAML::BeginMap;
  for (const slam::EstimatorConfig& c : spec.configs) {
    out << YAML::Key << c.name << YAML::Value;
    slam::WriteEstimatorConfig(c, &out);
  }
  out << YAML::EndMap;
  if (!spec.expectations.empty()) {
    // Grouped by configuration in the order the file gave them.
    std::vector<std::string> order;
    for (const Expectation& e : spec.expectations) {
      if (std::find(order.begin(), order.end(), e.config) == order.end()) order.push_back(e.config);
    }
    out << YAML::Key << "expect" << YAML::Value << YAML::BeginMap;
    for (const std::string& config : order) {
      bool open = false;
      for (const Expectation& e : spec.expectations) {
        if (e.config != config) continue;
        if (!open) out << YAML::Key << config << YAML::Value << YAML::BeginMap;
        open = true;
        out << YAML::Key << e.metric + (e.is_max ? "_max" : "_min") << YAML::Value
            << FormatNumber(e.threshold);
      }
      if (open) out << YAML::EndMap;
    }
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

// The --set overrides of the world and robot files (key without its "world." or "robot."
// prefix, value); the others are applied to the scenario file itself.
struct FileOverrides {
  std::vector<std::pair<std::string, std::string>> world, robot;
};

FileOverrides ApplyOverrides(const std::vector<std::string>& overrides, YamlNode* root_node) {
  YamlNode& root = *root_node;
  FileOverrides sets;
  for (const std::string& o : overrides) {
    const std::size_t eq = o.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw ConfigError("--set " + o + ": expected key=value");
    }
    const std::string key = o.substr(0, eq), value = o.substr(eq + 1);
    if (key.rfind("world.", 0) == 0) {
      sets.world.emplace_back(key.substr(6), value);
    } else if (key.rfind("robot.", 0) == 0) {
      sets.robot.emplace_back(key.substr(6), value);
    } else {
      root.Override(key, value, "--set " + o);
    }
  }
  return sets;
}

// A recorded log: `source` and the robot file its wheel geometry comes from.
LogSource ReadLogSource(const YamlNode& root, const YamlNode& source, const std::string& path,
                        const FileOverrides& sets) {
  for (const char* key : {"world", "world_overrides", "faults"}) {
    if (root.Has(key))
      root.Required(key).Fail("a log scenario (source: {log: ...}) has no " + std::string(key));
  }
  if (!sets.world.empty())
    throw ConfigError("--set world." + sets.world.front().first + ": a log scenario has no world");
  LogSource log;
  log.path = ResolveLog(source.Required("log"), path);
  source.Read("lenient", &log.read.lenient);
  source.Read("strict", &log.read.strict);
  int max_scans = 0;
  source.Read("max_scans", &max_scans);
  if (max_scans < 0) source.Required("max_scans").Fail("must be >= 0 (0: every scan)");
  log.max_scans = static_cast<std::size_t>(max_scans);
  if (const auto map = source.Optional("truth_map")) {
    fs::path p = map->As<std::string>();
    if (p.is_relative()) p = fs::path(path).parent_path() / p;
    log.truth_map = p.lexically_normal().string();
  }
  if (const auto topics = source.Optional("topics")) {
    if (!topics->IsMap()) topics->Fail("topics is a map (scan: /front/scan, ...)");
    for (const std::string& key : topics->Keys()) {
      std::string* name = log.read.topics.Find(key);
      if (name == nullptr) {
        topics->Required(key).Fail("unknown topic key '" + key + "' (expected one of " +
                                   slam::BagTopicNames::Keys() + ")");
      }
      *name = topics->Get<std::string>(key);
    }
    topics->ThrowIfInvalid(log.read.topics.Validate());
  }
  if (const auto perturb = source.Optional("perturb"))
    log.perturb = slam::ParseLogPerturbation(*perturb);
  if (const auto robot_node = root.Optional("robot")) {
    YamlNode robot = WorldOrRobot(*robot_node, path, "robots");
    for (const auto& [k, v] : sets.robot) robot.Override(k, v, "--set robot." + k + "=" + v);
    log.robot = sim::NominalOdometry(sim::ParseRobotSpec(robot));
    robot.CheckAllKeysUsed();
  } else if (!sets.robot.empty()) {
    throw ConfigError("--set robot." + sets.robot.front().first + ": the scenario has no robot");
  }
  return log;
}

// A simulated world, with the scenario's and the command line's overrides.
SimulatedSource ReadSimulatedSource(const YamlNode& root, const std::string& path,
                                    std::uint64_t seed, const FileOverrides& sets) {
  SimulatedSource sim_source;
  YamlNode world = WorldOrRobot(root.Required("world"), path, "worlds");
  // No robot: the one `slamrig simulate` drives when given none.
  const std::optional<YamlNode> robot_node = root.Optional("robot");
  YamlNode robot = robot_node
                       ? WorldOrRobot(*robot_node, path, "robots")
                       : YamlNode::LoadFile(sim::FindPresetFile(sim::kDefaultRobot, "robots"));
  for (const char* section : {"world_overrides", "robot_overrides"}) {
    if (auto o = root.Optional(section)) {
      for (const std::string& key : o->Keys()) {
        const YamlNode value = o->Required(key);
        if (!value.IsScalar()) value.Fail("override values must be scalars");
        // Located and resolved (a relative path) by the scenario file that says it.
        (section[0] == 'w' ? world : robot)
            .Override(key, value.As<std::string>(), value.Where(),
                      std::filesystem::path(path).parent_path().string());
      }
    }
  }
  for (const auto& [k, v] : sets.world) world.Override(k, v, "--set world." + k + "=" + v);
  for (const auto& [k, v] : sets.robot) robot.Override(k, v, "--set robot." + k + "=" + v);
  // `world: {generate: {kind: office, seed: 7, ...}}`: a procedural world, made here.
  sim_source.options.world = world.IsMap() && world.Has("generate")
                                 ? sim::worldgen::GenerateWorld(world.Required("generate"))
                                 : sim::ParseWorldSpec(world);
  world.CheckAllKeysUsed();
  sim_source.options.robot = sim::ParseRobotSpec(robot);
  robot.CheckAllKeysUsed();
  sim_source.options.seed = seed;
  if (auto faults = root.Optional("faults")) ReadFaults(*faults, &sim_source);
  root.ThrowIfInvalid(sim_source.options.Validate());
  return sim_source;
}

// The SLAM configurations, in file order, with the source's wheel geometry.
void ReadConfigs(const YamlNode& root, ScenarioSpec* spec_out) {
  ScenarioSpec& spec = *spec_out;
  const YamlNode slam = root.Required("slam");
  if (!slam.IsMap()) slam.Fail("expected a map of SLAM configurations (name: {algorithm: ...})");
  const slam::DiffDriveParams robot =
      spec.simulated ? sim::NominalOdometry(spec.simulated->options.robot) : spec.log->robot;
  // The simulated gyro's noise as the robot file states it; a log's gyro is not characterised.
  std::optional<slam::GyroNoiseModel> gyro;
  if (spec.simulated && spec.simulated->options.robot.imu.enabled) {
    const sim::ImuOptions& imu = spec.simulated->options.robot.imu;
    gyro = slam::GyroNoiseModel{imu.gyro.noise_density, imu.gyro.random_walk, imu.rate_hz};
  }
  for (const std::string& name : slam.Keys()) {
    slam::EstimatorConfig config = slam::ParseEstimatorConfig(name, slam.Required(name));
    config.odometry.robot = robot;
    config.gyro = gyro;
    spec.configs.push_back(std::move(config));
  }
  if (spec.configs.empty()) slam.Fail("needs at least one SLAM configuration");
}

}  // namespace

ScenarioSpec LogScenario(const LogSource& log, std::vector<slam::EstimatorConfig> configs,
                         std::uint64_t seed, const std::string& origin) {
  ScenarioSpec spec;
  spec.path = origin;
  spec.name = fs::path(log.path).filename().string();
  spec.seed = seed;
  spec.log = log;
  spec.configs = std::move(configs);
  spec.resolved_yaml = ResolvedYaml(spec, {});
  return spec;
}

ScenarioSpec LoadScenario(const std::string& path, const std::vector<std::string>& overrides,
                          std::optional<std::uint64_t> seed) {
  YamlNode root = YamlNode::LoadFile(path);
  if (!root.IsMap()) root.Fail("a scenario file is a map (name, world, robot, slam, ...)");
  const FileOverrides sets = ApplyOverrides(overrides, &root);

  ScenarioSpec spec;
  spec.path = path;
  spec.name = fs::path(path).stem().string();
  root.Read("name", &spec.name);
  root.Read("description", &spec.description);
  spec.has_duration = root.Has("duration_s");
  root.Read("duration_s", &spec.duration_s);
  if (!(spec.duration_s > 0.0 && spec.duration_s <= 1e6)) {
    root.Required("duration_s").Fail("must be in (0, 1e6] seconds");
  }
  root.Read("seed", &spec.seed);
  if (seed) spec.seed = *seed;
  root.Read("record", &spec.record);

  if (const auto source = root.Optional("source")) {
    spec.log = ReadLogSource(root, *source, path, sets);
  } else {
    spec.simulated = ReadSimulatedSource(root, path, spec.seed, sets);
  }
  ReadConfigs(root, &spec);

  if (auto texture = root.Optional("texture")) {
    if (!spec.simulated || !spec.simulated->options.robot.camera)
      texture->Fail("texture: needs a simulated robot with a camera (robot: {camera: ...})");
    if (!texture->IsMap()) texture->Fail("expected a map (resolution_m, pixel_stride, ...)");
    FieldReader reader(*texture);
    VisitFields(reader, spec.texture);
    texture->ThrowIfInvalid(spec.texture.Validate());
  }
  if (auto expect = root.Optional("expect")) ReadExpectations(*expect, &spec);
  root.CheckAllKeysUsed();
  spec.resolved_yaml = ResolvedYaml(spec, overrides);
  return spec;
}

}  // namespace slamrig::scenario
