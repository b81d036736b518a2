#include "sim/worldgen/worldgen.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "sim/world_yaml.h"
#include "slam/config/fields.h"
#include "slam/io/atomic_file.h"
#include "slam/types/validation.h"

namespace slamrig::sim::worldgen {

// The `generate:` map's schema: one field list per options struct, shared by reader and writer.

template <typename V>
void VisitFields(V& v, RouteOptions& r) {
  v("speed_m_s", r.speed_m_s);
  v("laps", r.laps);
  v("robot_radius_m", r.robot_radius_m);
  v("clearance_margin_m", r.clearance_margin_m);
  v("lookahead_m", r.lookahead_m);
  v("map_resolution_m", r.map_resolution_m);
  v("route_length_m", r.route_length_m);
}

template <typename V>
void VisitFields(V& v, OfficeOptions& o) {
  v("width_m", o.width_m);
  v("height_m", o.height_m);
  v("corridor_width_m", o.corridor_width_m);
  v("block_m", o.block_m);
  v("room_m", o.room_m);
  v("door_width_m", o.door_width_m);
  v("open_door_fraction", o.open_door_fraction);
  v("closed_corridor_fraction", o.closed_corridor_fraction);
  v("room_visit_fraction", o.room_visit_fraction);
  v("furniture_per_10m2", o.furniture_per_10m2);
  v("pillar_fraction", o.pillar_fraction);
  v("glass_fraction", o.glass_fraction);
  v("black_fraction", o.black_fraction);
}

template <typename V>
void VisitFields(V& v, WarehouseOptions& o) {
  v("width_m", o.width_m);
  v("height_m", o.height_m);
  v("aisle_width_m", o.aisle_width_m);
  v("shelf_depth_m", o.shelf_depth_m);
  v("unit_m", o.unit_m);
  v("cross_aisle_m", o.cross_aisle_m);
  v("cross_aisles", o.cross_aisles);
  v("black_fraction", o.black_fraction);
}

template <typename V>
void VisitFields(V& v, CorridorOptions& o) {
  v("length_m", o.length_m);
  v("hallway_width_m", o.hallway_width_m);
  v("block_m", o.block_m);
  v("hallways", o.hallways);
  v("rungs", o.rungs);
  v("feature_spacing_m", o.feature_spacing_m);
  v("glass_fraction", o.glass_fraction);
}

template <typename V>
void VisitFields(V& v, CampusOptions& o) {
  v("width_m", o.width_m);
  v("height_m", o.height_m);
  v("street_width_m", o.street_width_m);
  v("block_m", o.block_m);
  v("building_fraction", o.building_fraction);
  v("open_fraction", o.open_fraction);
  v("trees_per_1000m2", o.trees_per_1000m2);
  v("post_spacing_m", o.post_spacing_m);
  v("glass_fraction", o.glass_fraction);
  v("black_fraction", o.black_fraction);
}

template <typename V>
void VisitFields(V& v, MazeOptions& o) {
  v("width_m", o.width_m);
  v("height_m", o.height_m);
  v("cell_m", o.cell_m);
  v("wall_m", o.wall_m);
  v("extra_openings", o.extra_openings);
  v("black_fraction", o.black_fraction);
}

template <typename V>
void VisitKindFields(V& v, GenerateSpec& s) {
  switch (s.kind) {
    case WorldKind::kOffice:
      VisitFields(v, s.office);
      break;
    case WorldKind::kWarehouse:
      VisitFields(v, s.warehouse);
      break;
    case WorldKind::kCorridor:
      VisitFields(v, s.corridor);
      break;
    case WorldKind::kCampus:
      VisitFields(v, s.campus);
      break;
    case WorldKind::kMaze:
      VisitFields(v, s.maze);
      break;
  }
  VisitFields(v, s.route);
}

GenerateSpec ParseGenerateSpec(const YamlNode& node) {
  if (!node.IsMap()) node.Fail("generate is a map ({kind: office, seed: 7, ...})");
  GenerateSpec spec;
  const YamlNode kind = node.Required("kind");
  if (!ParseWorldKind(kind.As<std::string>(), &spec.kind)) {
    kind.Fail("unknown kind '" + kind.As<std::string>() + "'; expected one of " + WorldKindNames());
  }
  node.Read("seed", &spec.seed);
  spec.route = DefaultRouteOptions(spec.kind);
  FieldReader reader(node);
  VisitKindFields(reader, spec);
  // Each broken rule at its own key when it is written there.
  for (const std::string& error : spec.Validate()) {
    const std::string field = error.substr(0, error.find(' '));
    if (node.Has(field)) node.Required(field).Fail(error.substr(error.find(';') + 2));
    node.Fail(error);
  }
  return spec;
}

std::string GenerateSpecToYaml(const GenerateSpec& spec) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "kind" << YAML::Value << WorldKindName(spec.kind);
  out << YAML::Key << "seed" << YAML::Value << spec.seed;
  FieldWriter writer(&out);
  GenerateSpec copy = spec;
  VisitKindFields(writer, copy);
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

GeneratedWorld Generate(const GenerateSpec& spec) {
  GeneratedWorld g;
  g.spec = spec;
  g.layout = MakeLayout(spec);
  g.route = PlanRoute(g.layout, spec.route.route_length_m);
  WorldSpec& w = g.world;
  w.name = g.layout.name;
  w.walls = g.layout.walls;
  const auto& p = g.route.waypoints;
  w.spawn = Pose2(p[0].x(), p[0].y(), std::atan2(p[1].y() - p[0].y(), p[1].x() - p[0].x()));
  w.drive.mode = DriveMode::kWaypoints;
  w.drive.waypoints_m = p;
  w.drive.closed = true;
  w.drive.laps = spec.route.laps;
  w.drive.speed_m_s = spec.route.speed_m_s;
  w.drive.lookahead_m = spec.route.lookahead_m;
  // Turning on the spot at corners keeps the robot near the planned route.
  w.drive.turn_in_place_rad = 0.5;
  // Dead ends (a maze's, a room's) are driven to their end before turning back.
  w.drive.dead_end_reach_m = 0.25;
  return g;
}

WorldSpec GenerateWorld(const YamlNode& node) {
  const GenerateSpec spec = ParseGenerateSpec(node);
  try {
    return Generate(spec).world;
  } catch (const ParameterError& e) {
    if (node.Has(e.field())) node.Required(e.field()).Fail(e.what());
    node.Fail(e.what());
  }
}

slam::MapImage RasteriseWalls(const GeneratedWorld& world) {
  const double res = world.spec.route.map_resolution_m;
  slam::MapImage map;
  const Eigen::Vector2d lo = (world.layout.min_m.array() - 1.0).matrix();
  const Eigen::Vector2d hi = (world.layout.max_m.array() + 1.0).matrix();
  map.resolution_m = res;
  map.origin = Pose2(lo.x(), lo.y(), 0.0);
  map.width = static_cast<int>(std::ceil((hi.x() - lo.x()) / res));
  map.height = static_cast<int>(std::ceil((hi.y() - lo.y()) / res));
  map.occupancy.assign(static_cast<std::size_t>(map.width) * map.height, 0);
  const double half = 0.5 * res;
  for (const ShapeSpec& s : world.world.walls) {
    // The shape grown by half a cell: a thin wall never falls between cell centres.
    ShapeSpec grown = s;
    if (s.type == ShapeType::kBox) grown.size_m = (s.size_m.array() + 2.0 * half).matrix();
    if (s.type == ShapeType::kCircle) grown.radius_m = s.radius_m + half;
    const std::vector<Eigen::Vector2d> outline =
        s.type == ShapeType::kCircle ? std::vector<Eigen::Vector2d>{} : grown.Outline();
    Eigen::Vector2d blo = (grown.center_m.array() - grown.radius_m).matrix(),
                    bhi = (grown.center_m.array() + grown.radius_m).matrix();
    if (!outline.empty()) {
      blo = bhi = outline[0];
      for (const auto& q : outline) blo = blo.cwiseMin(q), bhi = bhi.cwiseMax(q);
    }
    const int x0 = std::max(0, static_cast<int>(std::floor((blo.x() - lo.x()) / res)));
    const int y0 = std::max(0, static_cast<int>(std::floor((blo.y() - lo.y()) / res)));
    const int x1 = std::min(map.width - 1, static_cast<int>(std::floor((bhi.x() - lo.x()) / res)));
    const int y1 = std::min(map.height - 1, static_cast<int>(std::floor((bhi.y() - lo.y()) / res)));
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        const Eigen::Vector2d c(lo.x() + (x + 0.5) * res, lo.y() + (y + 0.5) * res);
        if (grown.Contains(c)) map.occupancy[static_cast<std::size_t>(y) * map.width + x] = 100;
      }
    }
  }
  return map;
}

