#include "slam/graph/g2o_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <ostream>
#include <string>

#include "slam/graph/testing/random_graph.h"
#include "slam/types/error.h"
#include "tests/util/temp_dir.h"

namespace slamrig::slam {
namespace {

using slamrig::testing::TempDir;
using ::testing::HasSubstr;

constexpr const char* kTiny =
    "# a comment\n"
    "VERTEX_SE2 0 0 0 0\n"
    "VERTEX_SE2 1 1.5 -0.25 0.5\n"
    "\n"
    "VERTEX_SE2 7 2 1 -3\n"
    "FIX 0\n"
    "EDGE_SE2 0 1 1.5 -0.25 0.5 10 1 0.5 20 2 30\n"
    "EDGE_SE2 7 0 -1 0.5 0.1 1 0 0 1 0 1\n";

void ExpectSameGraph(const PoseGraph& a, const PoseGraph& b) {
  ASSERT_EQ(a.vertices().size(), b.vertices().size());
  ASSERT_EQ(a.edges().size(), b.edges().size());
  for (std::size_t i = 0; i < a.vertices().size(); ++i) {
    EXPECT_EQ(a.vertices()[i].id, b.vertices()[i].id);
    EXPECT_EQ(a.vertices()[i].pose, b.vertices()[i].pose);
    EXPECT_EQ(a.vertices()[i].fixed, b.vertices()[i].fixed);
  }
  for (std::size_t i = 0; i < a.edges().size(); ++i) {
    EXPECT_EQ(a.edges()[i].from, b.edges()[i].from);
    EXPECT_EQ(a.edges()[i].to, b.edges()[i].to);
    EXPECT_EQ(a.edges()[i].measurement, b.edges()[i].measurement);
    EXPECT_EQ(a.edges()[i].information, b.edges()[i].information);
    EXPECT_EQ(a.edges()[i].kind, b.edges()[i].kind);
  }
}

TEST(G2oIoTest, ReadsVerticesEdgesFixAndKinds) {
  TempDir dir;
  const PoseGraph g = ReadG2o(dir.Write("tiny.g2o", kTiny));
  ASSERT_EQ(g.vertices().size(), 3u);
  EXPECT_EQ(g.vertices()[2].id, 7);
  EXPECT_EQ(g.pose(1), Pose2(1.5, -0.25, 0.5));
  EXPECT_TRUE(g.vertex(0).fixed);
  EXPECT_FALSE(g.vertex(7).fixed);
  ASSERT_EQ(g.edges().size(), 2u);
  const PoseGraphEdge& e = g.edges()[0];
  EXPECT_EQ(e.kind, EdgeKind::kOdometry);
  EXPECT_EQ(g.edges()[1].kind, EdgeKind::kLoopClosure);
  Eigen::Matrix3d expected;
  expected << 10, 1, 0.5, 1, 20, 2, 0.5, 2, 30;
  EXPECT_EQ(e.information, expected);
}

TEST(G2oIoTest, RoundTripsARandomGraphBitForBit) {
  TempDir dir;
  testing::RandomPoseGraph r = testing::MakeRandomPoseGraph({.num_poses = 40, .seed = 3});
  r.graph.SetFixed(5, true);
  const std::string path = dir.File("random.g2o");
  WriteG2o(path, r.graph);
  const PoseGraph back = ReadG2o(path);
  ExpectSameGraph(r.graph, back);
  EXPECT_EQ(FormatG2o(back), FormatG2o(r.graph));
}

TEST(G2oIoTest, ReadsGzip) {
  TempDir dir;
  const std::string path = dir.File("tiny.g2o.gz");
  gzFile f = gzopen(path.c_str(), "wb");
  const std::string text = kTiny;
  gzwrite(f, text.data(), static_cast<unsigned>(text.size()));
  gzclose(f);
  ExpectSameGraph(ReadG2o(path), ReadG2o(dir.Write("tiny.g2o", kTiny)));
}

TEST(G2oIoTest, EdgesDefineTheVerticesWhenThereAreNoVertexLines) {
  TempDir dir;
  const PoseGraph g = ReadG2o(dir.Write("edges.g2o",
                                        "EDGE_SE2 2 3 1 0 0 1 0 0 1 0 1\n"
                                        "EDGE_SE2 0 2 1 0 0 1 0 0 1 0 1\n"));
  ASSERT_EQ(g.vertices().size(), 3u);
  EXPECT_EQ(g.vertices()[0].id, 0);
  EXPECT_EQ(g.vertices()[1].id, 2);
  EXPECT_EQ(g.vertices()[2].id, 3);
  EXPECT_EQ(g.pose(3), Pose2());
}

struct BadCase {
  const char* name;
  const char* text;
  const char* message;  // expected after "<path>:"
};

void PrintTo(const BadCase& c, std::ostream* os) { *os << c.name; }

class G2oBadInputTest : public ::testing::TestWithParam<BadCase> {};

TEST_P(G2oBadInputTest, IsOneParseErrorWithFileLineAndField) {
  TempDir dir;
  const std::string path = dir.Write("bad.g2o", GetParam().text);
  try {
    ReadG2o(path);
    FAIL() << "no error for " << GetParam().name;
  } catch (const ParseError& e) {
    EXPECT_EQ(std::string(e.what()), path + ":" + GetParam().message);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, G2oBadInputTest,
    ::testing::Values(
        BadCase{"unknown_tag", "VERTEX_SE2 0 0 0 0\nVERTEX_XY 1 2 3\n",
                "2: tag: unknown record 'VERTEX_XY' (expected VERTEX_SE2, EDGE_SE2 or FIX)"},
        BadCase{"vertex_field_count", "VERTEX_SE2 0 0 0\n",
                "1: VERTEX_SE2: expected 4 fields (id x y theta), found 3"},
        BadCase{"edge_field_count", "VERTEX_SE2 0 0 0 0\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0 1 9\n",
                "2: EDGE_SE2: expected 11 fields (from to dx dy dtheta I11 I12 I13 I22 I23 I33), "
                "found 12"},
        BadCase{"non_number", "VERTEX_SE2 0 0 abc 0\n",
                "1: VERTEX_SE2.y: expected a finite number, got 'abc'"},
        BadCase{"nan", "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nEDGE_SE2 0 1 nan 0 0 1 0 0 1 0 1\n",
                "3: EDGE_SE2.dx: expected a finite number, got 'nan'"},
        BadCase{"inf", "VERTEX_SE2 0 0 0 inf\n",
                "1: VERTEX_SE2.theta: expected a finite number, got 'inf'"},
        BadCase{"trailing_garbage", "VERTEX_SE2 0 1.5x 0 0\n",
                "1: VERTEX_SE2.x: expected a finite number, got '1.5x'"},
        BadCase{"bad_id", "VERTEX_SE2 -1 0 0 0\n",
                "1: VERTEX_SE2.id: expected a non-negative integer vertex id, got '-1'"},
        BadCase{"not_positive_definite",
                "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nEDGE_SE2 0 1 1 0 0 1 2 0 1 0 1\n",
                "3: EDGE_SE2.information: the matrix (I11 I12 I13 I22 I23 I33) is not positive "
                "definite"},
        BadCase{"zero_information",
                "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nEDGE_SE2 0 1 1 0 0 0 0 0 0 0 0\n",
                "3: EDGE_SE2.information: the matrix (I11 I12 I13 I22 I23 I33) is not positive "
                "definite"},
        BadCase{"missing_vertex",
                "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n"
                "EDGE_SE2 1 5 1 0 0 1 0 0 1 0 1\n",
                "4: EDGE_SE2.to: vertex 5 is not defined by any VERTEX_SE2 line"},
        BadCase{"duplicate_vertex", "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nVERTEX_SE2 0 1 1 1\n",
                "3: VERTEX_SE2.id: duplicate vertex id 0"},
        BadCase{"self_edge", "VERTEX_SE2 0 0 0 0\nEDGE_SE2 0 0 1 0 0 1 0 0 1 0 1\n",
                "2: EDGE_SE2.to: edge from vertex 0 to itself"},
        BadCase{"fix_missing", "VERTEX_SE2 0 0 0 0\nFIX 3\n", "2: FIX.id: vertex 3 is not defined"},
        BadCase{"fix_empty", "VERTEX_SE2 0 0 0 0\nFIX\n",
                "2: FIX: expected at least one vertex id"}),
    [](const ::testing::TestParamInfo<BadCase>& p) { return std::string(p.param.name); });

TEST(G2oIoTest, MissingFileIsAParseError) {
  EXPECT_THROW(ReadG2o("/nonexistent/graph.g2o"), ParseError);
}

}  // namespace
}  // namespace slamrig::slam
