#include "slam/matching/icp_odometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <tuple>
#include <utility>

#include "slam/matching/scan_points.h"
#include "slam/matching/solution_remapping.h"
#include "slam/matching/testing/segment_world.h"

namespace slamrig::slam {
namespace {

using testing::RangeFinderSpec;
using testing::SegmentWorld;

// True poses round the office's corridor loop: 0.2 m steps along each side, turns on the spot in
// 0.2 rad steps at the corners.
std::vector<Pose2> OfficeLoop() {
  const Eigen::Vector2d corners[] = {
      {1.5, 1.5}, {18.5, 1.5}, {18.5, 10.5}, {1.5, 10.5}, {1.5, 1.5}};
  std::vector<Pose2> poses;
  double yaw = 0.0;
  for (int side = 0; side < 4; ++side) {
    const Eigen::Vector2d a = corners[side], b = corners[side + 1];
    const int steps = static_cast<int>(std::round((b - a).norm() / 0.2));
    for (int s = 0; s < steps; ++s) {
      const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(s) / steps);
      poses.emplace_back(p.x(), p.y(), yaw);
    }
    for (int t = 0; t < 8; ++t) poses.emplace_back(b.x(), b.y(), yaw + 1.5708 * (t / 8.0));
    yaw += 1.5708;
  }
  return poses;
}

// Wheel odometry with a 3 % scale error, a yaw bias that grows with distance and white noise.
Pose2 NoisyIncrement(const Pose2& truth, RandomEngine& rng) {
  const double d = truth.translation().norm();
  const Eigen::Vector3d n = StandardNormal3(rng);
  return Pose2(1.03 * truth.x() + 0.003 * n.x(), truth.y() + 0.003 * n.y(),
               1.04 * truth.theta() + 0.02 * d + 0.002 * n.z());
}

double PositionRmse(const std::vector<Pose2>& estimate, const std::vector<Pose2>& truth) {
  double sum = 0.0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    sum += ((truth.front() * estimate[i]).translation() - truth[i].translation()).squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(truth.size()));
}

// A lap of the office with noisy odometry: scan-to-local-map ICP drifts far less than odometry.
TEST(IcpOdometryTest, DriftsMuchLessThanOdometryRoundTheOffice) {
  const SegmentWorld world = SegmentWorld::Office();
  const std::vector<Pose2> truth = OfficeLoop();
  RandomEngine rng(17);
  IcpOdometry icp{IcpOdometryOptions{}};
  std::vector<Pose2> estimate, odometry;
  Pose2 dead_reckoning;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    const Pose2 increment = k == 0 ? Pose2() : NoisyIncrement(truth[k - 1].Between(truth[k]), rng);
    dead_reckoning = dead_reckoning * increment;
    odometry.push_back(dead_reckoning);
    const IcpOdometryStep step =
        icp.Add(world.Scan(truth[k], Time(), RangeFinderSpec{}, &rng), increment);
    estimate.push_back(step.pose);
    EXPECT_EQ(step.pose, icp.pose());
  }
  const double icp_rmse = PositionRmse(estimate, truth), odom_rmse = PositionRmse(odometry, truth);
  EXPECT_GT(odom_rmse, 1.0);  // the odometry really drifts
  EXPECT_LT(icp_rmse, 0.1 * odom_rmse);
  EXPECT_LT(icp_rmse, 0.03);
  const IcpOdometryCounts& counts = icp.counts();
  EXPECT_EQ(counts.scans, static_cast<int>(truth.size()));
  EXPECT_GT(counts.matched, counts.scans * 9 / 10);
  EXPECT_LE(static_cast<int>(icp.local_map().size()), 10 * 1081);
}

