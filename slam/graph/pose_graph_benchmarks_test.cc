// The figures on the standard 2D benchmarks (SE-Sync's data/*.g2o): from the odometry
// chain and from the chordal initialisation, the optimiser must reach the chi2 that SE-Sync
// certifies globally optimal, within 0.1 %.
#include <gtest/gtest.h>

#include <ostream>
#include <string>

#include "slam/graph/g2o_io.h"
#include "slam/graph/graph_initialization.h"
#include "slam/graph/pose_graph_optimizer.h"
#include "tests/util/dataset.h"

namespace slamrig::slam {
namespace {

struct Benchmark {
  const char* name;
  int vertices;
  int edges;
  double optimal_chi2;  // SE-Sync's certified optimum, in g2o's chi2
  bool chordal;
};

void PrintTo(const Benchmark& b, std::ostream* os) {
  *os << b.name << (b.chordal ? " from chordal" : " from odometry");
}

class PoseGraphBenchmarksTest : public ::testing::TestWithParam<Benchmark> {};

TEST_P(PoseGraphBenchmarksTest, ReachesTheCertifiedOptimum) {
  const Benchmark& b = GetParam();
  SLAMRIG_REQUIRE_DATASET(path, std::string("pose_graphs_2d/") + b.name + ".g2o.gz");
  PoseGraph graph = ReadG2o(path);
  if (b.chordal) {
    InitializeChordal(&graph);
  } else {
    InitializeFromOdometry(&graph);
  }
  const PoseGraphSummary s = PoseGraphOptimizer({}).Optimize(&graph);
  EXPECT_EQ(s.num_vertices, b.vertices);
  EXPECT_EQ(s.num_edges, b.edges);
  EXPECT_TRUE(s.converged) << s.message;
  EXPECT_NEAR(s.final_chi2, b.optimal_chi2, 1e-3 * b.optimal_chi2);
  RecordProperty("iterations", s.iterations);
}

INSTANTIATE_TEST_SUITE_P(Graphs, PoseGraphBenchmarksTest,
                         ::testing::Values(Benchmark{"intel", 1728, 2512, 45.0047, false},
                                           Benchmark{"intel", 1728, 2512, 45.0047, true},
                                           Benchmark{"city10000", 10000, 20687, 511.985, false},
                                           Benchmark{"city10000", 10000, 20687, 511.985, true},
                                           Benchmark{"manhattan", 3500, 5453, 3549.04, false},
                                           Benchmark{"manhattan", 3500, 5453, 3549.04, true},
                                           Benchmark{"ais2klinik", 15115, 16727, 172.816, false},
                                           Benchmark{"ais2klinik", 15115, 16727, 172.816, true}),
                         [](const ::testing::TestParamInfo<Benchmark>& p) {
                           return std::string(p.param.name) +
                                  (p.param.chordal ? "_chordal" : "_odometry");
                         });

}  // namespace
}  // namespace slamrig::slam
