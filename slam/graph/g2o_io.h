#pragma once

#include <string>

#include "slam/graph/pose_graph.h"

namespace slamrig::slam {

/// Reads a 2D g2o file, plain or gzip: `VERTEX_SE2 id x y theta`,
/// `EDGE_SE2 from to dx dy dtheta I11 I12 I13 I22 I23 I33` (upper triangle of the information,
/// row-major) and `FIX id...`; blank lines and `#` comments are skipped. Edges with
/// |to - from| = 1 are odometry, the others loop closures. A file without any VERTEX_SE2 line
/// (e.g. SE-Sync's manhattan.g2o) gets one vertex per edge end, in ascending id order, at the
/// origin. Any other problem - an unknown tag, a wrong field count, a non-number, NaN or inf, a
/// negative id, an information matrix that is not positive definite, an edge or FIX naming a
/// vertex that is not defined, a duplicate vertex id, a self-edge - is one ParseError
/// `file:line: field: problem`.
PoseGraph ReadG2o(const std::string& path);

/// The graph as g2o text: every vertex (in order), FIX lines for fixed vertices, every edge.
/// Numbers are written in their shortest form that reads back to the same double.
std::string FormatG2o(const PoseGraph& graph);

/// Writes FormatG2o(graph) to `path` atomically.
void WriteG2o(const std::string& path, const PoseGraph& graph);

}  // namespace slamrig::slam