// Odometry far worse than the noise model (a tenth of each step's length and a third of each
// turn, 1-sigma, beyond ICP's basin on the turns): the search before ICP, with its window from the
// noise it measures, keeps the route; ICP alone from the same prior loses it.
TEST(IcpOdometryTest, SearchesBeyondIcpsBasinWhenTheOdometryIsPoor) {
  const SegmentWorld world = SegmentWorld::Office();
  std::vector<Pose2> truth;
  const std::vector<Pose2> loop = OfficeLoop();
  // Half the lap: two sides and two corners.
  for (std::size_t k = 0; k < loop.size() / 2; k += 4) truth.push_back(loop[k]);
  auto run = [&](double sigmas) {
    RandomEngine rng(23);
    IcpOdometryOptions options;
    options.search.sigmas = sigmas;
    IcpOdometry icp(options);
    std::vector<Pose2> estimate;
    for (std::size_t k = 0; k < truth.size(); ++k) {
      Pose2 increment;
      if (k > 0) {
        const Pose2 step = truth[k - 1].Between(truth[k]);
        const Eigen::Vector3d n = StandardNormal3(rng);
        const double d = step.translation().norm();
        increment = step * Pose2(0.1 * d * n.x(), 0.1 * d * n.y(),
                                 (std::abs(step.theta()) / 3.0 + 0.02) * n.z());
      }
      estimate.push_back(
          icp.Add(world.Scan(truth[k], Time(), RangeFinderSpec{}, &rng), increment).pose);
    }
    return std::make_pair(PositionRmse(estimate, truth), icp.counts());
  };
  const auto [searched_rmse, searched] = run(3.0);
  const auto [icp_rmse, icp_only] = run(0.0);
  EXPECT_EQ(icp_only.searched, 0);
  EXPECT_GT(searched.searched, 0);
  EXPECT_GT(searched.search_chosen, 0);
  EXPECT_LT(searched_rmse, 0.05);
  EXPECT_GT(icp_rmse, 4.0 * searched_rmse);
}

// Turning on the spot in a room corner, 0.5 rad a scan, the odometry once reports 0.2 of a 0.9 rad
// turn (a wheel skids): the truth is 0.7 rad off the prior, far outside the noise model's window
// around the reported turn (+-0.13 rad). ICP from there finds a neighbouring minimum or fails;
// either way the prior is doubted and the search over the wide window finds the heading. With the
// wide window off, it is lost.
TEST(IcpOdometryTest, DoubtsAPriorThatUnderReportsATurn) {
  const SegmentWorld world = SegmentWorld::Office();
  auto run = [&](double wide_window_rad) {
    RandomEngine rng(29);
    IcpOdometryOptions options;
    options.search.wide_window_rad = wide_window_rad;
    IcpOdometry icp(options);
    const Pose2 start(3.0, 2.5, 0.0);
    IcpOdometryStep step;
    int widened = 0;
    for (int k = 0; k < 8; ++k) {
      const double reported = k == 0 ? 0.0 : (k == 4 ? 0.2 : 0.5);
      const double yaw = 0.5 * k + (k >= 4 ? 0.4 : 0.0);
      step = icp.Add(world.Scan(start * Pose2(0.0, 0.0, yaw), Time(), RangeFinderSpec{}, &rng),
                     Pose2(0.0, 0.0, reported));
      widened += step.search_widened ? 1 : 0;
    }
    return std::make_pair(std::abs(NormalizeAngle(step.pose.theta() - 3.9)), widened);
  };
  const auto [wide_error, wide_count] = run(1.0);
  const auto [narrow_error, narrow_count] = run(0.0);
  EXPECT_LT(wide_error, 0.01);
  EXPECT_GE(wide_count, 1);
  EXPECT_GT(narrow_error, 0.1);
}

// In a featureless corridor the match is degenerate along the axis: the pose follows odometry
// along it and the scans across it, and every such scan is counted.
TEST(IcpOdometryTest, FallsBackToOdometryAlongADegenerateCorridor) {
  const SegmentWorld corridor({{{-100.0, 1.0}, {100.0, 1.0}}, {{-100.0, -1.0}, {100.0, -1.0}}});
  RandomEngine rng(23);
  IcpOdometry icp{IcpOdometryOptions{}};
  Pose2 truth(-10.0, 0.2, 0.0), dead_reckoning;
  const Pose2 start = truth;
  for (int k = 0; k < 75; ++k) {
    const Pose2 true_increment = k == 0 ? Pose2() : Pose2(0.2, 0.0, 0.008 * std::sin(0.2 * k));
    truth = truth * true_increment;
    const Pose2 increment = k == 0 ? Pose2() : NoisyIncrement(true_increment, rng);
    dead_reckoning = dead_reckoning * increment;
    const IcpOdometryStep step =
        icp.Add(corridor.Scan(truth, Time(), RangeFinderSpec{}, &rng), increment);
    if (k > 0) {
      EXPECT_EQ(step.outcome, IcpOdometryOutcome::kDegenerate) << k;
    }
  }
  EXPECT_EQ(icp.counts().degenerate, 74);
  const Pose2 estimate = start * icp.pose(), odometry = start * dead_reckoning;
  // Across the corridor and in yaw: corrected. Along it: the odometry's 3 % overestimate stays.
  EXPECT_LT(std::abs(estimate.y() - truth.y()), 0.03);
  EXPECT_GT(std::abs(odometry.y() - truth.y()), 0.3);
  EXPECT_LT(std::abs(NormalizeAngle(estimate.theta() - truth.theta())), 0.01);
  // With the heading corrected, the distance along the axis is the odometry's: 3 % too long.
  EXPECT_NEAR(estimate.x() - start.x(), 1.03 * (truth.x() - start.x()), 0.05);
}

