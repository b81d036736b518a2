#include "sim/shape_spec.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace slamrig::sim {
namespace {

using ::testing::HasSubstr;

ShapeSpec Polygon(std::vector<Eigen::Vector2d> points) {
  ShapeSpec s;
  s.type = ShapeType::kPolygon;
  s.points_m = std::move(points);
  return s;
}

TEST(ShapeSpecTest, RejectsASelfIntersectingPolygon) {
  const ShapeSpec bow_tie = Polygon({{0, 0}, {2, 2}, {2, 0}, {0, 2}});
  ASSERT_EQ(bow_tie.Validate().size(), 1u);
  EXPECT_THAT(bow_tie.Validate()[0], HasSubstr("edges 0 and 2 cross"));
  const ShapeSpec l_shape = Polygon({{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}});
  EXPECT_TRUE(l_shape.Validate().empty());
  EXPECT_FALSE(l_shape.IsConvexPolygon());
}

TEST(ShapeSpecTest, NamesTheBrokenField) {
  ShapeSpec circle;
  circle.type = ShapeType::kCircle;
  circle.radius_m = -1.0;
  EXPECT_EQ(circle.Validate(), std::vector<std::string>{"radius_m = -1; must be > 0"});
  ShapeSpec box;
  box.size_m = {0.0, 1.0};
  EXPECT_THAT(box.Validate()[0], HasSubstr("size_m = [0, 1]"));
  const ShapeSpec tiny_edge = Polygon({{0, 0}, {1, 0}, {1, 0.001}});
  EXPECT_THAT(tiny_edge.Validate()[0], HasSubstr("edge 1 is 0.001 m long"));
}

TEST(ShapeSpecTest, ContainsPointsOfRotatedBoxesPolygonsAndCircles) {
  ShapeSpec box;
  box.center_m = {1.0, 1.0};
  box.size_m = {4.0, 0.5};
  box.angle_rad = std::numbers::pi / 2;  // now 0.5 wide along x, 4 along y
  EXPECT_TRUE(box.Contains({1.1, 2.9}));
  EXPECT_FALSE(box.Contains({2.9, 1.1}));
  const ShapeSpec l_shape = Polygon({{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}});
  EXPECT_TRUE(l_shape.Contains({0.5, 1.5}));
  EXPECT_FALSE(l_shape.Contains({1.5, 1.5}));
  ShapeSpec polyline;
  polyline.type = ShapeType::kPolyline;
  polyline.points_m = {{0, 0}, {1, 0}};
  EXPECT_FALSE(polyline.Contains({0.5, 0.0}));
}

TEST(ShapeSpecTest, OutlineIsCounterClockwise) {
  const ShapeSpec clockwise = Polygon({{0, 0}, {0, 1}, {1, 1}, {1, 0}});
  EXPECT_GT(TwiceSignedArea(clockwise.Outline()), 0.0);
  EXPECT_TRUE(clockwise.IsConvexPolygon());
  ShapeSpec box;
  EXPECT_NEAR(TwiceSignedArea(box.Outline()), 2.0, 1e-12);
}

}  // namespace
}  // namespace slamrig::sim
