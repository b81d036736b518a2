#include "slam/matching/map_frame_drift.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "slam/matching/icp_matcher.h"
#include "slam/matching/icp_odometry.h"
#include "slam/matching/testing/segment_world.h"

namespace slamrig::slam {
namespace {

using testing::RangeFinderSpec;
using testing::SegmentWorld;

Eigen::Vector3d Gaussian3(const Eigen::Matrix3d& covariance, RandomEngine& rng) {
  const Eigen::Matrix3d l = covariance.llt().matrixL();
  return l * StandardNormal3(rng);
}

// A pose moved by an additive error in (x, y, yaw), IcpMatcher's parametrisation.
Pose2 Perturbed(const Pose2& pose, const Eigen::Vector3d& error) {
  return Pose2(pose.x() + error.x(), pose.y() + error.y(), pose.theta() + error.z());
}

Eigen::Vector3d PoseError(const Pose2& estimate, const Pose2& truth) {
  return {estimate.x() - truth.x(), estimate.y() - truth.y(),
          NormalizeAngle(estimate.theta() - truth.theta())};
}

// The shares of each keyframe in the map composed of `points` (each keyframe's points at its
// pose) at `robot`, as IcpOdometry computes them.
std::vector<Eigen::Matrix3d> Shares(const std::vector<std::vector<Eigen::Vector2d>>& points,
                                    const std::vector<Eigen::Vector2d>& scan, const IcpOptions& icp,
                                    const Pose2& robot) {
  const LocalMapPoints map = ComposeLocalMap(points, IcpOdometryOptions{}.local_map_voxel_m);
  const IcpMatcher matcher(icp, map.points);
  return FrameWeights(KeyframeInformations(map, matcher, static_cast<int>(points.size()), scan,
                                           robot.translation()));
}

struct DriftSample {
  Eigen::Matrix3d model_frame;                // the frame's covariance before the keyframe joins
  Eigen::Matrix3d model_drift;                // FrameDriftCovariance
  std::vector<Eigen::Vector3d> frame, drift;  // the matched pose's error before; its change
};

// K + 1 keyframes at `poses` (the last joins, the first leaves), each placed with an independent
// error of covariance `covariance`: a noise-free scan at the last pose matched against the map
// before and after, over `trials` draws.
DriftSample SimulateLocalMap(const SegmentWorld& world, const std::vector<Pose2>& poses,
                             const Eigen::Matrix3d& covariance, int trials) {
  RangeFinderSpec spec;
  spec.num_beams = 541;
  spec.angle_increment_rad *= 2.0;
  spec.range_max_m = 12.0;
  const IcpOdometryOptions options;
  std::vector<std::vector<Eigen::Vector2d>> base_points;
  for (const Pose2& pose : poses) {
    base_points.push_back(
        ScanToBasePoints(world.Scan(pose, Time(), spec, nullptr), options.points));
  }
  const Pose2& robot = poses.back();
  const std::size_t k = poses.size() - 1;

  // The model, from the true poses (the shares move little with errors of a few millimetres).
  std::vector<std::vector<Eigen::Vector2d>> true_points;
  for (std::size_t j = 0; j < poses.size(); ++j) {
    std::vector<Eigen::Vector2d> world_points;
    for (const Eigen::Vector2d& p : base_points[j]) world_points.push_back(poses[j] * p);
    true_points.push_back(std::move(world_points));
  }
  const std::vector<Eigen::Matrix3d> before =
      Shares(std::vector<std::vector<Eigen::Vector2d>>(true_points.begin(), true_points.end() - 1),
             true_points.back(), options.icp, robot);
  const std::vector<Eigen::Matrix3d> after =
      Shares(std::vector<std::vector<Eigen::Vector2d>>(true_points.begin() + 1, true_points.end()),
             true_points.back(), options.icp, robot);
  DriftSample sample;
  sample.model_frame.setZero();
  std::vector<KeyframeShare> shares(poses.size());
  for (std::size_t j = 0; j < poses.size(); ++j) {
    shares[j].covariance =
        CovarianceAtRobot(covariance, poses[j].translation(), robot.translation());
    if (j < k) shares[j].before = before[j];
    if (j > 0) shares[j].after = after[j - 1];
    sample.model_frame += shares[j].before * shares[j].covariance * shares[j].before.transpose();
  }
  sample.model_drift = FrameDriftCovariance(shares);

  // The matcher on maps of keyframes placed with errors.
  RandomEngine rng(41);
  const std::vector<Eigen::Vector2d>& scan = base_points.back();
  for (int t = 0; t < trials; ++t) {
    std::vector<std::vector<Eigen::Vector2d>> placed;
    for (std::size_t j = 0; j < poses.size(); ++j) {
      const Pose2 pose = Perturbed(poses[j], Gaussian3(covariance, rng));
      std::vector<Eigen::Vector2d> world_points;
      for (const Eigen::Vector2d& p : base_points[j]) world_points.push_back(pose * p);
      placed.push_back(std::move(world_points));
    }
    const auto match = [&](std::size_t first, std::size_t last) {
      const LocalMapPoints map = ComposeLocalMap(std::span(placed).subspan(first, last - first),
                                                 options.local_map_voxel_m);
      const std::optional<MatchResult> result =
          IcpMatcher(options.icp, map.points).Match(scan, robot);
      EXPECT_TRUE(result.has_value());
      return result ? PoseError(result->pose, robot) : Eigen::Vector3d::Zero().eval();
    };
    const Eigen::Vector3d frame_before = match(0, k), frame_after = match(1, k + 1);
    sample.frame.push_back(frame_before);
    sample.drift.push_back(frame_after - frame_before);
  }
  return sample;
}

// The mean over samples of e^T C^-1 e: 3 for a 3-dof Gaussian of covariance C.
double MeanNees(const std::vector<Eigen::Vector3d>& errors, const Eigen::Matrix3d& c) {
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(c);
  double sum = 0.0;
  for (const Eigen::Vector3d& e : errors) sum += e.dot(ldlt.solve(e));
  return sum / static_cast<double>(errors.size());
}

// Keyframes every 0.3 m along a corridor, the local map's ten and the one joining.
std::vector<Pose2> CorridorPoses(double x0, double y, int count) {
  std::vector<Pose2> poses;
  for (int j = 0; j < count; ++j) poses.emplace_back(x0 + 0.3 * j, y, 0.02 * std::sin(j));
  return poses;
}

constexpr int kTrials = 120;
// Bounds for the mean of 120 chi2_3 / 3 draws (sd 0.075 of the mean's 1) with room for the
// model's linearisation: a model off by a factor 1.5 in every direction falls outside.
constexpr double kLower = 0.75, kUpper = 1.3;

// In the office's south corridor (door jambs and a partition in view) the derived frame drift
// matches the spread of an ICP match against a local map whose keyframes were placed with
// independent errors; a drift of equal shares (1/K each, variance 2 C / K^2) or the old fitted
// share 0.45 (variance 0.2 C) does not. The shares come from the points the scan pairs with: from
// all the map's surviving points instead, the drift came out 46 times too small (the older
// keyframes' surviving points lie where the newest scan does not look). The frame's own spread
// (not the drift) is still underestimated in yaw by this model (0.9e-6 against 3.5e-6 rad^2),
// so it is not asserted.
TEST(MapFrameDriftTest, MatchesTheSpreadOfASimulatedLocalMapsFrameDrift) {
  const Eigen::Matrix3d c = Eigen::Vector3d(1e-4, 1e-4, 4e-6).asDiagonal();
  const DriftSample s =
      SimulateLocalMap(SegmentWorld::Office(), CorridorPoses(2.0, 1.6, 11), c, kTrials);
  EXPECT_GT(MeanNees(s.drift, s.model_drift) / 3.0, kLower);
  EXPECT_LT(MeanNees(s.drift, s.model_drift) / 3.0, kUpper);
  const double equal = MeanNees(s.drift, 2.0 / 100.0 * c) / 3.0;
  const double fitted = MeanNees(s.drift, 0.2 * c) / 3.0;
  EXPECT_TRUE(equal < kLower || equal > kUpper) << equal;
  EXPECT_TRUE(fitted < kLower || fitted > kUpper) << fitted;
}

// Along a corridor whose only feature along its axis is one far door jamb, the derived drift is
// large along the axis and small across it. Its spread is still 3 times the model's here (mean
// NEES / 3 = 3.2), so only the shape is asserted.
TEST(MapFrameDriftTest, DriftsAlongAWeaklyConstrainedCorridor) {
  const SegmentWorld corridor({{{-20.0, 1.0}, {20.0, 1.0}},
                               {{-20.0, -1.0}, {3.0, -1.0}},
                               {{4.0, -1.0}, {20.0, -1.0}},
                               {{3.0, -1.0}, {3.0, -2.0}},
                               {{4.0, -1.0}, {4.0, -2.0}}});
  const Eigen::Matrix3d c = Eigen::Vector3d(1e-4, 1e-4, 4e-6).asDiagonal();
  const DriftSample s = SimulateLocalMap(corridor, CorridorPoses(-6.0, 0.0, 11), c, kTrials);
  EXPECT_GT(s.model_drift(0, 0), 4.0 * s.model_drift(1, 1));
  double along = 0.0, across = 0.0;
  for (const Eigen::Vector3d& d : s.drift) {
    along += d.x() * d.x();
    across += d.y() * d.y();
  }
  EXPECT_GT(along, 4.0 * across);
}

// The shares of any keyframes sum to the identity; a keyframe without information has none.
TEST(MapFrameDriftTest, SharesSumToTheIdentity) {
  RandomEngine rng(7);
  for (int trial = 0; trial < 100; ++trial) {
    std::vector<Eigen::Matrix3d> informations;
    for (int j = 0; j < 1 + trial % 10; ++j) {
      Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
      for (int i = 0; i < 5; ++i) {
        const Eigen::Vector3d row = StandardNormal3(rng);
        h += row * row.transpose();
      }
      informations.push_back(h);
    }
    informations.push_back(Eigen::Matrix3d::Zero());
    Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
    const std::vector<Eigen::Matrix3d> weights = FrameWeights(informations);
    for (const Eigen::Matrix3d& w : weights) sum += w;
    EXPECT_LT((sum - Eigen::Matrix3d::Identity()).norm(), 1e-9) << trial;
    EXPECT_TRUE(weights.back().isZero()) << trial;
  }
  EXPECT_TRUE(FrameWeights(std::vector<Eigen::Matrix3d>(3, Eigen::Matrix3d::Zero()))[0].isZero());
}

// A keyframe's pose error moves a robot elsewhere as the rigid motion does: the robot's pose
// error is the one of a pose carried along with the keyframe's points.
TEST(MapFrameDriftTest, CovarianceAtRobotIsTheRigidMotionsLever) {
  RandomEngine rng(11);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Vector3d k = StandardNormal3(rng), r = StandardNormal3(rng);
    const Pose2 keyframe(3.0 * k.x(), 3.0 * k.y(), k.z()), robot(3.0 * r.x(), 3.0 * r.y(), r.z());
    const Eigen::Vector3d error = 1e-6 * StandardNormal3(rng);
    // The robot held fixed in the keyframe's frame while the keyframe moves by `error`.
    const Pose2 moved = Perturbed(keyframe, error) * keyframe.Between(robot);
    const Eigen::Vector3d robot_error = PoseError(moved, robot);
    // CovarianceAtRobot of e e^T is g e (g e)^T: its diagonal the squares of g e.
    const Eigen::Matrix3d c =
        CovarianceAtRobot(error * error.transpose(), keyframe.translation(), robot.translation());
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(std::sqrt(c(i, i)), std::abs(robot_error(i)), 1e-9) << trial << " " << i;
    }
  }
}