// A corridor closed by a wall 15 m ahead: the wall's few returns are the only surface across the
// axis, so the scan's own geometry sees the axis weakly (under the 15 % of weak_direction_ratio)
// while ICP's covariance is far from degenerate and its match does correct the odometry there.
SegmentWorld CorridorWithAFarEnd() {
  return SegmentWorld(
      {{{-100.0, -1.0}, {15.0, -1.0}}, {{-100.0, 1.0}, {15.0, 1.0}}, {{15.0, -1.0}, {15.0, 1.0}}});
}

// Where the scan sees a direction weakly, a match that moved the pose along it beyond the gate is
// taken for a slide and the odometry stands there. With the rule off the same match corrects the
// odometry (the far wall does hold it: what the rule trades for the wheels); within the gate, or
// where the scan sees every direction well (the office), the rule leaves the match as it is.
TEST(IcpOdometryTest, KeepsTheOdometryWhereAMatchMovesFarAlongAWeaklySeenDirection) {
  const SegmentWorld corridor = CorridorWithAFarEnd(), office = SegmentWorld::Office();
  const Pose2 truth(0.5, 0.0, 0.0);
  // The second scan's step with the rule on and off: the odometry off by `error_m` along x.
  auto steps = [&](const SegmentWorld& world, const Pose2& start, double error_m) {
    std::pair<IcpOdometryStep, IcpOdometryStep> on_off;
    for (const bool on : {true, false}) {
      IcpOdometryOptions options;
      options.weak_direction_ratio = on ? 0.15 : 0.0;
      IcpOdometry icp(options);
      icp.Add(world.Scan(start, Time(), RangeFinderSpec{}, nullptr), Pose2());
      const IcpOdometryStep step =
          icp.Add(world.Scan(start * truth, Time(), RangeFinderSpec{}, nullptr),
                  Pose2(truth.x() + error_m, 0.0, 0.0));
      (on ? on_off.first : on_off.second) = step;
    }
    return on_off;
  };
  const Pose2 origin;
  ASSERT_EQ(ScanGeometry(ScanToBasePoints(corridor.Scan(truth, Time(), RangeFinderSpec{}, nullptr),
                                          IcpOdometryOptions().points))
                .WeakCount(0.15),
            1);

  const auto [slid, matched] = steps(corridor, origin, 0.3);
  EXPECT_EQ(matched.outcome, IcpOdometryOutcome::kMatched);
  EXPECT_NEAR(matched.pose.x(), truth.x(), 0.03);
  EXPECT_EQ(slid.outcome, IcpOdometryOutcome::kDegenerate);
  EXPECT_NEAR(slid.pose.x(), truth.x() + 0.3, 0.01);
  EXPECT_NEAR(slid.pose.y(), 0.0, 0.02);  // across the corridor the match holds

  for (const auto& [world, start, error_m] :
       {std::tuple{&corridor, origin, 0.06}, std::tuple{&office, Pose2(5.0, 1.5, 0.0), 0.3}}) {
    const auto [on, off] = steps(*world, start, error_m);
    EXPECT_EQ(on.outcome, off.outcome) << error_m;
    EXPECT_EQ(on.pose, off.pose) << error_m;
  }
  EXPECT_NEAR(steps(office, Pose2(5.0, 1.5, 0.0), 0.3).first.pose.x(), truth.x(), 0.02);
}