std::string MapPgm(const slam::MapImage& map) {
  std::string pgm =
      "P5\n" + std::to_string(map.width) + " " + std::to_string(map.height) + "\n255\n";
  const std::size_t header = pgm.size();
  pgm.resize(header + static_cast<std::size_t>(map.width) * map.height);
  for (int y = 0; y < map.height; ++y) {
    const int row = map.height - 1 - y;  // the image's top row is the highest y
    for (int x = 0; x < map.width; ++x) {
      pgm[header + static_cast<std::size_t>(row) * map.width + x] =
          static_cast<char>(map.at(x, y) >= 50 ? 0 : 254);
    }
  }
  return pgm;
}

std::string MapYaml(const slam::MapImage& map, const std::string& image_file) {
  return "image: " + image_file + "\nmode: trinary\nresolution: " + FormatNumber(map.resolution_m) +
         "\norigin: [" + FormatNumber(map.origin.x()) + ", " + FormatNumber(map.origin.y()) +
         ", 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";
}

std::string RenderPng(const GeneratedWorld& world) {
  const Eigen::Vector2d lo = (world.layout.min_m.array() - 1.0).matrix();
  const Eigen::Vector2d hi = (world.layout.max_m.array() + 1.0).matrix();
  const double scale = std::min(40.0, 1600.0 / (hi - lo).maxCoeff());  // pixels per metre
  const int width = static_cast<int>(std::ceil((hi.x() - lo.x()) * scale));
  const int height = static_cast<int>(std::ceil((hi.y() - lo.y()) * scale));
  cv::Mat image(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  auto px = [&](const Eigen::Vector2d& p) {
    return cv::Point(static_cast<int>(std::lround((p.x() - lo.x()) * scale)),
                     static_cast<int>(std::lround((hi.y() - p.y()) * scale)));
  };
  for (const ShapeSpec& s : world.world.walls) {
    const cv::Scalar colour = s.material == SurfaceMaterial::kGlass   ? cv::Scalar(230, 170, 60)
                              : s.material == SurfaceMaterial::kBlack ? cv::Scalar(0, 0, 0)
                                                                      : cv::Scalar(110, 110, 110);
    if (s.type == ShapeType::kCircle) {
      cv::circle(image, px(s.center_m), std::max(1, static_cast<int>(s.radius_m * scale)), colour,
                 cv::FILLED, cv::LINE_AA);
    } else {
      std::vector<cv::Point> points;
      for (const auto& q : s.Outline()) points.push_back(px(q));
      cv::fillConvexPoly(image, points, colour, cv::LINE_AA);
    }
  }
  const auto& route = world.route.waypoints;
  for (std::size_t i = 0; i < route.size(); ++i) {
    cv::line(image, px(route[i]), px(route[(i + 1) % route.size()]), cv::Scalar(40, 40, 220), 1,
             cv::LINE_AA);
  }
  cv::circle(image, px(route.front()), 5, cv::Scalar(40, 170, 40), cv::FILLED, cv::LINE_AA);
  std::vector<unsigned char> png;
  cv::imencode(".png", image, png);
  return std::string(png.begin(), png.end());
}

void WriteGeneratedWorld(const GeneratedWorld& world, const std::string& dir) {
  namespace fs = std::filesystem;
  fs::create_directories(dir);
  std::string header =
      "# A generated world: `slamrig world generate " +
      std::string(WorldKindName(world.spec.kind)) + " --seed " + std::to_string(world.spec.seed) +
      "` with these parameters (the route: " + FormatNumber(std::round(world.route.length_m)) +
      " m a lap, " + std::to_string(world.route.loops) + " loops, " +
      std::to_string(world.route.reversals) + " reversals):\n";
  std::string params = GenerateSpecToYaml(world.spec);
  for (std::size_t at = 0; at < params.size();) {
    const std::size_t end = params.find('\n', at);
    header += "#   " + params.substr(at, end - at) + "\n";
    at = end + 1;
  }
  const slam::MapImage map = RasteriseWalls(world);
  slam::WriteFileAtomically((fs::path(dir) / "map.pgm").string(), MapPgm(map));
  slam::WriteFileAtomically((fs::path(dir) / "map.yaml").string(), MapYaml(map, "map.pgm"));
  slam::WriteFileAtomically((fs::path(dir) / "world.png").string(), RenderPng(world));
  // The world last: a folder with world.yaml is complete.
  slam::WriteFileAtomically((fs::path(dir) / "world.yaml").string(),
                            header + WorldSpecToYaml(world.world));
}

}  // namespace slamrig::sim::worldgen
