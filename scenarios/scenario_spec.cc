#include "scenarios/scenario_spec.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <system_error>

#include "sim/robot_yaml.h"
#include "sim/world_yaml.h"
#include "slam/types/error.h"

namespace slamrig::scenario {
namespace {

namespace fs = std::filesystem;

std::string Resolve(const YamlNode& node, const std::string& scenario_path) {
  fs::path p = node.As<std::string>();
  if (p.is_relative()) p = fs::path(scenario_path).parent_path() / p;
  std::error_code error;  // e.g. a name too long for the OS: not there either
  if (!fs::exists(p, error)) node.Fail("file '" + p.string() + "' does not exist");
  return p.lexically_normal().string();
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

const std::vector<std::string>& KnownMetrics() {
  static const std::vector<std::string> metrics = {
      "ate_rmse_m",     "ate_mean_m",   "ate_median_m",  "ate_max_m",       "ate_rot_rmse_rad",
      "rpe_m_per_scan", "rpe_m_per_1m", "rpe_m_per_10m", "rpe_rad_per_10m", "final_error_m",
      "map_f1",         "map_iou",      "map_precision", "map_recall",      "realtime_factor",
      "mean_neff",      "resamples",    "scans"};
  return metrics;
}

ScenarioSpec LoadScenario(const std::string& path, const std::vector<std::string>& overrides,
                          std::optional<std::uint64_t> seed) {
  YamlNode root = YamlNode::LoadFile(path);
  std::vector<std::pair<std::string, std::string>> world_set, robot_set;
  for (const std::string& o : overrides) {
    const std::size_t eq = o.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw ConfigError("--set " + o + ": expected key=value");
    }
    const std::string key = o.substr(0, eq), value = o.substr(eq + 1);
    if (key.rfind("world.", 0) == 0) {
      world_set.emplace_back(key.substr(6), value);
    } else if (key.rfind("robot.", 0) == 0) {
      robot_set.emplace_back(key.substr(6), value);
    } else {
      root.Override(key, value);
    }
  }

  ScenarioSpec spec;
  spec.path = path;
  spec.name = fs::path(path).stem().string();
  root.Read("name", &spec.name);
  root.Read("description", &spec.description);
  root.Read("duration_s", &spec.duration_s);
  if (!(spec.duration_s > 0.0 && spec.duration_s <= 1e6)) {
    root.Required("duration_s").Fail("must be in (0, 1e6] seconds");
  }
  std::uint64_t file_seed = 1;
  root.Read("seed", &file_seed);
  spec.sim.seed = seed.value_or(file_seed);

  // World and robot files, with the scenario's and the command line's overrides.
  const std::string world_path = Resolve(root.Required("world"), path);
  const std::string robot_path = Resolve(root.Required("robot"), path);
  YamlNode world = YamlNode::LoadFile(world_path);
  YamlNode robot = YamlNode::LoadFile(robot_path);
  for (const char* section : {"world_overrides", "robot_overrides"}) {
    if (auto o = root.Optional(section)) {
      for (const std::string& key : o->Keys()) {
        const YamlNode value = o->Required(key);
        if (!value.IsScalar()) value.Fail("override values must be scalars");
        (section[0] == 'w' ? world : robot).Override(key, value.As<std::string>());
      }
    }
  }
  for (const auto& [k, v] : world_set) world.Override(k, v);
  for (const auto& [k, v] : robot_set) robot.Override(k, v);
  spec.sim.world = sim::ParseWorldSpec(world);
  world.CheckAllKeysUsed();
  spec.sim.robot = sim::ParseRobotSpec(robot);
  robot.CheckAllKeysUsed();

  // Faults.
  if (auto faults = root.Optional("faults")) {
    if (auto patches = faults->Optional("slip_patches")) {
      for (const YamlNode& z : patches->Elements()) {
        sim::ZoneSpec zone;
        zone.name = "slip_patch";
        z.Read("name", &zone.name);
        const YamlNode shape = z.Required("shape");
        const std::string type = shape.Get<std::string>("type");
        if (type == "box") {
          zone.shape.type = sim::ShapeType::kBox;
          const auto c = shape.Required("center_m").Elements();
          const auto s = shape.Required("size_m").Elements();
          if (c.size() != 2 || s.size() != 2) shape.Fail("center_m and size_m need 2 numbers");
          zone.shape.center_m = {c[0].As<double>(), c[1].As<double>()};
          zone.shape.size_m = {s[0].As<double>(), s[1].As<double>()};
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
        spec.sim.world.zones.push_back(zone);
      }
    }
    if (auto crowd = faults->Optional("crowd")) {
      for (auto& person : MakeCrowd(*crowd, spec.sim.world.drive))
        spec.sim.world.obstacles.push_back(person);
    }
    if (auto kidnaps = faults->Optional("kidnap")) {
      for (const YamlNode& k : kidnaps->Elements()) {
        KidnapFault fault{k.Get<double>("at_s"), ReadPose(k.Required("to"))};
        if (!(fault.at_s > 0.0)) k.Required("at_s").Fail("must be > 0");
        spec.kidnaps.push_back(fault);
      }
    }
    if (auto blackouts = faults->Optional("lidar_blackout")) {
      for (const YamlNode& b : blackouts->Elements()) {
        BlackoutFault fault{b.Get<double>("from_s"), b.Get<double>("to_s")};
        if (!(fault.from_s >= 0.0 && fault.to_s > fault.from_s)) {
          b.Fail("needs 0 <= from_s < to_s");
        }
        spec.blackouts.push_back(fault);
      }
    }
  }
  root.ThrowIfInvalid(spec.sim.Validate());

  // SLAM configurations, in file order.
  const YamlNode slam = root.Required("slam");
  for (const std::string& name : slam.Keys()) {
    SlamConfig config = ParseSlamConfig(name, slam.Required(name));
    config.pf.seed = spec.sim.seed;
    const sim::WheelOptions& wheels = spec.sim.robot.wheels;
    config.sync.robot = {wheels.radius_m, spec.sim.robot.encoders.ticks_per_revolution,
                         wheels.track_width_m};
    spec.slam.push_back(config);
  }
  if (spec.slam.empty()) slam.Fail("needs at least one SLAM configuration");

  // Expectations: `<config>: {<metric>_max: x, <metric>_min: y}`.
  if (auto expect = root.Optional("expect")) {
    for (const std::string& config : expect->Keys()) {
      const YamlNode block = expect->Required(config);
      if (std::none_of(spec.slam.begin(), spec.slam.end(),
                       [&](const SlamConfig& c) { return c.name == config; })) {
        block.Fail("no SLAM configuration named '" + config + "' in slam:");
      }
      for (const std::string& key : block.Keys()) {
        const YamlNode value = block.Required(key);
        Expectation e;
        e.config = config;
        const bool is_max = key.size() > 4 && key.substr(key.size() - 4) == "_max";
        const bool is_min = key.size() > 4 && key.substr(key.size() - 4) == "_min";
        e.metric = key.substr(0, key.size() - 4);
        const auto& known = KnownMetrics();
        if ((!is_max && !is_min) ||
            std::find(known.begin(), known.end(), e.metric) == known.end()) {
          std::string names;
          for (const auto& m : known) names += (names.empty() ? "" : ", ") + m;
          value.Fail("unknown expectation; use <metric>_max or <metric>_min with a metric of: " +
                     names);
        }
        e.is_max = is_max;
        e.threshold = value.As<double>();
        spec.expectations.push_back(e);
      }
    }
  }
  root.CheckAllKeysUsed();

  // The resolved configuration, for the report folder.
  std::ostringstream resolved;
  resolved << "# Resolved configuration of " << path << "\nname: " << spec.name
           << "\nseed: " << spec.sim.seed << "\nduration_s: " << spec.duration_s << "\n";
  for (const auto& o : overrides) resolved << "# --set " << o << "\n";
  resolved << "kidnaps:";
  for (const auto& k : spec.kidnaps)
    resolved << "\n  - {at_s: " << k.at_s << ", to: [" << k.to.x() << ", " << k.to.y() << ", "
             << k.to.theta() << "]}";
  resolved << (spec.kidnaps.empty() ? " []\n" : "\n") << "lidar_blackouts:";
  for (const auto& b : spec.blackouts)
    resolved << "\n  - {from_s: " << b.from_s << ", to_s: " << b.to_s << "}";
  resolved << (spec.blackouts.empty() ? " []\n" : "\n") << "slam:\n";
  for (const auto& c : spec.slam) {
    std::istringstream lines(SlamConfigToYaml(c));
    for (std::string line; std::getline(lines, line);) resolved << "  " << line << "\n";
  }
  resolved << "expect:\n";
  for (const auto& e : spec.expectations) {
    resolved << "  - {config: " << e.config << ", metric: " << e.metric << ", "
             << (e.is_max ? "max: " : "min: ") << e.threshold << "}\n";
  }
  resolved << "world:\n";
  std::istringstream world_lines(sim::WorldSpecToYaml(spec.sim.world));
  for (std::string line; std::getline(world_lines, line);) resolved << "  " << line << "\n";
  resolved << "robot:\n";
  std::istringstream robot_lines(sim::RobotSpecToYaml(spec.sim.robot));
  for (std::string line; std::getline(robot_lines, line);) resolved << "  " << line << "\n";
  spec.resolved_yaml = resolved.str();
  return spec;
}

}  // namespace slamrig::scenario