// A random information of a keyframe's points for a match (five random point-to-line rows).
Eigen::Matrix3d RandomInformation(RandomEngine& rng) {
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  for (int i = 0; i < 5; ++i) {
    const Eigen::Vector3d row = StandardNormal3(rng);
    h += row * row.transpose();
  }
  return h;
}

// The covariance of a sample's residual after its least-squares regression on `given`.
Eigen::Matrix3d ResidualCovariance(const std::vector<Eigen::Vector3d>& samples,
                                   const std::vector<Eigen::VectorXd>& given) {
  const auto count = static_cast<Eigen::Index>(samples.size());
  const Eigen::Index dimension = given.front().size();
  Eigen::MatrixXd x(count, dimension);
  Eigen::MatrixXd y(count, 3);
  for (Eigen::Index i = 0; i < count; ++i) {
    x.row(i) = given[static_cast<std::size_t>(i)].transpose();
    y.row(i) = samples[static_cast<std::size_t>(i)].transpose();
  }
  const Eigen::MatrixXd coefficients = x.colPivHouseholderQr().solve(y);
  const Eigen::MatrixXd residual = y - x * coefficients;
  return residual.transpose() * residual / static_cast<double>(count - dimension);
}

// A rigid motion's error (x, y, yaw) about the origin as the same motion's about `xy`, and back.
Eigen::Vector3d AboutPoint(const Eigen::Vector3d& e, const Eigen::Vector2d& xy) {
  return {e.x() - e.z() * xy.y(), e.y() + e.z() * xy.x(), e.z()};
}
Eigen::Vector3d AboutOrigin(const Eigen::Vector3d& e, const Eigen::Vector2d& xy) {
  return {e.x() + e.z() * xy.y(), e.y() - e.z() * xy.x(), e.z()};
}

