#pragma once

#include <string>
#include <vector>

#include "slam/grid/occupancy_grid.h"
#include "slam/types/pose2.h"

namespace slamrig::slam {

/// How occupied cells are compared.
struct MapScoreOptions {
  int tolerance_cells = 1;  ///< a cell matches if the other map has one this close (Chebyshev)
  double occupied_probability = 0.65;  ///< a cell with a higher probability is occupied

  /// One message per broken rule (prefixed "map_score.").
  std::vector<std::string> Validate() const;
};

/// Agreement of the occupied cells of an estimated map with a ground-truth raster.
struct MapScore {
  int estimate_occupied = 0;
  int truth_occupied = 0;
  int estimate_matched = 0;  ///< estimate cells with a truth cell within the tolerance
  int truth_matched = 0;     ///< truth cells with an estimate cell within the tolerance
  double precision = 0.0;    ///< estimate_matched / estimate_occupied
  double recall = 0.0;       ///< truth_matched / truth_occupied
  double f1 = 0.0;
  /// Tolerant IoU, F1 / (2 - F1): equals |A and B| / |A or B| when precision and recall count the
  /// same cells.
  double iou = 0.0;
};

/// Scores `estimate` against `truth`. `truth_from_estimate` maps the estimate's frame into the
/// truth's (the ATE alignment); each estimate cell centre is moved by it to a truth cell.
MapScore ScoreMap(const OccupancyGrid& estimate, const Pose2& truth_from_estimate,
                  const OccupancyGrid& truth, const MapScoreOptions& options = {});

}  // namespace slamrig::slam
