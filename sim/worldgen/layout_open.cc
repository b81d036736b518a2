// The warehouse, campus and maze kinds.

#include <algorithm>
#include <cmath>

#include "sim/worldgen/layout.h"
#include "sim/worldgen/layout_parts.h"
#include "slam/types/validation.h"

namespace slamrig::sim::worldgen {

Layout MakeWarehouse(const WarehouseOptions& o, const RouteOptions& route, Rng& rng) {
  const double clear = route.clearance_m(), depth = 2.0 * o.shelf_depth_m;
  if (0.5 * o.aisle_width_m < clear) {
    FailParameter("aisle_width_m", o.aisle_width_m,
                  "narrower than the route's clearance; must be >= " + FormatNumber(2.0 * clear));
  }
  if (0.5 * o.cross_aisle_m < clear) {
    FailParameter("cross_aisle_m", o.cross_aisle_m,
                  "narrower than the route's clearance; must be >= " + FormatNumber(2.0 * clear));
  }
  const int bands = o.cross_aisles;
  const double row_length = (o.height_m - bands * o.cross_aisle_m) / (bands - 1);
  if (row_length < o.unit_m) {
    FailParameter("height_m", o.height_m,
                  "too short for " + std::to_string(bands) +
                      " cross aisles and one unit per row; "
                      "must be >= " +
                      FormatNumber(bands * o.cross_aisle_m + (bands - 1) * o.unit_m));
  }
  const int rows = static_cast<int>((o.width_m - o.aisle_width_m) / (o.aisle_width_m + depth));
  if (rows * (bands - 1) < 2) {
    FailParameter(
        "width_m", o.width_m,
        "too small for two loops; must be >= " + FormatNumber(3.0 * o.aisle_width_m + 2.0 * depth) +
            " (two rows), or cross_aisles >= 3");
  }
  const double aisle = (o.width_m - rows * depth) / (rows + 1);
  std::vector<double> xs, ys;
  for (int k = 0; k <= rows; ++k) xs.push_back(0.5 * aisle + k * (aisle + depth));
  for (int b = 0; b < bands; ++b)
    ys.push_back(0.5 * o.cross_aisle_m + b * (o.cross_aisle_m + row_length));
  Layout layout;
  AddOuterWalls(o.width_m, o.height_m, 0.2, &layout);
  AddGridGraph(xs, ys, &layout);
  // Every unit the same size, the same gap between units: the aisles look alike.
  const int units = static_cast<int>(row_length / o.unit_m);
  const double margin = 0.5 * (row_length - units * o.unit_m);
  for (int r = 0; r < rows; ++r) {
    const double x0 = aisle + r * (aisle + depth);
    for (int b = 0; b + 1 < bands; ++b) {
      const double y0 = o.cross_aisle_m + b * (o.cross_aisle_m + row_length) + margin;
      for (int u = 0; u < units; ++u) {
        const double y = y0 + u * o.unit_m;
        const SurfaceMaterial m =
            rng.Chance(o.black_fraction) ? SurfaceMaterial::kBlack : SurfaceMaterial::kMatte;
        layout.walls.push_back(Box({x0, y + 0.05}, {x0 + depth, y + o.unit_m - 0.05}, m));
      }
    }
  }
  return layout;
}

Layout MakeCampus(const CampusOptions& o, const RouteOptions& route, Rng& rng) {
  const double sw = o.street_width_m, clear = route.clearance_m();
  if (0.5 * sw < clear) {
    FailParameter("street_width_m", sw,
                  "narrower than the route's clearance; must be >= " + FormatNumber(2.0 * clear));
  }
  const int nx = GridCount(o.width_m, sw, o.block_m), ny = GridCount(o.height_m, sw, o.block_m);
  CheckTwoLoops(nx, ny, "width_m", o.width_m, "height_m", o.height_m, o.block_m + sw, sw,
                "a campus of");
  const std::vector<double> xs = GridLines(o.width_m, sw, nx);
  const std::vector<double> ys = GridLines(o.height_m, sw, ny);
  Layout layout;
  layout.min_m = Eigen::Vector2d::Zero();
  layout.max_m = Eigen::Vector2d(o.width_m, o.height_m);
  AddGridGraph(xs, ys, &layout);
  const auto facade = MaterialDraw(rng, o.glass_fraction, o.black_fraction);
  for (int bj = 0; bj < ny; ++bj) {
    for (int bi = 0; bi < nx; ++bi) {
      const Eigen::Vector2d lo(xs[bi] + 0.5 * sw, ys[bj] + 0.5 * sw);
      const Eigen::Vector2d hi(xs[bi + 1] - 0.5 * sw, ys[bj + 1] - 0.5 * sw);
      // Posts along the block's edges, 0.6 m in from the street.
      const Eigen::Vector2d in_lo = (lo.array() + 0.6).matrix(),
                            in_hi = (hi.array() - 0.6).matrix();
      const Eigen::Vector2d corners[4] = {
          in_lo, {in_hi.x(), in_lo.y()}, in_hi, {in_lo.x(), in_hi.y()}};
      for (int side = 0; side < 4; ++side) {
        const Eigen::Vector2d a = corners[side], b = corners[(side + 1) % 4];
        const double length = (b - a).norm();
        for (double s = rng.Uniform(0.0, o.post_spacing_m); s < length; s += o.post_spacing_m) {
          layout.walls.push_back(Disc(a + (b - a) * (s / length), 0.08));
        }
      }
      const double u = rng.Uniform();
      if (u < o.building_fraction) {
        const Eigen::Vector2d blo = lo + rng.UniformPoint({2.0, 2.0}, {8.0, 8.0});
        const Eigen::Vector2d bhi = hi - rng.UniformPoint({2.0, 2.0}, {8.0, 8.0});
        if ((bhi - blo).minCoeff() < 2.0) continue;
        const SurfaceMaterial m = facade();
        layout.walls.push_back(Box(blo, bhi, m));
        // A glass building shows its concrete core through the facade.
        if (m == SurfaceMaterial::kGlass && (bhi - blo).minCoeff() > 10.0) {
          layout.walls.push_back(Box((blo.array() + 4.0).matrix(), (bhi.array() - 4.0).matrix()));
        }
      } else if (u >= o.building_fraction + o.open_fraction) {
        const Eigen::Vector2d size = hi - lo;
        const int trees =
            static_cast<int>(o.trees_per_1000m2 * size.prod() / 1000.0 + rng.Uniform());
        for (int t = 0; t < trees; ++t) {
          const double r = rng.Uniform(0.15, 0.5);
          layout.walls.push_back(Disc(
              {rng.Uniform(lo.x() + 1.5, hi.x() - 1.5), rng.Uniform(lo.y() + 1.5, hi.y() - 1.5)},
              r));
        }
      }
    }
  }
  return layout;
}

namespace {

// The maze's passages: open[h] between cells (i, j) and (i + 1, j) at h = j * (mx - 1) + i,
// then open[v] between (i, j) and (i, j + 1) at v = (mx - 1) * my + j * mx + i.
std::vector<bool> CarveMaze(int mx, int my, int extra, Rng& rng) {
  const int num_h = (mx - 1) * my;
  std::vector<bool> open(static_cast<std::size_t>(num_h + mx * (my - 1)), false);
  std::vector<bool> visited(static_cast<std::size_t>(mx * my), false);
  std::vector<int> stack = {0};
  visited[0] = true;
  while (!stack.empty()) {
    const int cell = stack.back(), i = cell % mx, j = cell / mx;
    int next[4][2];  // neighbour cell, wall index
    int n = 0;
    if (i > 0 && !visited[cell - 1]) next[n][0] = cell - 1, next[n++][1] = j * (mx - 1) + i - 1;
    if (i + 1 < mx && !visited[cell + 1]) next[n][0] = cell + 1, next[n++][1] = j * (mx - 1) + i;
    if (j > 0 && !visited[cell - mx])
      next[n][0] = cell - mx, next[n++][1] = num_h + (j - 1) * mx + i;
    if (j + 1 < my && !visited[cell + mx])
      next[n][0] = cell + mx, next[n++][1] = num_h + j * mx + i;
    if (n == 0) {
      stack.pop_back();
      continue;
    }
    const int k = rng.Below(n);
    open[next[k][1]] = true;
    visited[next[k][0]] = true;
    stack.push_back(next[k][0]);
  }
  std::vector<int> closed;
  for (int w = 0; w < static_cast<int>(open.size()); ++w) {
    if (!open[w]) closed.push_back(w);
  }
  if (static_cast<int>(closed.size()) < extra) {
    FailParameter("extra_openings", extra,
                  "the maze has only " + std::to_string(closed.size()) +
                      " inner walls left to open; lower it or enlarge width_m and height_m");
  }
  for (int k = 0; k < extra; ++k) {
    std::swap(closed[k], closed[k + rng.Below(static_cast<int>(closed.size()) - k)]);
    open[closed[k]] = true;
  }
  return open;
}

}  // namespace

Layout MakeMaze(const MazeOptions& o, const RouteOptions& route, Rng& rng) {
  const double c = o.cell_m, w = o.wall_m, clear = route.clearance_m();
  if (0.5 * (c - w) < clear) {
    FailParameter("cell_m", c,
                  "passages narrower than the route's clearance; must be >= " +
                      FormatNumber(2.0 * clear + w));
  }
  const int mx = static_cast<int>(o.width_m / c), my = static_cast<int>(o.height_m / c);
  if (mx < 2 || my < 2) {
    FailParameter(mx < 2 ? "width_m" : "height_m", mx < 2 ? o.width_m : o.height_m,
                  "too small for a maze of cell_m = " + FormatNumber(c) +
                      "; must be >= " + FormatNumber(2.0 * c));
  }
  const std::vector<bool> open = CarveMaze(mx, my, o.extra_openings, rng);
  const int num_h = (mx - 1) * my;
  Layout layout;
  const double width = mx * c, height = my * c;
  for (int j = 0; j < my; ++j) {
    for (int i = 0; i < mx; ++i) layout.nodes.emplace_back((i + 0.5) * c, (j + 0.5) * c);
  }
  const auto material = MaterialDraw(rng, 0.0, o.black_fraction);
  for (int wall = 0; wall < static_cast<int>(open.size()); ++wall) {
    const bool horizontal = wall < num_h;
    const int i = horizontal ? wall % (mx - 1) : (wall - num_h) % mx;
    const int j = horizontal ? wall / (mx - 1) : (wall - num_h) / mx;
    const int a = j * mx + i, b = horizontal ? a + 1 : a + mx;
    if (open[wall]) {
      layout.edges.push_back({a, b, {}});
    } else if (horizontal) {  // a wall between (i, j) and (i + 1, j): along y at x = (i + 1) c
      const double x = (i + 1) * c;
      layout.walls.push_back(
          Box({x - 0.5 * w, j * c - 0.5 * w}, {x + 0.5 * w, (j + 1) * c + 0.5 * w}, material()));
    } else {
      const double y = (j + 1) * c;
      layout.walls.push_back(
          Box({i * c - 0.5 * w, y - 0.5 * w}, {(i + 1) * c + 0.5 * w, y + 0.5 * w}, material()));
    }
  }
  // The outer walls, centred on the maze's bounds like the inner ones.
  layout.walls.push_back(Box({-0.5 * w, -0.5 * w}, {width + 0.5 * w, 0.5 * w}));
  layout.walls.push_back(Box({-0.5 * w, height - 0.5 * w}, {width + 0.5 * w, height + 0.5 * w}));
  layout.walls.push_back(Box({-0.5 * w, 0.5 * w}, {0.5 * w, height - 0.5 * w}));
  layout.walls.push_back(Box({width - 0.5 * w, 0.5 * w}, {width + 0.5 * w, height - 0.5 * w}));
  layout.min_m = Eigen::Vector2d(-0.5 * w, -0.5 * w);
  layout.max_m = Eigen::Vector2d(width + 0.5 * w, height + 0.5 * w);
  return layout;
}

}  // namespace slamrig::sim::worldgen