// Wheels that turn the robot 0.02 rad per metre: a lap of the office fits the drift from the clear
// matches, and ten blind metres after it (no returns at all) drift by what is left of it; without
// the calibration, by all of it (0.2 rad). What is left: the zero-drift prior (prior_m, 5 m against
// the ~33 m of the lap) holds back about 13 % of the drift, the matches' noise a little more.
TEST(IcpOdometryTest, ABlindStretchDriftsByTheCalibratedOdometryOnly) {
  const SegmentWorld office = SegmentWorld::Office(), blind({});
  std::vector<Pose2> truth = OfficeLoop();
  truth.resize(180);
  for (int k = 0; k < 50; ++k) truth.push_back(truth.back() * Pose2(0.2, 0.0, 0.0));
  double yaw_error[2] = {0.0, 0.0};
  for (const bool calibrate : {false, true}) {
    IcpOdometryOptions options;
    options.calibration.enabled = calibrate;
    IcpOdometry icp(options);
    RandomEngine rng(31);
    for (std::size_t k = 0; k < truth.size(); ++k) {
      const Pose2 step = k == 0 ? Pose2() : truth[k - 1].Between(truth[k]);
      const Eigen::Vector3d n = StandardNormal3(rng);
      const Pose2 increment(step.x() + 0.002 * n.x(), step.y() + 0.002 * n.y(),
                            step.theta() + 0.02 * step.translation().norm() + 0.001 * n.z());
      const SegmentWorld& world = k < 180 ? office : blind;
      const IcpOdometryStep placed =
          icp.Add(world.Scan(truth[k], Time(), RangeFinderSpec{}, &rng), increment);
      if (k >= 180) {
        ASSERT_EQ(placed.outcome, IcpOdometryOutcome::kNoPoints) << k;
      }
    }
    const Pose2 estimate = truth.front() * icp.pose();
    yaw_error[calibrate] = std::abs(NormalizeAngle(estimate.theta() - truth.back().theta()));
    if (calibrate) {
      EXPECT_NEAR(icp.calibration().applied_drift_rad_per_m(), -0.02, 0.006);
    }
  }
  EXPECT_GT(yaw_error[0], 0.15);
  EXPECT_LT(yaw_error[1], 0.3 * yaw_error[0]);
}

// A scan the match cannot place (the lidar blocked by someone standing close in front) is placed
// by the odometry alone, here 0.25 rad short of a turn on the spot. It stays out of the local map,
// and the next scan's window covers the blind step's noise as well as its own, so that the step's
// error is searched for against the map the last match placed. Without: the blind scan joins the
// map and the next window is its own step's.
TEST(IcpOdometryTest, AFailedScanStaysOutOfTheMapAndWidensTheNextWindow) {
  const SegmentWorld office = SegmentWorld::Office();
  const Pose2 start(1.5, 1.5, 0.0);        // the office's south-west corner
  auto blocked = [](const Pose2& robot) {  // a person-sized box 0.5 m in front
    SegmentWorld world({});
    const Eigen::Vector2d c = robot * Eigen::Vector2d(0.65, 0.0);
    world.AddBox(c.x() - 0.15, c.y() - 0.15, c.x() + 0.15, c.y() + 0.15);
    return world;
  };
  struct Outcome {
    bool map_kept;
    IcpOdometryStep blind, next;
    double yaw_error;
  };
  auto run = [&](int blind_scans) {
    IcpOdometryOptions options;
    options.search.blind_scans = blind_scans;
    IcpOdometry icp(options);
    RandomEngine rng(41);
    const Pose2 turn(0.0, 0.0, 0.3);
    Pose2 truth = start;
    icp.Add(office.Scan(truth, Time(), RangeFinderSpec{}, &rng), Pose2());
    for (int k = 0; k < 3; ++k) {
      truth = truth * turn;
      icp.Add(office.Scan(truth, Time(), RangeFinderSpec{}, &rng), turn);
    }
    const std::size_t map_size = icp.local_map().size();
    truth = truth * Pose2(0.0, 0.0, 0.55);  // the wheels report 0.3
    Outcome outcome;
    outcome.blind = icp.Add(blocked(truth).Scan(truth, Time(), RangeFinderSpec{}, &rng), turn);
    outcome.map_kept = icp.local_map().size() == map_size;
    truth = truth * turn;
    outcome.next = icp.Add(office.Scan(truth, Time(), RangeFinderSpec{}, &rng), turn);
    outcome.yaw_error =
        std::abs(NormalizeAngle((start.Inverse() * truth).theta() - outcome.next.pose.theta()));
    return outcome;
  };
  const Outcome on = run(1), off = run(0);
  for (const Outcome* o : {&on, &off}) {
    ASSERT_EQ(o->blind.outcome, IcpOdometryOutcome::kMatchFailed);
    ASSERT_EQ(o->next.outcome, IcpOdometryOutcome::kMatched);
  }
  EXPECT_TRUE(on.map_kept);
  EXPECT_FALSE(on.blind.keyframe);
  EXPECT_FALSE(off.map_kept);
  // The next window: the noise model (sigma_yaw_per_rad 0.2 of each turn, plus the floor) at 3
  // sigma over the blind turn and its own, against over its own.
  const IcpOdometryOptions defaults;
  EXPECT_NEAR(on.next.window.y(), 3.0 * defaults.StretchSigmas(0.0, 0.6).y(), 1e-12);
  EXPECT_NEAR(off.next.window.y(), 3.0 * defaults.StretchSigmas(0.0, 0.3).y(), 1e-12);
  EXPECT_LT(on.yaw_error, 0.01);
}

