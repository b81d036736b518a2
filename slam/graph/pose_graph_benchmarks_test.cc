// The figures on the standard 2D benchmarks (SE-Sync's data/*.g2o): the optimiser must
// reach the chi2 that SE-Sync certifies globally optimal within 0.1 %: intel and city10000
// from the odometry chain, manhattan and ais2klinik from the chordal initialisation.
#include <gtest/gtest.h>

#include <string>

#include "slam/graph/g2o_io.h"
#include "slam/graph/graph_initialization.h"
#include "slam/graph/pose_graph_optimizer.h"
#include "tests/util/dataset.h"

namespace slamrig::slam {
namespace {

PoseGraphSummary Solve(const std::string& path, bool chordal) {
  PoseGraph graph = ReadG2o(path);
  if (chordal) {
    InitializeChordal(&graph);
  } else {
    InitializeFromOdometry(&graph);
  }
  return PoseGraphOptimizer({}).Optimize(&graph);
}

TEST(PoseGraphBenchmarksTest, IntelFromOdometryReachesTheCertifiedOptimum) {
  SLAMRIG_REQUIRE_DATASET(path, "pose_graphs_2d/intel.g2o.gz");
  const PoseGraphSummary s = Solve(path, false);
  EXPECT_EQ(s.num_vertices, 1728);
  EXPECT_EQ(s.num_edges, 2512);
  EXPECT_TRUE(s.converged) << s.message;
  EXPECT_NEAR(s.final_chi2, 45.0047, 1e-3 * 45.0047);
}

TEST(PoseGraphBenchmarksTest, City10000FromOdometryReachesTheCertifiedOptimum) {
  SLAMRIG_REQUIRE_DATASET(path, "pose_graphs_2d/city10000.g2o.gz");
  const PoseGraphSummary s = Solve(path, false);
  EXPECT_TRUE(s.converged) << s.message;
  EXPECT_NEAR(s.final_chi2, 511.985, 1e-3 * 511.985);
}

TEST(PoseGraphBenchmarksTest, ManhattanFromChordalReachesTheCertifiedOptimum) {
  SLAMRIG_REQUIRE_DATASET(path, "pose_graphs_2d/manhattan.g2o.gz");
  const PoseGraphSummary s = Solve(path, true);
  EXPECT_TRUE(s.converged) << s.message;
  EXPECT_NEAR(s.final_chi2, 3549.04, 1e-3 * 3549.04);
}

TEST(PoseGraphBenchmarksTest, Ais2klinikFromChordalReachesTheCertifiedOptimum) {
  SLAMRIG_REQUIRE_DATASET(path, "pose_graphs_2d/ais2klinik.g2o.gz");
  const PoseGraphSummary s = Solve(path, true);
  EXPECT_TRUE(s.converged) << s.message;
  EXPECT_NEAR(s.final_chi2, 172.816, 1e-3 * 172.816);
}

}  // namespace
}  // namespace slamrig::slam
