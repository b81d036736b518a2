#include "sim/worldgen/layout.h"

#include <algorithm>
#include <cmath>

#include "sim/worldgen/layout_parts.h"
#include "slam/types/error.h"
#include "slam/types/validation.h"

namespace slamrig::sim::worldgen {

ShapeSpec Box(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, SurfaceMaterial material) {
  ShapeSpec s;
  s.type = ShapeType::kBox;
  s.center_m = 0.5 * (lo + hi);
  s.size_m = (hi - lo).cwiseAbs();
  s.material = material;
  return s;
}

ShapeSpec Disc(const Eigen::Vector2d& center, double radius, SurfaceMaterial material) {
  ShapeSpec s;
  s.type = ShapeType::kCircle;
  s.center_m = center;
  s.radius_m = radius;
  s.material = material;
  return s;
}

void AddGridGraph(const std::vector<double>& xs, const std::vector<double>& ys, Layout* layout) {
  const int nxp = static_cast<int>(xs.size()), nyp = static_cast<int>(ys.size());
  const int first = static_cast<int>(layout->nodes.size());
  for (int j = 0; j < nyp; ++j) {
    for (int i = 0; i < nxp; ++i) layout->nodes.emplace_back(xs[i], ys[j]);
  }
  // Horizontal edges first (H(i, j) = j * (nxp - 1) + i), then vertical ones.
  for (int j = 0; j < nyp; ++j) {
    for (int i = 0; i + 1 < nxp; ++i) {
      layout->edges.push_back({first + j * nxp + i, first + j * nxp + i + 1, {}});
    }
  }
  for (int j = 0; j + 1 < nyp; ++j) {
    for (int i = 0; i < nxp; ++i) {
      layout->edges.push_back({first + j * nxp + i, first + (j + 1) * nxp + i, {}});
    }
  }
}

void FailParameter(const std::string& field, double value, const std::string& rule) {
  throw ParameterError(field, field + " = " + FormatNumber(value) + "; " + rule);
}

std::vector<double> GridLines(double extent, double width, int count) {
  std::vector<double> lines;
  const double pitch = (extent - width) / count;
  for (int i = 0; i <= count; ++i) lines.push_back(0.5 * width + i * pitch);
  return lines;
}

int GridCount(double extent, double width, double block) {
  return std::max(1, static_cast<int>(std::lround((extent - width) / (block + width))));
}

void CheckTwoLoops(int nx, int ny, const char* width_field, double width, const char* height_field,
                   double height, double block_pitch, double corridor, const std::string& what) {
  if (nx * ny >= 2) return;
  // GridCount rounds: a second block from 1.5 block pitches on.
  const double least = std::ceil(1.5 * block_pitch + corridor);
  FailParameter(width_field, width,
                "too small for two loops: " + what + " " + FormatNumber(width) + " x " +
                    FormatNumber(height) + " m holds one block; needs " + width_field + " >= " +
                    FormatNumber(least) + " or " + height_field + " >= " + FormatNumber(least));
}

void AddFaceWall(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& normal,
                 double thickness, const std::vector<Gap>& gaps,
                 const std::function<SurfaceMaterial()>& material, Layout* layout) {
  const double length = (b - a).norm();
  const Eigen::Vector2d d = (b - a) / length;
  auto piece = [&](double s0, double s1, double depth0, double depth1, SurfaceMaterial m) {
    if (s1 - s0 < 0.02) return;
    const Eigen::Vector2d p0 = a + s0 * d - depth0 * normal;
    const Eigen::Vector2d p1 = a + s1 * d - depth1 * normal;
    layout->walls.push_back(Box(p0.cwiseMin(p1), p0.cwiseMax(p1), m));
  };
  double s = 0.0;
  for (const Gap& g : gaps) {
    piece(s, g.from, 0.0, thickness, material());
    if (g.shut) piece(g.from, g.to, 0.02, 0.1, SurfaceMaterial::kMatte);  // the door leaf
    s = g.to;
  }
  piece(s, length, 0.0, thickness, material());
}

std::function<SurfaceMaterial()> MaterialDraw(Rng& rng, double glass, double black) {
  return [&rng, glass, black] {
    const double u = rng.Uniform();
    if (u < glass) return SurfaceMaterial::kGlass;
    if (u < glass + black) return SurfaceMaterial::kBlack;
    return SurfaceMaterial::kMatte;
  };
}

void AddOuterWalls(double width, double height, double t, Layout* layout) {
  const auto matte = [] { return SurfaceMaterial::kMatte; };
  AddFaceWall({0, 0}, {width, 0}, {0, 1}, t, {}, matte, layout);
  AddFaceWall({0, height}, {width, height}, {0, -1}, t, {}, matte, layout);
  AddFaceWall({0, -t}, {0, height + t}, {1, 0}, t, {}, matte, layout);
  AddFaceWall({width, -t}, {width, height + t}, {-1, 0}, t, {}, matte, layout);
  layout->min_m = Eigen::Vector2d(-t, -t);
  layout->max_m = Eigen::Vector2d(width + t, height + t);
}

Layout MakeLayout(const GenerateSpec& spec) {
  Rng rng(spec.seed);
  Layout layout;
  switch (spec.kind) {
    case WorldKind::kOffice:
      layout = MakeOffice(spec.office, spec.route, rng);
      break;
    case WorldKind::kWarehouse:
      layout = MakeWarehouse(spec.warehouse, spec.route, rng);
      break;
    case WorldKind::kCorridor:
      layout = MakeCorridor(spec.corridor, spec.route, rng);
      break;
    case WorldKind::kCampus:
      layout = MakeCampus(spec.campus, spec.route, rng);
      break;
    case WorldKind::kMaze:
      layout = MakeMaze(spec.maze, spec.route, rng);
      break;
  }
  layout.name = std::string(WorldKindName(spec.kind)) + "_" + std::to_string(spec.seed);
  for (LayoutEdge& e : layout.edges) {
    std::sort(e.spurs.begin(), e.spurs.end(),
              [](const Spur& x, const Spur& y) { return x.at_m < y.at_m; });
  }
  return layout;
}

}  // namespace slamrig::sim::worldgen