// While the lidar stays blocked the blind stretch grows up to search.blind_scans scans, or less
// where its window would pass max_window_m; then the wheels' placement is kept: the blind scan
// joins the map and the stretch starts again.
TEST(IcpOdometryTest, ABlindStretchEndsAfterItsScansOrWhereItsWindowPassesTheMaximum) {
  SegmentWorld hall({});  // walls far from anything the blocked scans see
  hall.AddBox(-20.0, -20.0, 20.0, 20.0);
  auto joined_at = [&](int blind_scans) {
    IcpOdometryOptions options;
    options.search.blind_scans = blind_scans;
    IcpOdometry icp(options);
    RandomEngine rng(43);
    Pose2 truth(-6.0, 0.0, 0.0);
    icp.Add(hall.Scan(truth, Time(), RangeFinderSpec{}, &rng), Pose2());
    const Pose2 step(0.5, 0.0, 0.0);
    for (int k = 1; k <= 40; ++k) {
      truth = truth * step;
      SegmentWorld blocked({});
      blocked.AddBox(truth.x() + 0.5, truth.y() - 0.15, truth.x() + 0.8, truth.y() + 0.15);
      const IcpOdometryStep placed =
          icp.Add(blocked.Scan(truth, Time(), RangeFinderSpec{}, &rng), step);
      EXPECT_EQ(placed.outcome, IcpOdometryOutcome::kMatchFailed) << k;
      if (placed.keyframe) return k;
    }
    return 0;
  };
  EXPECT_EQ(joined_at(0), 1);
  EXPECT_EQ(joined_at(1), 2);
  EXPECT_EQ(joined_at(5), 6);
  // 3 sigma of 0.05 m per m plus 0.005 m reaches 2 m after 13.2 m: the 27th step of 0.5 m.
  EXPECT_EQ(joined_at(100), 27);
}

// Same scans and increments, same bits.
TEST(IcpOdometryTest, SameInputSameBits) {
  const SegmentWorld world = SegmentWorld::Office();
  const std::vector<Pose2> truth = OfficeLoop();
  std::vector<LaserScan> scans;
  std::vector<Pose2> increments;
  RandomEngine rng(29);
  for (std::size_t k = 0; k < 40; ++k) {
    scans.push_back(world.Scan(truth[k], Time(), RangeFinderSpec{}, &rng));
    increments.push_back(k == 0 ? Pose2() : NoisyIncrement(truth[k - 1].Between(truth[k]), rng));
  }
  IcpOdometry a{IcpOdometryOptions{}}, b{IcpOdometryOptions{}};
  for (std::size_t k = 0; k < scans.size(); ++k) {
    const IcpOdometryStep sa = a.Add(scans[k], increments[k]);
    const IcpOdometryStep sb = b.Add(scans[k], increments[k]);
    ASSERT_EQ(sa.pose, sb.pose) << k;
    ASSERT_EQ(sa.covariance, sb.covariance) << k;
  }
}

// A scan without a single return keeps the odometry prior and is counted.
TEST(IcpOdometryTest, ScanWithoutPointsKeepsThePrior) {
  const SegmentWorld world = SegmentWorld::Office();
  IcpOdometry icp{IcpOdometryOptions{}};
  icp.Add(world.Scan(Pose2(5.0, 1.5, 0.0), Time(), RangeFinderSpec{}, nullptr), Pose2());
  const SegmentWorld empty({});
  const Pose2 increment(0.1, 0.0, 0.01);
  const IcpOdometryStep step =
      icp.Add(empty.Scan(Pose2(5.1, 1.5, 0.01), Time(), RangeFinderSpec{}, nullptr), increment);
  EXPECT_EQ(step.outcome, IcpOdometryOutcome::kNoPoints);
  EXPECT_EQ(step.pose, increment);
  EXPECT_EQ(icp.counts().no_points, 1);
  EXPECT_GT(step.covariance(0, 0), 0.0);
}

TEST(IcpOdometryOptionsTest, ValidateIncludesTheNestedOptions) {
  IcpOdometryOptions options;
  EXPECT_TRUE(options.Validate().empty());
  options.local_map_keyframes = 0;
  options.icp.trim_fraction = 2.0;
  const std::vector<std::string> errors = options.Validate();
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0], "local_map_keyframes = 0; must be >= 1");
  EXPECT_EQ(errors[1], "icp.trim_fraction = 2; must be in (0, 1]");
}

}  // namespace
}  // namespace slamrig::slam
