#include "sim/worldgen/worldgen.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "sim/ray_caster.h"
#include "sim/world.h"
#include "sim/world_yaml.h"
#include "slam/types/error.h"
#include "slam/types/validation.h"

namespace slamrig::sim::worldgen {
namespace {

constexpr WorldKind kAllKinds[] = {WorldKind::kOffice, WorldKind::kWarehouse, WorldKind::kCorridor,
                                   WorldKind::kCampus, WorldKind::kMaze};

// Small worlds of each kind, so that many seeds stay fast.
GenerateSpec SmallSpec(WorldKind kind, std::uint64_t seed) {
  GenerateSpec spec;
  spec.kind = kind;
  spec.seed = seed;
  spec.route = DefaultRouteOptions(kind);
  spec.office.width_m = 36.0;
  spec.office.height_m = 30.0;
  spec.warehouse.width_m = 24.0;
  spec.warehouse.height_m = 20.0;
  spec.corridor.length_m = 50.0;
  spec.campus.width_m = 150.0;
  spec.campus.height_m = 120.0;
  spec.campus.block_m = 40.0;
  spec.maze.width_m = 16.0;
  spec.maze.height_m = 12.0;
  return spec;
}

std::string Bytes(const GeneratedWorld& g) {
  return WorldSpecToYaml(g.world) + MapPgm(RasteriseWalls(g));
}

TEST(WorldgenTest, SameSpecSameBytesAndSeedsDiffer) {
  for (const WorldKind kind : kAllKinds) {
    const std::string a = Bytes(Generate(SmallSpec(kind, 7)));
    EXPECT_EQ(a, Bytes(Generate(SmallSpec(kind, 7)))) << WorldKindName(kind);
    EXPECT_NE(a, Bytes(Generate(SmallSpec(kind, 8)))) << WorldKindName(kind);
  }
  const GeneratedWorld office = Generate(SmallSpec(WorldKind::kOffice, 7));
  EXPECT_EQ(RenderPng(office), RenderPng(Generate(SmallSpec(WorldKind::kOffice, 7))));
}

// Distance from `p` to the nearest occupied cell of `map` within `reach` (else reach).
double DistanceToOccupied(const slam::MapImage& map, const Eigen::Vector2d& p, double reach) {
  const double res = map.resolution_m;
  const int cx = static_cast<int>(std::floor((p.x() - map.origin.x()) / res));
  const int cy = static_cast<int>(std::floor((p.y() - map.origin.y()) / res));
  const int k = static_cast<int>(std::ceil(reach / res)) + 1;
  double best = reach;
  for (int y = std::max(0, cy - k); y <= std::min(map.height - 1, cy + k); ++y) {
    for (int x = std::max(0, cx - k); x <= std::min(map.width - 1, cx + k); ++x) {
      if (map.at(x, y) < 50) continue;
      // Nearest point of the cell's square.
      const double x0 = map.origin.x() + x * res, y0 = map.origin.y() + y * res;
      const double dx = std::max({x0 - p.x(), 0.0, p.x() - (x0 + res)});
      const double dy = std::max({y0 - p.y(), 0.0, p.y() - (y0 + res)});
      best = std::min(best, std::hypot(dx, dy));
    }
  }
  return best;
}

// Every route segment, sampled every 5 cm, keeps the robot's radius plus the margin from every
// occupied cell of the rasterised map (which knows nothing of the planner), over many seeds.
TEST(WorldgenTest, EveryRouteKeepsItsClearanceFromTheRasterisedWalls) {
  for (const WorldKind kind : kAllKinds) {
    for (std::uint64_t seed = 1; seed <= (kind == WorldKind::kCampus ? 3u : 10u); ++seed) {
      GenerateSpec spec = SmallSpec(kind, seed);
      if (kind != WorldKind::kCampus) spec.route.map_resolution_m = 0.05;
      const GeneratedWorld g = Generate(spec);
      const slam::MapImage map = RasteriseWalls(g);
      const double need = spec.route.clearance_m();
      const auto& w = g.route.waypoints;
      ASSERT_GE(w.size(), 4u);
      double worst = need;
      for (std::size_t i = 0; i < w.size(); ++i) {
        const Eigen::Vector2d a = w[i], b = w[(i + 1) % w.size()];
        const int steps = std::max(1, static_cast<int>((b - a).norm() / 0.05));
        for (int s = 0; s <= steps; ++s) {
          const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(s) / steps);
          // The raster grows walls by up to a cell's half diagonal.
          worst = std::min(worst, DistanceToOccupied(map, p, need) + 0.75 * map.resolution_m);
        }
      }
      EXPECT_GE(worst, need) << WorldKindName(kind) << " seed " << seed;
      EXPECT_GE(g.route.loops, 2) << WorldKindName(kind) << " seed " << seed;
    }
  }
}

// The route drives every edge of the layout's graph: each edge's midpoint lies on the route.
TEST(WorldgenTest, TheRouteCoversEveryEdgeAndReversesAtDeadEnds) {
  for (const WorldKind kind : kAllKinds) {
    const GeneratedWorld g = Generate(SmallSpec(kind, 3));
    const auto& w = g.route.waypoints;
    for (const LayoutEdge& e : g.layout.edges) {
      const Eigen::Vector2d mid = 0.5 * (g.layout.nodes[e.a] + g.layout.nodes[e.b]);
      double best = 1e9;
      for (std::size_t i = 0; i < w.size(); ++i) {
        const Eigen::Vector2d a = w[i], d = w[(i + 1) % w.size()] - a;
        const double f = std::clamp((mid - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
        best = std::min(best, (a + f * d - mid).norm());
      }
      EXPECT_LT(best, 1e-6) << WorldKindName(kind);
    }
  }
  // A maze is a tree plus a few openings: it has dead ends, and the route turns back at them.
  EXPECT_GT(Generate(SmallSpec(WorldKind::kMaze, 3)).route.reversals, 2);
}

// Distance from `p` to the closed polyline `w`.
double DistanceToRoute(const std::vector<Eigen::Vector2d>& w, const Eigen::Vector2d& p) {
  double best = 1e9;
  for (std::size_t i = 0; i < w.size(); ++i) {
    const Eigen::Vector2d a = w[i], d = w[(i + 1) % w.size()] - a;
    const double f = std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
    best = std::min(best, (a + f * d - p).norm());
  }
  return best;
}

// A length budget drives part of the world: the lap fits, closes a loop, starts where the whole
// route starts and drives only where the whole route drives; a budget too short for one loop
// names route_length_m and the least length, which then works.
TEST(WorldgenTest, ARouteWithinItsLengthClosesALoopOnTheWorldsOwnRoute) {
  for (const WorldKind kind : kAllKinds) {
    for (std::uint64_t seed = 1; seed <= 4; ++seed) {
      GenerateSpec spec = SmallSpec(kind, seed);
      const GeneratedWorld whole = Generate(spec);
      spec.route.route_length_m = 0.4 * whole.route.length_m;
      GeneratedWorld part;
      try {
        part = Generate(spec);
      } catch (const ParameterError& e) {
        EXPECT_EQ(e.field(), "route_length_m");
        const std::string what = e.what(), tag = "must be >= ";
        ASSERT_NE(what.find(tag), std::string::npos) << what;
        const double least = std::stod(what.substr(what.find(tag) + tag.size()));
        EXPECT_GT(least, spec.route.route_length_m) << what;
        spec.route.route_length_m = least;
        part = Generate(spec);
      }
      const std::string name = std::string(WorldKindName(kind)) + " seed " + std::to_string(seed);
      EXPECT_LE(part.route.length_m, spec.route.route_length_m) << name;
      EXPECT_LT(part.route.length_m, whole.route.length_m) << name;
      EXPECT_GE(part.route.loops, 1) << name;
      EXPECT_EQ(part.route.waypoints.front(), whole.route.waypoints.front()) << name;
      const auto& w = part.route.waypoints;
      for (std::size_t i = 0; i < w.size(); ++i) {
        for (const double f : {0.0, 0.25, 0.5, 0.75}) {
          const Eigen::Vector2d p = w[i] + f * (w[(i + 1) % w.size()] - w[i]);
          EXPECT_LT(DistanceToRoute(whole.route.waypoints, p), 1e-6) << name << " waypoint " << i;
        }
      }
    }
  }
  GenerateSpec tiny = SmallSpec(WorldKind::kCampus, 1);
  tiny.route.route_length_m = 10.0;
  try {
    Generate(tiny);
    ADD_FAILURE() << "a 10 m campus route was made";
  } catch (const ParameterError& e) {
    EXPECT_THAT(e.what(),
                ::testing::StartsWith(
                    "route_length_m = 10; too short for one loop of this world; must be >= "));
  }
}

// The map against the Box2D world: rays cast from the route hit where the map turns occupied.
TEST(WorldgenTest, TheMapMatchesTheWorld) {
  for (const WorldKind kind : kAllKinds) {
    GenerateSpec spec = SmallSpec(kind, 5);
    spec.route.map_resolution_m = 0.05;
    const GeneratedWorld g = Generate(spec);
    const slam::MapImage map = RasteriseWalls(g);
    World world(g.world);
    RayCaster caster(world.b2world());  // every surface matte: the geometry alone
    int checked = 0, agree = 0;
    for (std::size_t i = 0; i < g.route.waypoints.size(); i += 3) {
      const Eigen::Vector2d o = g.route.waypoints[i];
      std::vector<Ray> rays;
      for (int k = 0; k < 90; ++k) {
        const double a = -std::numbers::pi + k * 2.0 * std::numbers::pi / 90;
        rays.push_back({o, {std::cos(a), std::sin(a)}, a});
      }
      std::vector<double> ranges(rays.size());
      caster.Cast(rays, 20.0, ranges);
      for (std::size_t k = 0; k < rays.size(); ++k) {
        if (!std::isfinite(ranges[k])) continue;
        auto occupied = [&](double t) {
          const Eigen::Vector2d p = o + t * rays[k].direction;
          const int x = static_cast<int>(std::floor((p.x() - map.origin.x()) / map.resolution_m));
          const int y = static_cast<int>(std::floor((p.y() - map.origin.y()) / map.resolution_m));
          return map.at(x, y) >= 50;
        };
        ++checked;
        // Occupied a third of a cell past the hit, free half way to it.
        if (occupied(ranges[k] + 0.015) && !occupied(0.5 * ranges[k])) ++agree;
      }
    }
    ASSERT_GT(checked, 50) << WorldKindName(kind);
    // A ray grazing a corner may pass a cell the grown raster marks; nearly all agree.
    EXPECT_GT(agree, 0.99 * checked) << WorldKindName(kind);
  }
}

TEST(WorldgenTest, AGeneratedWorldIsAnOrdinaryWorldFile) {
  const GeneratedWorld g = Generate(SmallSpec(WorldKind::kOffice, 2));
  const std::string yaml = WorldSpecToYaml(g.world);
  const YamlNode node = YamlNode::LoadString(yaml, "world.yaml");
  EXPECT_EQ(WorldSpecToYaml(ParseWorldSpec(node)), yaml);
  EXPECT_THAT(yaml, ::testing::HasSubstr("material: glass"));
}

std::string ErrorOf(const std::string& text) {
  try {
    const YamlNode root = YamlNode::LoadString(text, "scenario.yaml");
    GenerateWorld(root.Required("generate"));
    root.CheckAllKeysUsed();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(WorldgenTest, BadInputIsOneLineNamingTheKey) {
  EXPECT_EQ(ErrorOf("generate: {kind: ofice, seed: 7}"),
            "scenario.yaml:1:18: generate.kind: unknown kind 'ofice'; expected one of office, "
            "warehouse, corridor, campus, maze");
  EXPECT_THAT(ErrorOf("generate: {kind: office, width_m: -3}"),
              ::testing::HasSubstr("generate.width_m: must be in [10, 500]"));
  EXPECT_THAT(ErrorOf("generate: {kind: maze, laps: 0}"),
              ::testing::HasSubstr("generate.laps: must be in [1, 100]"));
  EXPECT_THAT(ErrorOf("generate: {kind: office, widht_m: 30}"), ::testing::HasSubstr("widht_m"));
  // A kind's parameter is not another kind's.
  EXPECT_THAT(ErrorOf("generate: {kind: maze, corridor_width_m: 3}"),
              ::testing::HasSubstr("corridor_width_m"));
  // Too small for two loops: says so at the parameter.
  EXPECT_THAT(ErrorOf("generate: {kind: office, width_m: 16, height_m: 16}"),
              ::testing::HasSubstr("generate.width_m: width_m = 16; too small for two loops"));
  EXPECT_THAT(ErrorOf("generate: {kind: maze, cell_m: 1}"),
              ::testing::HasSubstr("generate.cell_m: cell_m = 1; passages narrower"));
  EXPECT_THAT(ErrorOf("generate: {kind: warehouse, width_m: 10, cross_aisles: 2}"),
              ::testing::HasSubstr("generate.width_m: width_m = 10; too small for two loops"));
  EXPECT_THAT(ErrorOf("generate: {kind: office, corridor_width_m: 1}"),
              ::testing::HasSubstr("corridor_width_m = 1; narrower than the route's clearance"));
}

TEST(WorldgenTest, ParsesWhatItWrites) {
  for (const WorldKind kind : kAllKinds) {
    GenerateSpec spec = SmallSpec(kind, 11);
    const std::string yaml = GenerateSpecToYaml(spec);
    const YamlNode node = YamlNode::LoadString(yaml, "g.yaml");
    const GenerateSpec back = ParseGenerateSpec(node);
    node.CheckAllKeysUsed();
    EXPECT_EQ(GenerateSpecToYaml(back), yaml);
  }
}

// Each broken rule names its key, value and bound, numbers as written.
TEST(WorldKindsTest, BrokenRulesNameKeyValueAndBound) {
  GenerateSpec spec;
  spec.kind = WorldKind::kMaze;
  spec.route.speed_m_s = 0.01;
  spec.maze.cell_m = 0.1;
  spec.maze.black_fraction = 1.5;
  EXPECT_THAT(spec.Validate(),
              ::testing::ElementsAre(
                  "speed_m_s = 0.01; must be in [0.05, 5]", "cell_m = 0.1; must be in [0.5, 10]",
                  "wall_m = " + FormatNumber(spec.maze.wall_m) + "; must be < cell_m / 2",
                  "black_fraction = 1.5; must be in [0, 1]"));
}

}  // namespace
}  // namespace slamrig::sim::worldgen
