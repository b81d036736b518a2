#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace slamrig::sim {

/// The kinds of planar geometry a world file can describe.
enum class ShapeType {
  kBox,       ///< solid rectangle: center, size, angle
  kPolygon,   ///< solid simple polygon: points (any winding, not self-intersecting)
  kPolyline,  ///< thin wall: points joined by segments, optionally closed
  kCircle,    ///< solid disc: center, radius
};

/// Name used in world files ("box", "polygon", "polyline", "circle").
const char* ShapeTypeName(ShapeType type);

/// How a wall's surface returns a lidar beam. Glass and black surfaces return a beam only near
/// normal incidence (within kSpecularReturnDeg of the surface normal, where real scanners see a
/// specular reflection); otherwise a beam passes through glass and is swallowed by black paint
/// (no return: the lidar reads its maximum range, and nothing behind is seen).
enum class SurfaceMaterial {
  kMatte,  ///< every beam that reaches it returns (the default)
  kGlass,  ///< transparent except near normal incidence
  kBlack,  ///< opaque, but returns only near normal incidence
};

/// The incidence angle from the normal up to which glass and black surfaces return a beam.
inline constexpr double kSpecularReturnDeg = 10.0;

/// Name used in world files ("matte", "glass", "black").
const char* SurfaceMaterialName(SurfaceMaterial material);

/// One piece of planar geometry in metres, in the frame of whatever owns it (the map frame for
/// walls and zones, the obstacle frame for moving obstacles). Only the fields of `type` are used.
struct ShapeSpec {
  ShapeType type = ShapeType::kBox;                    ///< which fields below apply
  Eigen::Vector2d center_m = Eigen::Vector2d::Zero();  ///< box and circle centre
  Eigen::Vector2d size_m = Eigen::Vector2d(1.0, 1.0);  ///< box full extent along its own x, y
  double angle_rad = 0.0;                              ///< box rotation, CCW
  double radius_m = 0.5;                               ///< circle radius
  std::vector<Eigen::Vector2d> points_m;               ///< polygon or polyline vertices
  bool closed = false;  ///< polyline: join the last point to the first
  SurfaceMaterial material = SurfaceMaterial::kMatte;  ///< how the lidar sees it (walls only)

  /// One message per broken rule, field names relative to the shape, e.g.
  /// "radius_m = -1; must be > 0" or "points: edges 0 and 2 cross; the polygon must be simple".
  std::vector<std::string> Validate() const;

  /// True if `point` lies inside a box, polygon or circle (never for a polyline).
  bool Contains(const Eigen::Vector2d& point) const;

  /// The vertices of a box or polygon, counter-clockwise.
  std::vector<Eigen::Vector2d> Outline() const;

  /// True for a convex polygon or box with at most 8 vertices (one Box2D polygon).
  bool IsConvexPolygon() const;
};

/// True if segments [a, b] and [c, d] share at least one point.
bool SegmentsIntersect(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                       const Eigen::Vector2d& d);

/// Twice the signed area of a closed polygon (positive when counter-clockwise).
double TwiceSignedArea(const std::vector<Eigen::Vector2d>& points);

}  // namespace slamrig::sim
