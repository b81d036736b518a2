#include "sim/worldgen/route.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <queue>
#include <tuple>

#include "slam/types/check.h"
#include "slam/types/validation.h"

namespace slamrig::sim::worldgen {
namespace {

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// One traversable copy of a layout edge; the route drives each arc once.
struct Arc {
  int a = 0, b = 0;
  int edge = 0;  // the layout edge it copies
};

// Shortest paths from `source` over `arcs`: the arc that reaches each node (-1: none) and the
// distance. Ties go to the lower node index, so the result depends on nothing but the graph.
void Dijkstra(const Layout& layout, const std::vector<std::vector<int>>& adjacency,
              const std::vector<Arc>& arcs, int source, std::vector<double>* distance,
              std::vector<int>* via) {
  const std::size_t n = layout.nodes.size();
  distance->assign(n, std::numeric_limits<double>::infinity());
  via->assign(n, -1);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  (*distance)[source] = 0.0;
  queue.push({0.0, source});
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > (*distance)[v]) continue;
    for (const int arc : adjacency[v]) {
      const int w = arcs[arc].a == v ? arcs[arc].b : arcs[arc].a;
      const double nd = d + (layout.nodes[w] - layout.nodes[v]).norm();
      if (nd < (*distance)[w]) {
        (*distance)[w] = nd;
        (*via)[w] = arc;
        queue.push({nd, w});
      }
    }
  }
}

// Adds a second copy of the arcs on shortest paths between odd nodes, paired greedily nearest
// first, so that every node has an even number of arcs.
void PairOddNodes(const Layout& layout, std::vector<std::vector<int>>* adjacency,
                  std::vector<Arc>* arcs) {
  std::vector<int> odd;
  for (int v = 0; v < static_cast<int>(adjacency->size()); ++v) {
    if ((*adjacency)[v].size() % 2 == 1) odd.push_back(v);
  }
  std::vector<std::vector<int>> via(odd.size());
  std::vector<std::tuple<double, int, int>> pairs;
  std::vector<double> distance;
  for (std::size_t i = 0; i < odd.size(); ++i) {
    Dijkstra(layout, *adjacency, *arcs, odd[i], &distance, &via[i]);
    for (std::size_t j = i + 1; j < odd.size(); ++j) {
      pairs.emplace_back(distance[odd[j]], static_cast<int>(i), static_cast<int>(j));
    }
  }
  std::sort(pairs.begin(), pairs.end());
  std::vector<bool> matched(odd.size(), false);
  std::vector<Arc> extra;
  for (const auto& [d, i, j] : pairs) {
    if (matched[i] || matched[j]) continue;
    matched[i] = matched[j] = true;
    for (int v = odd[j]; v != odd[i];) {
      const Arc& arc = (*arcs)[via[i][v]];
      extra.push_back(arc);
      v = arc.a == v ? arc.b : arc.a;
    }
  }
  for (const Arc& arc : extra) {
    arcs->push_back(arc);
    (*adjacency)[arc.a].push_back(static_cast<int>(arcs->size()) - 1);
    (*adjacency)[arc.b].push_back(static_cast<int>(arcs->size()) - 1);
  }
}

// Hierholzer's algorithm: the Euler circuit from `start` as (node, arc that reached it).
std::vector<std::pair<int, int>> EulerCircuit(const std::vector<std::vector<int>>& adjacency,
                                              const std::vector<Arc>& arcs, int start) {
  std::vector<bool> used(arcs.size(), false);
  std::vector<std::size_t> next(adjacency.size(), 0);
  std::vector<std::pair<int, int>> stack = {{start, -1}}, circuit;
  while (!stack.empty()) {
    const int v = stack.back().first;
    while (next[v] < adjacency[v].size() && used[adjacency[v][next[v]]]) ++next[v];
    if (next[v] < adjacency[v].size()) {
      const int arc = adjacency[v][next[v]];
      used[arc] = true;
      stack.push_back({arcs[arc].a == v ? arcs[arc].b : arcs[arc].a, arc});
    } else {
      circuit.push_back(stack.back());
      stack.pop_back();
    }
  }
  std::reverse(circuit.begin(), circuit.end());
  return circuit;
}

