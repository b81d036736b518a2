#pragma once

#include <Eigen/Core>
#include <vector>

#include "sim/worldgen/layout.h"

namespace slamrig::sim::worldgen {

/// A closed drive over a layout's graph.
struct Route {
  std::vector<Eigen::Vector2d> waypoints;  ///< closed: the robot returns to the first one
  double length_m = 0.0;                   ///< one lap
  int loops = 0;      ///< independent cycles of the graph it drives (edges - nodes + 1)
  int reversals = 0;  ///< dead ends and spurs it drives into and back out of
};

/// Plans a closed walk from the layout's start node that drives every edge (and every spur,
/// there and back, on its edge's first pass): a Chinese-postman tour, odd nodes paired greedily
/// by shortest path and those paths driven twice, the Euler circuit found by Hierholzer's
/// algorithm. Dead ends are driven in and back out. The graph must be connected (checked).
/// With `max_length_m` > 0 and a tour longer than that, the route drives instead the part of the
/// graph nearest the start whose tour fits (edges taken by the distance of their far end from the
/// start), so that a short drive still closes loops; it throws ParameterError on
/// `route_length_m` when not even one loop fits.
Route PlanRoute(const Layout& layout, double max_length_m = 0.0);

}  // namespace slamrig::sim::worldgen
