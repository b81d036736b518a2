#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "sim/shape_spec.h"
#include "sim/worldgen/world_kinds.h"
#include "slam/types/error.h"

namespace slamrig::sim::worldgen {

/// Draws from std::mt19937_64 (whose output the standard fixes) through its own arithmetic, never
/// a std:: distribution (implementation-defined), so a seed gives the same world everywhere.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}
  /// Uniform in [0, 1), 53 random bits.
  double Uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  /// Uniform in [lo, hi).
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  /// A point uniform in the box [lo, hi). y is drawn before x, as is every pair of draws here: one
  /// statement with two draws as arguments leaves their order to the compiler (gcc: last first),
  /// so each pair is sequenced explicitly, in the order that made the worlds already generated.
  Eigen::Vector2d UniformPoint(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) {
    const double y = Uniform(lo.y(), hi.y());
    const double x = Uniform(lo.x(), hi.x());
    return {x, y};
  }
  /// Uniform integer in [0, n), n > 0 (the modulo bias is below 2^-40 for any n here).
  int Below(int n) { return static_cast<int>(engine_() % static_cast<std::uint64_t>(n)); }
  /// True with probability p.
  bool Chance(double p) { return Uniform() < p; }

 private:
  std::mt19937_64 engine_;
};

/// A detour from a point of a route edge and back: the robot leaves the edge at `at_m` (distance
/// from the edge's first node), drives through `points` and comes back the same way.
struct Spur {
  double at_m = 0.0;
  std::vector<Eigen::Vector2d> points;
};

/// A stretch of free space the route must drive, between two graph nodes.
struct LayoutEdge {
  int a = 0, b = 0;
  std::vector<Spur> spurs;  ///< in increasing at_m
};

/// A generated world before it becomes a WorldSpec: its walls and the graph of its corridors,
/// aisles, streets or passages (the centre lines of its free space), on which the route is
/// planned. Every edge and spur keeps at least the route's clearance from every wall.
struct Layout {
  std::string name;
  std::vector<ShapeSpec> walls;
  std::vector<Eigen::Vector2d> nodes;
  std::vector<LayoutEdge> edges;
  int start_node = 0;
  Eigen::Vector2d min_m = Eigen::Vector2d::Zero();  ///< extent of the world, for the raster
  Eigen::Vector2d max_m = Eigen::Vector2d::Zero();
};

/// The layout of `spec`'s kind. Throws ConfigError naming the parameter when the world cannot
/// hold its route (too small for two loops, passages narrower than the route's clearance).
Layout MakeLayout(const GenerateSpec& spec);

// The kinds (layout_*.cc).
Layout MakeOffice(const OfficeOptions& o, const RouteOptions& route, Rng& rng);
Layout MakeWarehouse(const WarehouseOptions& o, const RouteOptions& route, Rng& rng);
Layout MakeCorridor(const CorridorOptions& o, const RouteOptions& route, Rng& rng);
Layout MakeCampus(const CampusOptions& o, const RouteOptions& route, Rng& rng);
Layout MakeMaze(const MazeOptions& o, const RouteOptions& route, Rng& rng);

// Shared building blocks.

/// An axis-aligned box wall from corner `lo` to corner `hi`.
ShapeSpec Box(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi,
              SurfaceMaterial material = SurfaceMaterial::kMatte);
/// A disc.
ShapeSpec Disc(const Eigen::Vector2d& center, double radius,
               SurfaceMaterial material = SurfaceMaterial::kMatte);

/// A grid of nodes at xs x ys (node j * xs.size() + i), with the edges between neighbours:
/// the horizontal ones first (H(i, j) = j * (xs.size() - 1) + i), then the vertical ones.
void AddGridGraph(const std::vector<double>& xs, const std::vector<double>& ys, Layout* layout);

/// A generator parameter the world cannot be made with; what() is "<field> = <value>; <rule>".
class ParameterError : public ConfigError {
 public:
  ParameterError(std::string field, const std::string& message)
      : ConfigError(message), field_(std::move(field)) {}
  /// The parameter's key ("width_m").
  const std::string& field() const { return field_; }

 private:
  std::string field_;
};

/// Throws ParameterError("<field> = <value>; <rule>").
[[noreturn]] void FailParameter(const std::string& field, double value, const std::string& rule);

}  // namespace slamrig::sim::worldgen