// Drops repeated points and the middle of three points on one straight run (not a reversal).
std::vector<Eigen::Vector2d> Simplify(const std::vector<Eigen::Vector2d>& points) {
  std::vector<Eigen::Vector2d> out;
  for (const Eigen::Vector2d& p : points) {
    if (!out.empty() && (p - out.back()).norm() < 1e-6) continue;
    if (out.size() >= 2) {
      const Eigen::Vector2d u = out.back() - out[out.size() - 2], w = p - out.back();
      if (std::abs(Cross(u, w)) < 1e-9 * u.norm() * w.norm() && u.dot(w) > 0.0) out.pop_back();
    }
    out.push_back(p);
  }
  return out;
}

// The layout's edges as arcs, and each node's arcs.
struct Graph {
  std::vector<Arc> arcs;
  std::vector<std::vector<int>> adjacency;
};

Graph MakeGraph(const Layout& layout) {
  Graph g;
  g.adjacency.resize(layout.nodes.size());
  for (int e = 0; e < static_cast<int>(layout.edges.size()); ++e) {
    g.arcs.push_back({layout.edges[e].a, layout.edges[e].b, e});
    g.adjacency[layout.edges[e].a].push_back(e);
    g.adjacency[layout.edges[e].b].push_back(e);
  }
  return g;
}

// The nodes with an edge when every one of them is reachable from the start, else -1.
int NodesReachedFromStart(const Layout& layout, const Graph& g) {
  std::vector<double> distance;
  std::vector<int> via;
  Dijkstra(layout, g.adjacency, g.arcs, layout.start_node, &distance, &via);
  int used_nodes = 0;
  for (std::size_t v = 0; v < g.adjacency.size(); ++v) {
    if (g.adjacency[v].empty()) continue;
    if (!std::isfinite(distance[v])) return -1;
    ++used_nodes;
  }
  return used_nodes;
}

// The tour of every edge of `layout`, or nothing when its edges are not all reachable from the
// start or it has fewer than `min_loops` independent cycles.
std::optional<Route> PlanTour(const Layout& layout, int min_loops) {
  Graph g = MakeGraph(layout);
  const int used_nodes = NodesReachedFromStart(layout, g);
  const int loops = static_cast<int>(layout.edges.size()) - used_nodes + 1;
  if (used_nodes <= 0 || loops < min_loops) return std::nullopt;
  std::vector<Arc>& arcs = g.arcs;
  std::vector<std::vector<int>>& adjacency = g.adjacency;
  Route route;
  route.loops = loops;
  PairOddNodes(layout, &adjacency, &arcs);
  const auto circuit = EulerCircuit(adjacency, arcs, layout.start_node);

  std::vector<Eigen::Vector2d> points = {layout.nodes[layout.start_node]};
  std::vector<bool> spurs_driven(layout.edges.size(), false);
  for (std::size_t k = 1; k < circuit.size(); ++k) {
    const auto [v, arc] = circuit[k];
    const int e = arcs[arc].edge;
    const LayoutEdge& edge = layout.edges[e];
    if (!spurs_driven[e]) {
      spurs_driven[e] = true;
      std::vector<const Spur*> spurs;
      for (const Spur& s : edge.spurs) spurs.push_back(&s);
      if (v == edge.a) std::reverse(spurs.begin(), spurs.end());  // driven b -> a
      for (const Spur* s : spurs) {
        for (const auto& p : s->points) points.push_back(p);
        for (std::size_t i = s->points.size() - 1; i-- > 0;) points.push_back(s->points[i]);
      }
    }
    points.push_back(layout.nodes[v]);
  }
  points = Simplify(points);
  if (points.size() > 1 && (points.back() - points.front()).norm() < 1e-6) points.pop_back();
  route.waypoints = points;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d& p = points[i];
    const Eigen::Vector2d& q = points[(i + 1) % points.size()];
    const Eigen::Vector2d& r = points[(i + 2) % points.size()];
    route.length_m += (q - p).norm();
    if ((q - p).dot(r - q) < 0.0 &&
        std::abs(Cross(q - p, r - q)) < 1e-9 * (q - p).norm() * (r - q).norm()) {
      ++route.reversals;
    }
  }
  return route;
}

