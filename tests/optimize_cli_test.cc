// `slamrig optimize` as a user runs it: a summary line and the certificate's line, the written
// graph is the library's result bit for bit, and bad input gives one error line, a non-zero exit
// and no output file.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "slam/graph/edge_error.h"
#include "slam/graph/g2o_io.h"
#include "slam/graph/graph_initialization.h"
#include "slam/graph/pose_graph_optimizer.h"
#include "slam/graph/testing/random_graph.h"
#include "tests/util/dataset.h"
#include "tests/util/read_file.h"
#include "tests/util/run_command.h"
#include "tests/util/temp_dir.h"

namespace slamrig {
namespace {

using slamrig::testing::ReadFile;

using testing::RunCommand;

const std::string kBinary = SLAMRIG_BINARY;

int CountLines(const std::string& text) {
  int n = 0;
  for (const char c : text) n += c == '\n';
  return n;
}

TEST(OptimizeCliTest, WritesTheLibrarysOptimumAndPrintsTheSummaryAndTheCertificate) {
  testing::TempDir dir;
  const slam::testing::RandomPoseGraph r =
      slam::testing::MakeRandomPoseGraph({.num_poses = 80, .seed = 21});
  const std::string in = dir.File("graph.g2o"), out = dir.File("optimised.g2o");
  slam::WriteG2o(in, r.graph);
  // No --init: chordal is the default.
  const auto result = RunCommand(kBinary + " optimize " + in + " --out " + out);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(CountLines(result.output), 2) << result.output;
  EXPECT_NE(result.output.find("\ncertified optimal (lambda_min = "), std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("80 vertices, " + std::to_string(r.graph.edges().size()) +
                               " edges; init chordal"),
            std::string::npos)
      << result.output;

  slam::PoseGraph expected = slam::ReadG2o(in);
  slam::InitializeChordal(&expected);
  const slam::PoseGraphSummary s = slam::PoseGraphOptimizer({}).Optimize(&expected);
  EXPECT_EQ(ReadFile(out), slam::FormatG2o(expected));
  char chi2[32];
  std::snprintf(chi2, sizeof(chi2), "-> %.6g in", slam::Chi2(slam::ReadG2o(out)));
  EXPECT_NE(result.output.find(chi2), std::string::npos) << result.output << " vs " << chi2;
  EXPECT_LT(s.final_chi2, s.initial_chi2);
}

// The final chi2 of a summary line ("chi2 A -> B in ...").
double FinalChi2(const std::string& output) {
  const std::size_t arrow = output.find(" -> ");
  return arrow == std::string::npos ? -1.0 : std::stod(output.substr(arrow + 4));
}

// A noisy graph (0.2 rad heading noise) where the odometry start ends in a poor local minimum:
// the default start reaches a far lower chi2 and certifies it; the odometry start's result is
// not certified.
TEST(OptimizeCliTest, TheDefaultStartAvoidsThePoorMinimumOfTheOdometryStart) {
  testing::TempDir dir;
  const std::string in = dir.File("graph.g2o");
  slam::WriteG2o(in, slam::testing::MakeRandomPoseGraph({.num_poses = 100,
                                                         .loop_closure_probability = 0.2,
                                                         .sigma_xy_m = 0.1,
                                                         .sigma_theta_rad = 0.2,
                                                         .seed = 3})
                         .graph);
  const auto by_default = RunCommand(kBinary + " optimize " + in);
  const auto from_odometry = RunCommand(kBinary + " optimize " + in + " --init odometry");
  ASSERT_EQ(by_default.exit_code, 0) << by_default.output;
  ASSERT_EQ(from_odometry.exit_code, 0) << from_odometry.output;
  EXPECT_GT(FinalChi2(by_default.output), 0.0) << by_default.output;
  EXPECT_LT(5.0 * FinalChi2(by_default.output), FinalChi2(from_odometry.output))
      << by_default.output << from_odometry.output;
  EXPECT_NE(by_default.output.find("\ncertified optimal"), std::string::npos) << by_default.output;
  EXPECT_NE(from_odometry.output.find("\nnot certified (lambda_min = "), std::string::npos)
      << from_odometry.output;
}

TEST(OptimizeCliTest, BestNamesTheStartItKeepsAndTheCertificateCanBeSkipped) {
  testing::TempDir dir;
  const std::string in = dir.File("graph.g2o");
  slam::WriteG2o(in, slam::testing::MakeRandomPoseGraph({.num_poses = 40, .seed = 4}).graph);
  const auto result = RunCommand(kBinary + " optimize " + in + " --init best --no-certificate");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(CountLines(result.output), 1) << result.output;
  EXPECT_NE(result.output.find("init best (chordal, odometry reached chi2 "), std::string::npos)
      << result.output;
}

TEST(OptimizeCliTest, BadGraphIsOneErrorLineAndNoOutput) {
  testing::TempDir dir;
  const std::string in = dir.Write("bad.g2o",
                                   "VERTEX_SE2 0 0 0 0\n"
                                   "VERTEX_SE2 1 1 0 0\n"
                                   "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 -1\n");
  const std::string out = dir.File("out.g2o");
  const auto result = RunCommand(kBinary + " optimize " + in + " --out " + out);
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_EQ(result.output, "slamrig: error: " + in +
                               ":3: EDGE_SE2.information: the matrix (I11 I12 I13 I22 I23 I33) "
                               "is not positive definite\n");
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(OptimizeCliTest, BadFlagsAreUsageErrors) {
  testing::TempDir dir;
  slam::WriteG2o(dir.File("g.g2o"), slam::testing::MakeRandomPoseGraph({.num_poses = 5}).graph);
  for (const std::string flags : {"--init nope", "--robust nope", "--trust-region nope",
                                  "--max-iterations 0", "--robust-scale -2", "--bogus"}) {
    const auto result = RunCommand(kBinary + " optimize " + dir.File("g.g2o") + " " + flags +
                                   " --out " + dir.File("out.g2o"));
    EXPECT_EQ(result.exit_code, 2) << flags << ": " << result.output;
    EXPECT_EQ(CountLines(result.output), 1) << flags << ": " << result.output;
    EXPECT_FALSE(std::filesystem::exists(dir.File("out.g2o"))) << flags;
  }
}

TEST(OptimizeCliTest, IntelReachesTheCertifiedOptimum) {
  SLAMRIG_REQUIRE_DATASET(path, "pose_graphs_2d/intel.g2o.gz");
  const auto result = RunCommand(kBinary + " optimize " + path);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("1728 vertices, 2512 edges"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("-> 45.004"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("\ncertified optimal (lambda_min = "), std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("SE-Sync's certified global optimum, cost 52.348"),
            std::string::npos)
      << result.output;
}

}  // namespace
}  // namespace slamrig
