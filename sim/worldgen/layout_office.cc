// The office and corridor kinds: grids of corridors between blocks (of rooms, or closed).

#include <algorithm>
#include <cmath>

#include "sim/worldgen/layout.h"
#include "sim/worldgen/layout_parts.h"
#include "slam/types/validation.h"

namespace slamrig::sim::worldgen {
namespace {

constexpr double kOuterWallM = 0.2;
constexpr double kBlockWallM = 0.15;
constexpr double kPartitionM = 0.1;

struct Rect {
  Eigen::Vector2d lo, hi;
  bool Overlaps(const Rect& o, double gap) const {
    return lo.x() < o.hi.x() + gap && o.lo.x() < hi.x() + gap && lo.y() < o.hi.y() + gap &&
           o.lo.y() < hi.y() + gap;
  }
};

// A block of the office grid: its free-space bounds and the corridor edges along its bottom and
// top faces (-1: shut off).
struct Block {
  Rect r;
  int bottom_edge = -1, top_edge = -1;
  double bottom_x0 = 0.0, top_x0 = 0.0;  // x of those edges' first nodes
};

// Desks, cabinets and a pillar in `room` (its inside), away from the `keep` rectangles.
void Furnish(const Rect& room, const std::vector<Rect>& keep, const OfficeOptions& o, Rng& rng,
             Layout* layout) {
  const Eigen::Vector2d size = room.hi - room.lo;
  const int count = static_cast<int>(o.furniture_per_10m2 * size.prod() / 10.0 + rng.Uniform());
  std::vector<Rect> placed = keep;
  for (int n = 0; n < count; ++n) {
    for (int attempt = 0; attempt < 8; ++attempt) {
      Eigen::Vector2d item = rng.UniformPoint({0.6, 0.4}, {1.6, 0.8});
      if (rng.Chance(0.5)) item = Eigen::Vector2d(item.y(), item.x());
      if (item.x() > size.x() || item.y() > size.y()) continue;
      const Eigen::Vector2d lo = rng.UniformPoint(room.lo, room.hi - item);
      const Rect r{lo, lo + item};
      if (std::any_of(placed.begin(), placed.end(),
                      [&](const Rect& p) { return p.Overlaps(r, 0.25); })) {
        continue;
      }
      placed.push_back(r);
      layout->walls.push_back(Box(r.lo, r.hi));
      break;
    }
  }
  if (!rng.Chance(o.pillar_fraction)) return;
  for (int attempt = 0; attempt < 8; ++attempt) {
    const double radius = rng.Uniform(0.15, 0.3);
    if (2.0 * radius > size.minCoeff()) return;
    const Eigen::Vector2d c =
        rng.UniformPoint((room.lo.array() + radius).matrix(), (room.hi.array() - radius).matrix());
    const Rect r{(c.array() - radius).matrix(), (c.array() + radius).matrix()};
    if (std::any_of(placed.begin(), placed.end(),
                    [&](const Rect& p) { return p.Overlaps(r, 0.25); })) {
      continue;
    }
    layout->walls.push_back(Disc(c, radius));
    return;
  }
}

// One block: its walls with a door per room, partitions, furniture, and spurs into some rooms.
void MakeOfficeBlock(const Block& block, const OfficeOptions& o, const RouteOptions& route,
                     Rng& rng, Layout* layout) {
  const double clear = route.clearance_m();
  const Eigen::Vector2d lo = block.r.lo, hi = block.r.hi;
  const double bw = hi.x() - lo.x(), bh = hi.y() - lo.y();
  const int rows = bh >= 2.0 * (2.0 * clear + 1.5) ? 2 : 1;
  const int cols = std::max(1, static_cast<int>(bw / o.room_m));
  const double rw = bw / cols, rd = bh / rows;
  const bool single_row_faces_top = rows == 1 && rng.Chance(0.5);
  std::vector<Gap> bottom_gaps, top_gaps;
  for (int row = 0; row < rows; ++row) {
    const bool faces_top = row == 1 || single_row_faces_top;
    for (int c = 0; c < cols; ++c) {
      const double rx0 = lo.x() + c * rw, rx1 = rx0 + rw;
      const double slack = std::max(0.0, 0.5 * rw - 0.5 * o.door_width_m - 0.3);
      const double x = 0.5 * (rx0 + rx1) + rng.Uniform(-slack, slack);
      const bool open = rng.Chance(o.open_door_fraction);
      const double half = 0.5 * o.door_width_m;
      (faces_top ? top_gaps : bottom_gaps).push_back({x - lo.x() - half, x - lo.x() + half, !open});
      // The room's inside, and what must stay clear in it: the door's swing and the spur.
      const double ry0 = lo.y() + row * rd, ry1 = ry0 + rd;
      const Rect inside{{rx0 + 0.5 * kPartitionM + 0.05, ry0 + kBlockWallM + 0.05},
                        {rx1 - 0.5 * kPartitionM - 0.05, ry1 - kBlockWallM - 0.05}};
      const double door_y = faces_top ? ry1 : ry0, inward = faces_top ? -1.0 : 1.0;
      std::vector<Rect> keep;
      const Eigen::Vector2d d0(x - half - 0.1, door_y), d1(x + half + 0.1, door_y + inward * 1.2);
      keep.push_back({d0.cwiseMin(d1), d0.cwiseMax(d1)});
      const int edge = faces_top ? block.top_edge : block.bottom_edge;
      const double side = clear + kBlockWallM + 0.05;  // from a partition or the block's wall
      const bool fits =
          rd >= 2.0 * clear + 0.5 && x - rx0 >= side && rx1 - x >= side && half >= clear;
      if (open && edge >= 0 && fits && rng.Chance(o.room_visit_fraction)) {
        const Eigen::Vector2d inner(x, door_y + inward * 0.5 * rd);
        const double corridor_y = layout->nodes[layout->edges[edge].a].y();
        const double x0 = faces_top ? block.top_x0 : block.bottom_x0;
        layout->edges[edge].spurs.push_back({x - x0, {Eigen::Vector2d(x, corridor_y), inner}});
        const Eigen::Vector2d k0(x - clear - 0.05, door_y),
            k1(x + clear + 0.05, inner.y() + inward * (clear + 0.05));
        keep.push_back({k0.cwiseMin(k1), k0.cwiseMax(k1)});
      }
      Furnish(inside, keep, o, rng, layout);
    }
  }
  const auto material = MaterialDraw(rng, o.glass_fraction, o.black_fraction);
  AddFaceWall({lo.x(), lo.y()}, {hi.x(), lo.y()}, {0, -1}, kBlockWallM, bottom_gaps, material,
              layout);
  AddFaceWall({lo.x(), hi.y()}, {hi.x(), hi.y()}, {0, 1}, kBlockWallM, top_gaps, material, layout);
  AddFaceWall({lo.x(), lo.y()}, {lo.x(), hi.y()}, {-1, 0}, kBlockWallM, {}, material, layout);
  AddFaceWall({hi.x(), lo.y()}, {hi.x(), hi.y()}, {1, 0}, kBlockWallM, {}, material, layout);
  for (int c = 1; c < cols; ++c) {
    const double x = lo.x() + c * rw;
    layout->walls.push_back(Box({x - 0.5 * kPartitionM, lo.y() + kBlockWallM},
                                {x + 0.5 * kPartitionM, hi.y() - kBlockWallM}));
  }
  if (rows == 2) {
    const double y = lo.y() + rd;
    layout->walls.push_back(Box({lo.x() + kBlockWallM, y - 0.5 * kPartitionM},
                                {hi.x() - kBlockWallM, y + 0.5 * kPartitionM}));
  }
}

// Shuts off inner corridor stretches (never the outer ring, so all stays connected) while the
// graph keeps two loops; returns which edges are shut.
std::vector<bool> ShutCorridors(const Layout& layout, int nx, int ny, double fraction, Rng& rng) {
  const int num_h = (ny + 1) * nx;
  std::vector<int> inner;
  for (int e = 0; e < static_cast<int>(layout.edges.size()); ++e) {
    const bool horizontal = e < num_h;
    const int i = horizontal ? e % nx : (e - num_h) % (nx + 1);
    const int j = horizontal ? e / nx : (e - num_h) / (nx + 1);
    if (horizontal ? (j > 0 && j < ny) : (i > 0 && i < nx)) inner.push_back(e);
  }
  for (int k = static_cast<int>(inner.size()) - 1; k > 0; --k)
    std::swap(inner[k], inner[rng.Below(k + 1)]);
  const int loops = static_cast<int>(layout.edges.size() - layout.nodes.size()) + 1;
  const int count = std::min(
      static_cast<int>(std::lround(fraction * static_cast<double>(inner.size()))), loops - 2);
  std::vector<bool> shut(layout.edges.size(), false);
  for (int k = 0; k < count; ++k) shut[inner[k]] = true;
  return shut;
}

}  // namespace

Layout MakeOffice(const OfficeOptions& o, const RouteOptions& route, Rng& rng) {
  const double cw = o.corridor_width_m, clear = route.clearance_m();
  if (0.5 * cw < clear) {
    FailParameter("corridor_width_m", cw,
                  "narrower than the route's clearance; must be >= 2 x (robot_radius_m + "
                  "clearance_margin_m) = " +
                      FormatNumber(2.0 * clear));
  }
  if (o.room_visit_fraction > 0.0 && 0.5 * o.door_width_m < clear) {
    FailParameter("door_width_m", o.door_width_m,
                  "too narrow for the route to visit rooms; must be >= " +
                      FormatNumber(2.0 * clear) + " (or room_visit_fraction = 0)");
  }
  const int nx = GridCount(o.width_m, cw, o.block_m), ny = GridCount(o.height_m, cw, o.block_m);
  CheckTwoLoops(nx, ny, "width_m", o.width_m, "height_m", o.height_m, o.block_m + cw, cw,
                "an office of");
  const std::vector<double> xs = GridLines(o.width_m, cw, nx);
  const std::vector<double> ys = GridLines(o.height_m, cw, ny);
  Layout layout;
  AddOuterWalls(o.width_m, o.height_m, kOuterWallM, &layout);
  AddGridGraph(xs, ys, &layout);
  const std::vector<bool> shut = ShutCorridors(layout, nx, ny, o.closed_corridor_fraction, rng);
  // A shut stretch gets a door leaf across each end.
  for (std::size_t e = 0; e < shut.size(); ++e) {
    if (!shut[e]) continue;
    const Eigen::Vector2d a = layout.nodes[layout.edges[e].a], b = layout.nodes[layout.edges[e].b];
    const Eigen::Vector2d along = (b - a).normalized(), across(-along.y(), along.x());
    for (const auto& [end, dir] : {std::pair{a, along}, std::pair{b, Eigen::Vector2d(-along)}}) {
      const Eigen::Vector2d p0 = end + 0.5 * cw * dir - 0.5 * cw * across;
      const Eigen::Vector2d p1 = end + (0.5 * cw + 0.1) * dir + 0.5 * cw * across;
      layout.walls.push_back(Box(p0.cwiseMin(p1), p0.cwiseMax(p1)));
    }
  }
  for (int bj = 0; bj < ny; ++bj) {
    for (int bi = 0; bi < nx; ++bi) {
      Block block;
      block.r = {{xs[bi] + 0.5 * cw, ys[bj] + 0.5 * cw},
                 {xs[bi + 1] - 0.5 * cw, ys[bj + 1] - 0.5 * cw}};
      block.bottom_edge = shut[bj * nx + bi] ? -1 : bj * nx + bi;
      block.top_edge = shut[(bj + 1) * nx + bi] ? -1 : (bj + 1) * nx + bi;
      block.bottom_x0 = block.top_x0 = xs[bi];
      MakeOfficeBlock(block, o, route, rng, &layout);
    }
  }
  std::vector<LayoutEdge> open;
  for (std::size_t e = 0; e < layout.edges.size(); ++e) {
    if (!shut[e]) open.push_back(layout.edges[e]);
  }
  layout.edges = std::move(open);
  return layout;
}

Layout MakeCorridor(const CorridorOptions& o, const RouteOptions& route, Rng& rng) {
  const double hw = o.hallway_width_m, clear = route.clearance_m();
  // Features stand up to 0.2 m out of the walls.
  if (0.5 * hw - 0.2 < clear) {
    FailParameter("hallway_width_m", hw,
                  "narrower than the route's clearance beside a wall feature; must be >= " +
                      FormatNumber(2.0 * (clear + 0.2)));
  }
  const int nx = o.rungs - 1, ny = o.hallways - 1;
  const double height = ny * (o.block_m + hw) + hw;
  std::vector<double> xs = GridLines(o.length_m, hw, nx);
  std::vector<double> ys = GridLines(height, hw, ny);
  if (xs[1] - xs[0] - hw < 1.0) {
    FailParameter("length_m", o.length_m,
                  "too short for " + std::to_string(o.rungs) +
                      " rungs; must be >= " + FormatNumber(nx * (hw + 1.0) + hw));
  }
  Layout layout;
  AddOuterWalls(o.length_m, height, kOuterWallM, &layout);
  AddGridGraph(xs, ys, &layout);
  const auto matte = [] { return SurfaceMaterial::kMatte; };
  // Sparse features along every face that lines a hallway: a glass stretch, a cabinet or a half
  // pillar, about every feature_spacing_m.
  // (The outer walls have nothing behind them to see through glass: no glass there.)
  auto featured_face = [&](Eigen::Vector2d a, Eigen::Vector2d b, Eigen::Vector2d normal,
                           bool glass_allowed) {
    const double length = (b - a).norm();
    const Eigen::Vector2d d = (b - a) / length;
    std::vector<Gap> glass;
    for (double s = o.feature_spacing_m * rng.Uniform(0.3, 1.0); s < length - 3.0;
         s += o.feature_spacing_m * rng.Uniform(0.5, 1.5)) {
      if (rng.Chance(o.glass_fraction) && glass_allowed) {
        const double stretch = std::min(rng.Uniform(2.0, 6.0), length - s - 1.0);
        glass.push_back({s, s + stretch, false});
      } else if (rng.Chance(0.5)) {
        const Eigen::Vector2d p0 = a + s * d, p1 = a + (s + 0.6) * d + 0.18 * normal;
        layout.walls.push_back(Box(p0.cwiseMin(p1), p0.cwiseMax(p1)));
      } else {
        layout.walls.push_back(Disc(a + s * d, 0.2));
      }
    }
    AddFaceWall(a, b, normal, kBlockWallM, glass, matte, &layout);
    for (const Gap& g : glass) {  // the glass in the openings
      const Eigen::Vector2d p0 = a + g.from * d, p1 = a + g.to * d - 0.05 * normal;
      layout.walls.push_back(Box(p0.cwiseMin(p1), p0.cwiseMax(p1), SurfaceMaterial::kGlass));
    }
  };
  for (int bj = 0; bj < ny; ++bj) {
    for (int bi = 0; bi < nx; ++bi) {
      const Eigen::Vector2d lo(xs[bi] + 0.5 * hw, ys[bj] + 0.5 * hw);
      const Eigen::Vector2d hi(xs[bi + 1] - 0.5 * hw, ys[bj + 1] - 0.5 * hw);
      featured_face(lo, {hi.x(), lo.y()}, {0, -1}, true);
      featured_face({lo.x(), hi.y()}, hi, {0, 1}, true);
      AddFaceWall(lo, {lo.x(), hi.y()}, {-1, 0}, kBlockWallM, {}, matte, &layout);
      AddFaceWall({hi.x(), lo.y()}, hi, {1, 0}, kBlockWallM, {}, matte, &layout);
    }
  }
  featured_face({0, 0}, {o.length_m, 0}, {0, 1}, false);
  featured_face({0, height}, {o.length_m, height}, {0, -1}, false);
  return layout;
}

}  // namespace slamrig::sim::worldgen
