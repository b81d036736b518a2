#pragma once

// Initial guesses for pose-graph optimisation. Chordal initialisation is the 2D case of the
// chordal relaxation in Carlone, Tron, Daniilidis and Dellaert, "Initialization techniques for
// 3D SLAM: a survey on rotation estimation and its use in pose graph optimization", ICRA 2015:
// rotations first (relaxed, linear, then projected onto SO(2)), then the translations by linear
// least squares with those rotations fixed.

#include "slam/graph/pose_graph.h"

namespace slamrig::slam {

/// How many vertices an initialisation placed, and how many it could not reach and left at
/// their previous poses.
struct InitializationSummary {
  int vertices_set = 0;
  int vertices_kept = 0;
};

/// Re-composes the odometry chain: vertices in ascending id order, each placed at its
/// predecessor composed with an edge between the two (either direction; the first such edge).
/// The lowest id and fixed vertices keep their poses; where the chain has no edge between two
/// consecutive ids the previous relative placement of the pair is kept (counted in
/// vertices_kept).
InitializationSummary InitializeFromOdometry(PoseGraph* graph);

/// Chordal initialisation: (1) every rotation relaxed to an unconstrained 2D vector (c, s) with
/// R_j = R_i R_ij for each edge, weighted by the edge's marginal rotation information, solved by
/// sparse linear least squares with the anchors (PoseGraph::AnchorIndices()) held; (2) each
/// projected to SO(2), theta = atan2(s, c); (3) the translations by linear least squares on
/// R_i^T (t_j - t_i) = t_ij weighted by the information's translation block. Vertices not
/// connected to an anchor keep their poses. Exact on a graph without noise.
InitializationSummary InitializeChordal(PoseGraph* graph);

}  // namespace slamrig::slam
