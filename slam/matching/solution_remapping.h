#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "slam/types/pose2.h"

namespace slamrig::slam {

/// The translation directions a scan constrains: the eigen-decomposition of the information on
/// (x, y) of the robot with its yaw left free (the Schur complement of the yaw block of an
/// information matrix over x, y, yaw). Yaw itself is not judged: any wall seen at an angle fixes
/// it, while a corridor leaves its axis open.
struct MatchConstraints {
  Eigen::Vector2d eigenvalues = Eigen::Vector2d::Zero();       ///< ascending, 1 / m^2
  Eigen::Matrix2d eigenvectors = Eigen::Matrix2d::Identity();  ///< columns, robot frame
  /// Directions whose eigenvalue is below min_ratio times the largest: unconstrained.
  int WeakCount(double min_ratio) const;
};

/// Decomposes the translation part of `information` (over x, y, yaw, robot frame).
MatchConstraints DecomposeInformation(const Eigen::Matrix3d& information);

/// Unit surface normals of a scan's points (base frame, in beam order) from the chord between the
/// farthest beam-order neighbours within `neighbour_m` on either side; zero where a point has no
/// neighbour that near. The sign is arbitrary.
std::vector<Eigen::Vector2d> SurfaceNormals(std::span<const Eigen::Vector2d> points,
                                            double neighbour_m);

/// The point-to-line information of a scan's own geometry, in the base frame: sum over points of
/// J J^T with J = (n, p x n), n the unit normal (points with a zero normal are skipped). It is
/// what ICP's point-to-line problem would see (Zhang et al. 2016, Sec. VI): the walls of a
/// corridor all have normals across it, so its axis gets no information, whatever texture the
/// map has.
Eigen::Matrix3d ScanInformation(std::span<const Eigen::Vector2d> points,
                                std::span<const Eigen::Vector2d> normals);

/// The translation directions a scan's own geometry constrains: DecomposeInformation of its
/// ScanInformation, with SurfaceNormals from neighbours within 0.3 m (yaw left free). Points in
/// the robot's frame, in beam order.
MatchConstraints ScanGeometry(std::span<const Eigen::Vector2d> points);

/// The points whose beam meets its surface at an incidence angle (between the beam and the
/// normal) of at most `max_incidence_rad`, and their normals; points without a normal are kept.
/// A grazing beam's footprint stretches along the wall by 1 / cos(incidence): its end point
/// says little about where the robot is, and where the map was built from such beams, their
/// carving and hits leave a wall whose texture favours the poses it was seen from.
struct SelectedPoints {
  std::vector<Eigen::Vector2d> points;
  std::vector<Eigen::Vector2d> normals;
};
SelectedPoints DropGrazingPoints(std::span<const Eigen::Vector2d> points,
                                 std::span<const Eigen::Vector2d> normals,
                                 double max_incidence_rad);

/// Solution remapping (Zhang, Kaess, Singh, "On Degeneracy of Optimization-based State
/// Estimation Problems", ICRA 2016, Sec. V, Eq. 11): of the correction from `predicted` to
/// `matched`, keep the part along the well-constrained eigen-directions and drop the part along
/// the weak ones (eigenvalue < min_ratio times the largest), where the match only follows noise
/// or a biased map; along those the pose stays where the odometry put it. The yaw is the
/// match's. `constraints` are in the robot frame of `predicted`.
Pose2 RemapAlongWeakDirections(const Pose2& predicted, const Pose2& matched,
                               const MatchConstraints& constraints, double min_ratio);

}  // namespace slamrig::slam