// The graph of the chosen edges, in the layout's order, without the branches that would end where
// the layout goes on (a node of one chosen edge but several in the layout, the start excepted):
// the route turns back only at the world's own dead ends.
Layout Subgraph(const Layout& layout, std::vector<bool> chosen) {
  std::vector<int> layout_degree(layout.nodes.size(), 0);
  for (const LayoutEdge& edge : layout.edges) ++layout_degree[edge.a], ++layout_degree[edge.b];
  for (bool pruned = true; pruned;) {
    pruned = false;
    std::vector<int> degree(layout.nodes.size(), 0);
    for (std::size_t k = 0; k < chosen.size(); ++k) {
      if (chosen[k]) ++degree[layout.edges[k].a], ++degree[layout.edges[k].b];
    }
    const auto cut_short = [&](int v) {
      return degree[v] == 1 && layout_degree[v] > 1 && v != layout.start_node;
    };
    for (std::size_t k = 0; k < chosen.size(); ++k) {
      if (chosen[k] && (cut_short(layout.edges[k].a) || cut_short(layout.edges[k].b))) {
        chosen[k] = false;
        pruned = true;
      }
    }
  }
  Layout part;
  part.nodes = layout.nodes;
  part.start_node = layout.start_node;
  for (std::size_t k = 0; k < chosen.size(); ++k) {
    if (chosen[k]) part.edges.push_back(layout.edges[k]);
  }
  return part;
}

}  // namespace

Route PlanRoute(const Layout& layout, double max_length_m) {
  std::optional<Route> whole = PlanTour(layout, 0);
  SLAMRIG_CHECK(whole.has_value(), "a layout's graph is connected");
  if (max_length_m <= 0.0 || whole->length_m <= max_length_m) return *whole;
  // The part of the layout nearest the start: edges by the distance of their far end from it
  // (ties by their near end, then by index); of every prefix, less the branches it would cut
  // short, the longest tour that fits.
  const Graph g = MakeGraph(layout);
  std::vector<double> distance;
  std::vector<int> via;
  Dijkstra(layout, g.adjacency, g.arcs, layout.start_node, &distance, &via);
  std::vector<std::tuple<double, double, int>> order;
  for (int e = 0; e < static_cast<int>(layout.edges.size()); ++e) {
    const double da = distance[layout.edges[e].a], db = distance[layout.edges[e].b];
    order.emplace_back(std::max(da, db), std::min(da, db), e);
  }
  std::sort(order.begin(), order.end());
  std::vector<bool> chosen(layout.edges.size(), false);
  std::optional<Route> best;
  double shortest_loop = std::numeric_limits<double>::infinity();
  for (const auto& [far, near, e] : order) {
    chosen[e] = true;
    std::optional<Route> route = PlanTour(Subgraph(layout, chosen), 1);
    if (!route) continue;
    shortest_loop = std::min(shortest_loop, route->length_m);
    if (route->length_m <= max_length_m && (!best || route->length_m > best->length_m)) {
      best = std::move(route);
    }
  }
  if (!best) {
    FailParameter("route_length_m", max_length_m,
                  "too short for one loop of this world; must be >= " +
                      FormatNumber(std::ceil(shortest_loop)) + " (or 0: the whole route)");
  }
  return *best;
}

}  // namespace slamrig::sim::worldgen
