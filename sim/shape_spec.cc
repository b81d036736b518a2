#include "sim/shape_spec.h"

#include <algorithm>
#include <cmath>

#include "slam/types/validation.h"

namespace slamrig::sim {
namespace {

// Box2D welds vertices closer than half its linear slop (0.005 m); keep clear of that.
constexpr double kMinEdgeLengthM = 0.01;
constexpr int kMaxBox2dPolygonVertices = 8;

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// Sign of the turn a -> b -> c: +1 left, -1 right, 0 collinear.
int Orientation(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  const double v = Cross(b - a, c - a);
  return (v > 0.0) - (v < 0.0);
}

bool OnSegment(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p) {
  return std::min(a.x(), b.x()) <= p.x() && p.x() <= std::max(a.x(), b.x()) &&
         std::min(a.y(), b.y()) <= p.y() && p.y() <= std::max(a.y(), b.y());
}

}  // namespace

const char* SurfaceMaterialName(SurfaceMaterial material) {
  switch (material) {
    case SurfaceMaterial::kMatte:
      return "matte";
    case SurfaceMaterial::kGlass:
      return "glass";
    case SurfaceMaterial::kBlack:
      return "black";
  }
  return "?";
}

const char* ShapeTypeName(ShapeType type) {
  switch (type) {
    case ShapeType::kBox:
      return "box";
    case ShapeType::kPolygon:
      return "polygon";
    case ShapeType::kPolyline:
      return "polyline";
    case ShapeType::kCircle:
      return "circle";
  }
  return "?";
}

bool SegmentsIntersect(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                       const Eigen::Vector2d& d) {
  const int o1 = Orientation(a, b, c), o2 = Orientation(a, b, d);
  const int o3 = Orientation(c, d, a), o4 = Orientation(c, d, b);
  if (o1 != o2 && o3 != o4) return true;
  return (o1 == 0 && OnSegment(a, b, c)) || (o2 == 0 && OnSegment(a, b, d)) ||
         (o3 == 0 && OnSegment(c, d, a)) || (o4 == 0 && OnSegment(c, d, b));
}

double TwiceSignedArea(const std::vector<Eigen::Vector2d>& points) {
  double sum = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    sum += Cross(points[i], points[(i + 1) % points.size()]);
  }
  return sum;
}

std::vector<std::string> ShapeSpec::Validate() const {
  Rules rules;
  const std::vector<std::string>& errors = rules.errors();
  switch (type) {
    case ShapeType::kBox:
      rules.Require(size_m.x() > 0.0 && size_m.y() > 0.0, "size_m",
                    "[" + FormatNumber(size_m.x()) + ", " + FormatNumber(size_m.y()) + "]",
                    "both must be > 0");
      break;
    case ShapeType::kCircle:
      rules.Positive("radius_m", radius_m);
      break;
    case ShapeType::kPolygon:
    case ShapeType::kPolyline: {
      const bool polygon = type == ShapeType::kPolygon;
      const std::size_t min_points = polygon ? 3 : 2;
      if (points_m.size() < min_points) {
        rules.Add("points_m has " + std::to_string(points_m.size()) + " points; a " +
                  ShapeTypeName(type) + " needs at least " + std::to_string(min_points));
        break;
      }
      const bool loop = polygon || closed;
      const std::size_t num_edges = loop ? points_m.size() : points_m.size() - 1;
      for (std::size_t i = 0; i < num_edges; ++i) {
        const double length = (points_m[(i + 1) % points_m.size()] - points_m[i]).norm();
        if (length < kMinEdgeLengthM) {
          rules.Add("points_m: edge " + std::to_string(i) + " is " + FormatNumber(length) +
                    " m long; must be >= " + FormatNumber(kMinEdgeLengthM) + " m");
        }
      }
      if (!errors.empty() || !polygon) break;
      // A simple polygon: no two non-adjacent edges meet.
      const std::size_t n = points_m.size();
      for (std::size_t i = 0; i < n && errors.empty(); ++i) {
        for (std::size_t j = i + 2; j < n; ++j) {
          if (i == 0 && j == n - 1) continue;  // adjacent through the closing edge
          if (SegmentsIntersect(points_m[i], points_m[(i + 1) % n], points_m[j],
                                points_m[(j + 1) % n])) {
            rules.Add("points_m: edges " + std::to_string(i) + " and " + std::to_string(j) +
                      " cross; the polygon must not self-intersect");
            break;
          }
        }
      }
      if (errors.empty() && std::abs(TwiceSignedArea(points_m)) < 1e-6) {
        rules.Add("points_m: the polygon has no area");
      }
      break;
    }
  }
  if (type == ShapeType::kCircle || type == ShapeType::kBox) {
    if (!points_m.empty()) {
      rules.Add(std::string("points_m is not used by a ") + ShapeTypeName(type));
    }
  }
  return rules.errors();
}

std::vector<Eigen::Vector2d> ShapeSpec::Outline() const {
  std::vector<Eigen::Vector2d> outline;
  if (type == ShapeType::kBox) {
    const double c = std::cos(angle_rad), s = std::sin(angle_rad);
    const double hx = 0.5 * size_m.x(), hy = 0.5 * size_m.y();
    for (const auto& corner : {Eigen::Vector2d(-hx, -hy), Eigen::Vector2d(hx, -hy),
                               Eigen::Vector2d(hx, hy), Eigen::Vector2d(-hx, hy)}) {
      outline.push_back(center_m + Eigen::Vector2d(c * corner.x() - s * corner.y(),
                                                   s * corner.x() + c * corner.y()));
    }
  } else if (type == ShapeType::kPolygon) {
    outline = points_m;
    if (TwiceSignedArea(outline) < 0.0) std::reverse(outline.begin(), outline.end());
  }
  return outline;
}

bool ShapeSpec::IsConvexPolygon() const {
  if (type == ShapeType::kBox) return true;
  if (type != ShapeType::kPolygon) return false;
  const auto outline = Outline();
  const std::size_t n = outline.size();
  if (n < 3 || n > kMaxBox2dPolygonVertices) return false;
  for (std::size_t i = 0; i < n; ++i) {
    if (Cross(outline[(i + 1) % n] - outline[i], outline[(i + 2) % n] - outline[(i + 1) % n]) <=
        0.0) {
      return false;
    }
  }
  return true;
}

bool ShapeSpec::Contains(const Eigen::Vector2d& point) const {
  switch (type) {
    case ShapeType::kCircle:
      return (point - center_m).squaredNorm() <= radius_m * radius_m;
    case ShapeType::kPolyline:
      return false;
    case ShapeType::kBox: {
      const Eigen::Vector2d d = point - center_m;
      const double c = std::cos(angle_rad), s = std::sin(angle_rad);
      return std::abs(c * d.x() + s * d.y()) <= 0.5 * size_m.x() &&
             std::abs(-s * d.x() + c * d.y()) <= 0.5 * size_m.y();
    }
    case ShapeType::kPolygon: {
      // Crossing-number test.
      bool inside = false;
      for (std::size_t i = 0, j = points_m.size() - 1; i < points_m.size(); j = i++) {
        const auto& a = points_m[i];
        const auto& b = points_m[j];
        if ((a.y() > point.y()) != (b.y() > point.y()) &&
            point.x() < (b.x() - a.x()) * (point.y() - a.y()) / (b.y() - a.y()) + a.x()) {
          inside = !inside;
        }
      }
      return inside;
    }
  }
  return false;
}

}  // namespace slamrig::sim
