#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "slam/eval/error_stats.h"
#include "slam/types/pose2.h"
#include "slam/types/trajectory.h"

namespace slamrig::slam {

/// One relation of the Kümmerle et al. 2009 metric: the reference motion from the pose at `t1`
/// to the pose at `t2`, expressed in the frame of the first (t1_from_t2).
struct Relation {
  Time t1;
  Time t2;
  Pose2 relative;
};

/// Which pose pairs a generated relations file contains.
struct RelationGeneratorOptions {
  int consecutive_step = 1;              ///< (i, i + step) for every i; 0 = none
  std::vector<double> path_distances_m;  ///< (i, first j with path length >= d) for each d
  int num_random_pairs = 0;              ///< random (i, j) pairs over the whole run
  std::uint64_t seed = 1;

  /// One message per broken rule (prefixed "relations.").
  std::vector<std::string> Validate() const;
};

/// Relations from any reference trajectory (poses must be unique in time for a pair to be found
/// again by time; pairs with equal stamps are skipped).
std::vector<Relation> GenerateRelations(const Trajectory& reference,
                                        const RelationGeneratorOptions& options);

/// Freiburg relations text: one `t1 t2 x y z roll pitch yaw` line per relation (seconds, metres,
/// radians; z, roll and pitch 0).
std::string FormatRelations(const std::vector<Relation>& relations);
/// Parses FormatRelations output or a Freiburg `.relations` file; throws ParseError naming the
/// file, line and field.
std::vector<Relation> ParseRelations(const std::string& text, const std::string& source_name);

/// The metric (Kümmerle et al., "On measuring the accuracy of SLAM algorithms", Autonomous Robots
/// 27(4), 2009, Eqs. 1-2): for each relation, error = relative^-1 * (est(t1)^-1 est(t2)); mean and
/// standard deviation of the absolute and squared translational and rotational errors.
struct RelationsResult {
  int used = 0;                  ///< relations whose two times the estimate covers
  int skipped = 0;               ///< relations outside the estimate
  ErrorStats translation_m;      ///< |t| per relation
  ErrorStats translation_sq_m2;  ///< |t|^2 per relation
  ErrorStats rotation_rad;       ///< |theta| per relation
  ErrorStats rotation_sq_rad2;   ///< theta^2 per relation
};

/// Evaluates `estimate` on `relations`; poses are taken at exact stamps or interpolated.
RelationsResult EvaluateRelations(const Trajectory& estimate,
                                  const std::vector<Relation>& relations);

}  // namespace slamrig::slam