// In a chain of keyframes, each placed at the frame its scan saw plus an independent match error
// (the linear model KeyframeErrors keeps), the move of the seen frame from one keyframe's scan to
// the next, given the frame before, is what is left of the move after regressing it on that frame
// over many Monte Carlo chains of the same shares.
TEST(MapFrameDriftTest, KeyframeErrorsStateTheSeenFramesMoveGivenTheFrameBefore) {
  constexpr int kMapSize = 4, kJoins = 10, kChains = 20000;
  RandomEngine rng(5);
  KeyframeErrors model;
  std::vector<int> map;  // ids in the map, oldest first
  // Each chain's keyframe errors (about the origin, by id) and the frame last seen.
  std::vector<std::vector<Eigen::Vector3d>> chains(kChains);
  std::vector<Eigen::Vector3d> seen(kChains, Eigen::Vector3d::Zero());
  int compared = 0;
  for (int id = 0; id < kJoins; ++id) {
    const Eigen::Vector2d robot(0.5 * id, 2.0 * std::sin(0.7 * id));
    std::vector<Eigen::Matrix3d> informations;
    for (std::size_t j = 0; j < map.size(); ++j) informations.push_back(RandomInformation(rng));
    const std::vector<Eigen::Matrix3d> weights = FrameWeights(informations);
    std::vector<KeyframeShareOf> shares;
    for (std::size_t j = 0; j < map.size(); ++j)
      shares.push_back({.id = map[j], .share = weights[j]});
    const Eigen::Matrix3d q = model.See(shares, robot);
    Eigen::Matrix3d r = Eigen::Vector3d(1e-4, 2e-4, 1e-5).asDiagonal();
    r *= 1.0 + std::abs(StandardNormal(rng));
    if (id == 0) r.setZero();
    model.Join(id, r, robot);

    const Eigen::Matrix3d l = r.llt().matrixL();
    std::vector<Eigen::Vector3d> moves;
    std::vector<Eigen::VectorXd> before;
    for (int c = 0; c < kChains; ++c) {
      std::vector<Eigen::Vector3d>& chain = chains[static_cast<std::size_t>(c)];
      Eigen::Vector3d frame = Eigen::Vector3d::Zero();  // at the robot
      for (std::size_t j = 0; j < map.size(); ++j) {
        frame += weights[j] * AboutPoint(chain[static_cast<std::size_t>(map[j])], robot);
      }
      const Eigen::Vector3d frame_origin = AboutOrigin(frame, robot);
      moves.push_back(AboutPoint(frame_origin - seen[static_cast<std::size_t>(c)], robot));
      before.push_back(seen[static_cast<std::size_t>(c)]);
      seen[static_cast<std::size_t>(c)] = frame_origin;
      const Eigen::Vector3d noise = StandardNormal3(rng);
      chain.push_back(AboutOrigin(frame + l * noise, robot));
    }
    map.push_back(id);
    if (static_cast<int>(map.size()) > kMapSize) map.erase(map.begin());
    if (id < 3) continue;  // the frame is still nearly the first keyframe's (exactly known)
    ++compared;
    const Eigen::Matrix3d sampled = ResidualCovariance(moves, before);
    EXPECT_LT((q - sampled).norm(), 0.05 * sampled.norm()) << id << "\n" << q << "\n" << sampled;
  }
  EXPECT_EQ(compared, kJoins - 3);
  EXPECT_EQ(model.size(), kMapSize + 1);  // the map before the last join and the new keyframe
}

}  // namespace
}  // namespace slamrig::slam
