// The drift of a local map's frame as keyframes join and leave it. A scan matched against a map
// built from K keyframes, each placed with its own error, lands where the map's points put it: to
// first order at the information-weighted mean of the keyframes' errors, weighted by what each
// keyframe's surviving points tell a point-to-line match (Censi, "An accurate closed-form
// estimate of ICP's covariance", ICRA 2007: the pose's sensitivity to the reference points is
// (J^T J)^-1 J^T, so a rigid shift of one keyframe's points moves the pose by
// (sum_i H_i)^-1 H_j times that shift). When the map's composition changes from weights W_j to
// W'_j the frame moves by sum_j (W'_j - W_j) e_j; as sum_j W_j = sum_j W'_j = I, a shift common
// to all keyframes cancels and only their errors against one another remain.
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "slam/matching/icp_matcher.h"

namespace slamrig::slam {

/// A local map's points and the keyframe each came from.
struct LocalMapPoints {
  std::vector<Eigen::Vector2d> points;
  std::vector<int> keyframe;  ///< index into the keyframes the map was composed of
};

/// The points of `keyframes` (oldest first, one fixed frame), newest first and thinned to the first
/// (so the newest) point per `voxel_m` square (0: none), as IcpOdometry's local map.
LocalMapPoints ComposeLocalMap(std::span<const std::vector<Eigen::Vector2d>> keyframes,
                               double voxel_m);

/// The point-to-line information (PointToLineInformation) each of `keyframes` keyframes gives a
/// match of `scan` (points in the map's frame, at the pose at `robot_xy`) by `matcher`, built on
/// `map`'s points: the map points that are the nearest neighbour of a scan point within the
/// matcher's correspondence distance, once per pairing, as the match's sum runs, with the
/// matcher's normals (all zero for point-to-point ICP). What the scan does not see carries no
/// share.
std::vector<Eigen::Matrix3d> KeyframeInformations(const LocalMapPoints& map,
                                                  const IcpMatcher& matcher, int keyframes,
                                                  std::span<const Eigen::Vector2d> scan,
                                                  const Eigen::Vector2d& robot_xy);

/// The information a point-to-line match of a pose at `robot_xy` gets from reference `points`
/// with unit `normals` ((0, 0): none, skipped): sum of J^T J over the points, J = (n^T,
/// n . perp(p - robot_xy)), in the (x, y, yaw) of that pose (IcpMatcher's parametrisation).
Eigen::Matrix3d PointToLineInformation(std::span<const Eigen::Vector2d> points,
                                       std::span<const Eigen::Vector2d> normals,
                                       const Eigen::Vector2d& robot_xy);

/// The share of each keyframe in the map's frame: W_j = H^-1 H_j with H = sum_j H_j, the
/// eigenvalues of H below 1e-9 of its largest raised to that floor (IcpMatcher's rule). Sums to
/// the identity where H is regular; all zero where H is.
std::vector<Eigen::Matrix3d> FrameWeights(std::span<const Eigen::Matrix3d> informations);

/// A keyframe pose's error covariance `covariance` (x, y, yaw at the keyframe's position
/// `keyframe_xy`) as the error it causes in a pose at `robot_xy`: a yaw error about the keyframe
/// moves points at the robot by yaw times the lever.
Eigen::Matrix3d CovarianceAtRobot(const Eigen::Matrix3d& covariance,
                                  const Eigen::Vector2d& keyframe_xy,
                                  const Eigen::Vector2d& robot_xy);

/// One keyframe's part in a change of the map: its share before and after (zero where it was
/// not or is no longer in the map) and its error covariance at the robot.
struct KeyframeShare {
  Eigen::Matrix3d before = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d after = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
};

/// The covariance of the frame's move, sum_j (W'_j - W_j) C_j (W'_j - W_j)^T, with the
/// keyframes' errors independent (as when each was placed by an outside reference; a map built
/// by its own matches has them correlated: KeyframeErrors).
Eigen::Matrix3d FrameDriftCovariance(std::span<const KeyframeShare> shares);

/// One keyframe's share in the map's frame as a scan sees it (FrameWeights, at the robot).
struct KeyframeShareOf {
  int id = 0;
  Eigen::Matrix3d share = Eigen::Matrix3d::Zero();
};

/// The errors of the local map's keyframes, jointly, and the frame the matches see. A scan
/// matched against the map lands at its frame as that scan sees it, G = sum_j W_j e_j with the
/// shares of the points it pairs with; a keyframe placed by that match has the error G plus the
/// match's own. Keyframes placed against nearly the same map share most of their error, and
/// the frame moves by the change of the shares, where a shift common to all cancels. The shares
/// that matter are those of the scans that use the map: the joining scan sees almost nothing but
/// its own points (the map keeps the newest point of each voxel), the next ones see the older
/// keyframes too. This keeps the joint covariance of the errors of the keyframes in the map (each
/// a rigid motion about the matcher frame's origin) and states each move of the seen frame given
/// the frame before, the part a filter that tracks the frame takes as new noise (the conditional
/// covariance of a joint Gaussian).
class KeyframeErrors {
 public:
  /// A scan at `robot_xy` sees the frame through `shares` (the keyframes in the map). Returns the
  /// covariance of that frame's move since the last scan that saw it (x, y, yaw at the robot),
  /// given the frame then; keyframes not in `shares` have left the map and are marginalised out.
  /// A keyframe never joined is taken as the frame's definition (no error).
  Eigen::Matrix3d See(std::span<const KeyframeShareOf> shares, const Eigen::Vector2d& robot_xy);
  /// Keyframe `id` joins, placed by the last scan that saw the frame with a match error of
  /// covariance `r` (x, y, yaw at `robot_xy`): its error is that frame's plus its own. The first
  /// keyframe defines the frame: `r` zero.
  void Join(int id, const Eigen::Matrix3d& r, const Eigen::Vector2d& robot_xy);

  int size() const { return static_cast<int>(ids_.size()); }

 private:
  std::vector<int> ids_;        // the keyframes in the map, in the order of covariance_'s blocks
  Eigen::MatrixXd covariance_;  // 3 ids_.size() square: their errors about the origin
  Eigen::MatrixXd seen_;        // 3 x 3 ids_.size(): the last seen frame, about the origin
};

}  // namespace slamrig::slam
