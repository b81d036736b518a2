#include "slam/grid/ray_trace.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace slamrig::slam {
namespace {

TEST(TraceRayTest, PropertiesOverRandomRays) {
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> coord(-60, 60);
  for (int trial = 0; trial < 5000; ++trial) {
    // Sequenced draws, the last coordinate first (the order these cases were generated in).
    const int from_y = coord(rng), from_x = coord(rng), to_y = coord(rng), to_x = coord(rng);
    const Eigen::Array2i from(from_x, from_y), to(to_x, to_y);
    std::vector<Eigen::Array2i> cells;
    TraceRay(from, to, [&](int x, int y) { cells.emplace_back(x, y); });
    const int dx = to.x() - from.x(), dy = to.y() - from.y();
    ASSERT_EQ(static_cast<int>(cells.size()), std::max(std::abs(dx), std::abs(dy)));
    if (cells.empty()) continue;
    ASSERT_TRUE((cells.front() == from).all());
    // 8-connected, and the end cell follows the last visited one.
    cells.push_back(to);
    const double length = std::hypot(dx, dy);
    for (std::size_t i = 0; i < cells.size(); ++i) {
      if (i > 0) {
        const Eigen::Array2i step = (cells[i] - cells[i - 1]).abs();
        ASSERT_LE(step.maxCoeff(), 1);
        ASSERT_EQ(step.maxCoeff(), 1);
      }
      // Distance along the minor axis to the exact line stays within half a cell.
      const Eigen::Array2i d = cells[i] - from;
      const double cross =
          std::abs(static_cast<double>(d.x()) * dy - static_cast<double>(d.y()) * dx);
      const double minor_offset = cross / std::max(std::abs(dx), std::abs(dy));
      ASSERT_LE(minor_offset, 0.5 + 1e-9) << "trial " << trial << " length " << length;
    }
  }
}

TEST(TraceRayTest, SameCellVisitsNothing) {
  int visits = 0;
  TraceRay(Eigen::Array2i(3, 4), Eigen::Array2i(3, 4), [&](int, int) { ++visits; });
  EXPECT_EQ(visits, 0);
}

}  // namespace
}  // namespace slamrig::slam
