#include "slam/graph/g2o_io.h"

#include <Eigen/Cholesky>
#include <charconv>
#include <cmath>
#include <set>
#include <string_view>
#include <utility>
#include <vector>

#include "slam/io/atomic_file.h"
#include "slam/io/line_reader.h"
#include "slam/types/error.h"

namespace slamrig::slam {
namespace {

constexpr const char* kVertexFields[] = {"id", "x", "y", "theta"};
constexpr const char* kEdgeFields[] = {"from", "to",  "dx",  "dy",  "dtheta", "I11",
                                       "I12",  "I13", "I22", "I23", "I33"};

// Whitespace-separated tokens of one line.
std::vector<std::string_view> Tokens(std::string_view line) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
  return tokens;
}

// Reads one line's fields, throwing ParseError with the location on the first bad one.
class LineParser {
 public:
  LineParser(std::string where, std::string_view tag) : where_(std::move(where)), tag_(tag) {}

  [[noreturn]] void Fail(const std::string& field, const std::string& problem) const {
    throw ParseError(where_ + tag_ + (field.empty() ? "" : "." + field) + ": " + problem);
  }

  int Id(std::string_view token, const char* field) const {
    int value = 0;
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc() || end != token.data() + token.size() || value < 0) {
      Fail(field, "expected a non-negative integer vertex id, got '" + std::string(token) + "'");
    }
    return value;
  }

  double Number(std::string_view token, const char* field) const {
    double value = 0.0;
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc() || end != token.data() + token.size() || !std::isfinite(value)) {
      Fail(field, "expected a finite number, got '" + std::string(token) + "'");
    }
    return value;
  }

 private:
  std::string where_;
  std::string tag_;
};

// An edge as read, with its line for messages about its ends, checked once all lines are in.
struct PendingEdge {
  PoseGraphEdge edge;
  std::string where;
};

struct PendingFix {
  int id;
  std::string where;
};

std::string FormatDouble(double v) {
  char buffer[64];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof(buffer), v);
  return std::string(buffer, end);
}

}  // namespace

PoseGraph ReadG2o(const std::string& path) {
  LineReader reader(path);
  PoseGraph graph;
  std::vector<PendingEdge> edges;
  std::vector<PendingFix> fixes;
  std::string_view line;
  while (reader.Next(&line)) {
    const std::vector<std::string_view> t = Tokens(line);
    if (t.empty() || t[0].front() == '#') continue;
    const std::string where = path + ":" + std::to_string(reader.line_number()) + ": ";
    const LineParser p(where, t[0]);
    if (t[0] == "VERTEX_SE2") {
      if (t.size() != 5) {
        p.Fail("", "expected 4 fields (id x y theta), found " + std::to_string(t.size() - 1));
      }
      const int id = p.Id(t[1], kVertexFields[0]);
      if (graph.HasVertex(id)) p.Fail("id", "duplicate vertex id " + std::to_string(id));
      graph.AddVertex(id, Pose2(p.Number(t[2], "x"), p.Number(t[3], "y"), p.Number(t[4], "theta")));
    } else if (t[0] == "EDGE_SE2") {
      if (t.size() != 12) {
        p.Fail("", "expected 11 fields (from to dx dy dtheta I11 I12 I13 I22 I23 I33), found " +
                       std::to_string(t.size() - 1));
      }
      PendingEdge e{.edge = {}, .where = where};
      e.edge.from = p.Id(t[1], kEdgeFields[0]);
      e.edge.to = p.Id(t[2], kEdgeFields[1]);
      if (e.edge.from == e.edge.to)
        p.Fail("to", "edge from vertex " + std::string(t[1]) + " to itself");
      double v[9];
      for (int k = 2; k < 11; ++k) v[k - 2] = p.Number(t[k + 1], kEdgeFields[k]);
      e.edge.measurement = Pose2(v[0], v[1], v[2]);
      Eigen::Matrix3d& info = e.edge.information;
      info << v[3], v[4], v[5], v[4], v[6], v[7], v[5], v[7], v[8];
      if (Eigen::LLT<Eigen::Matrix3d>(info).info() != Eigen::Success) {
        p.Fail("information", "the matrix (I11 I12 I13 I22 I23 I33) is not positive definite");
      }
      const int gap = e.edge.to - e.edge.from;
      e.edge.kind = (gap == 1 || gap == -1) ? EdgeKind::kOdometry : EdgeKind::kLoopClosure;
      edges.push_back(std::move(e));
    } else if (t[0] == "FIX") {
      if (t.size() < 2) p.Fail("", "expected at least one vertex id");
      for (std::size_t k = 1; k < t.size(); ++k) fixes.push_back({p.Id(t[k], "id"), where});
    } else {
      throw ParseError(where + "tag: unknown record '" + std::string(t[0]) +
                       "' (expected VERTEX_SE2, EDGE_SE2 or FIX)");
    }
  }

  // Without VERTEX_SE2 lines the edges define the vertices; otherwise every end must exist.
  if (graph.empty()) {
    std::set<int> ids;
    for (const PendingEdge& e : edges) ids.insert({e.edge.from, e.edge.to});
    for (const int id : ids) graph.AddVertex(id, Pose2());
  }
  for (const PendingEdge& e : edges) {
    for (const auto& [field, id] : {std::pair{"from", e.edge.from}, std::pair{"to", e.edge.to}}) {
      if (!graph.HasVertex(id)) {
        throw ParseError(e.where + "EDGE_SE2." + field + ": vertex " + std::to_string(id) +
                         " is not defined by any VERTEX_SE2 line");
      }
    }
    graph.AddEdge(e.edge);
  }
  for (const PendingFix& f : fixes) {
    if (!graph.HasVertex(f.id)) {
      throw ParseError(f.where + "FIX.id: vertex " + std::to_string(f.id) + " is not defined");
    }
    graph.SetFixed(f.id, true);
  }
  return graph;
}

std::string FormatG2o(const PoseGraph& graph) {
  std::string out;
  out.reserve(64 * graph.vertices().size() + 160 * graph.edges().size());
  for (const PoseGraphVertex& v : graph.vertices()) {
    out += "VERTEX_SE2 " + std::to_string(v.id) + " " + FormatDouble(v.pose.x()) + " " +
           FormatDouble(v.pose.y()) + " " + FormatDouble(v.pose.theta()) + "\n";
  }
  for (const PoseGraphVertex& v : graph.vertices()) {
    if (v.fixed) out += "FIX " + std::to_string(v.id) + "\n";
  }
  for (const PoseGraphEdge& e : graph.edges()) {
    const Eigen::Matrix3d& i = e.information;
    out += "EDGE_SE2 " + std::to_string(e.from) + " " + std::to_string(e.to);
    for (const double v : {e.measurement.x(), e.measurement.y(), e.measurement.theta(), i(0, 0),
                           i(0, 1), i(0, 2), i(1, 1), i(1, 2), i(2, 2)}) {
      out += " " + FormatDouble(v);
    }
    out += "\n";
  }
  return out;
}

void WriteG2o(const std::string& path, const PoseGraph& graph) {
  WriteFileAtomically(path, FormatG2o(graph));
}

}  // namespace slamrig::slam
