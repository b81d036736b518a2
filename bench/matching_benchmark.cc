// Scan matcher speed (issue 9): the correlative matcher's loop-closure search (a window of +-7 m
// and +-pi at 5 cm, a 1081-beam Hokuyo scan decimated to a few hundred points) and ICP, on the
// SegmentWorld office mapped from scans round its corridor loop (built once, outside the timing);
// then both on the real intel-corrected log (skipped with a message when the dataset is absent):
// the loop-closure search on the map of its corrected poses, the pf relocaliser's whole-map search
// at full and coarser resolutions, and IcpOdometry over the whole log.
//
//   build/bench/matching_benchmark --benchmark_repetitions=5
//   --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <numbers>

#include "slam/io/carmen_reader.h"
#include "slam/io/dataset.h"
#include "slam/matching/correlative_matcher.h"
#include "slam/matching/icp_matcher.h"
#include "slam/matching/icp_odometry.h"
#include "slam/matching/scan_points.h"
#include "slam/matching/testing/segment_world.h"
#include "slam/odometry/scan_sync.h"
#include "slam/pf/particle_filter_options.h"

namespace slamrig::slam {
namespace {

using testing::RangeFinderSpec;
using testing::SegmentWorld;

struct Office {
  SegmentWorld world = SegmentWorld::Office();
  OccupancyGrid grid{OccupancyGridOptions{}};
};

const Office& TheOffice() {
  static const Office* office = [] {
    auto* o = new Office;
    RandomEngine rng(1);
    auto insert = [&](double x, double y, double yaw) {
      const Pose2 pose(x, y, yaw);
      o->grid.InsertScan(o->world.Scan(pose, Time(), RangeFinderSpec{}, &rng), pose);
    };
    for (double x = 1.5; x <= 18.5; x += 0.5) insert(x, 1.5, 0.0);
    for (double y = 1.5; y <= 10.5; y += 0.5) insert(18.5, y, 1.57);
    for (double x = 18.5; x >= 1.5; x -= 0.5) insert(x, 10.5, 3.14);
    for (double y = 10.5; y >= 1.5; y -= 0.5) insert(1.5, y, -1.57);
    return o;
  }();
  return *office;
}

const Pose2 kTruth(9.2, 1.7, 0.4);

std::vector<Eigen::Vector2d> DecimatedScan(double voxel_m) {
  RandomEngine rng(2);
  ScanPointsOptions points;
  points.voxel_size_m = voxel_m;
  return ScanToBasePoints(TheOffice().world.Scan(kTruth, Time(), RangeFinderSpec{}, &rng), points);
}

// Args: window half-width in cm, angular window in mrad, voxel size in mm, depth.
void BM_CorrelativeSearch(benchmark::State& state) {
  CorrelativeMatcherOptions options;
  options.linear_window_m = static_cast<double>(state.range(0)) / 100.0;
  options.angular_window_rad =
      std::min(static_cast<double>(state.range(1)) / 1000.0, std::numbers::pi);
  options.branch_and_bound_depth = static_cast<int>(state.range(3));
  options.min_score = 0.4;
  const CorrelativeMatcher matcher(options, TheOffice().grid);
  const std::vector<Eigen::Vector2d> scan =
      DecimatedScan(static_cast<double>(state.range(2)) / 1000.0);
  const Pose2 initial(kTruth.x() + 0.8 * options.linear_window_m,
                      kTruth.y() - 0.3 * options.linear_window_m,
                      kTruth.theta() + 0.8 * options.angular_window_rad);
  int nodes = 0;
  double error_m = 0.0;
  for (auto _ : state) {
    const std::optional<MatchResult> m = matcher.Match(scan, initial);
    if (!m) {
      state.SkipWithError("no match");
      break;
    }
    nodes = m->iterations;
    error_m = (m->pose.translation() - kTruth.translation()).norm();
    benchmark::DoNotOptimize(m->pose);
  }
  state.counters["points"] = static_cast<double>(scan.size());
  state.counters["nodes"] = nodes;
  state.counters["error_m"] = error_m;
}
BENCHMARK(BM_CorrelativeSearch)
    ->Args({700, 3142, 100, 7})  // loop closure: +-7 m, +-pi
    ->Args({700, 3142, 60, 7})
    ->Args({300, 3142, 100, 7})
    ->Args({100, 500, 100, 5})  // local: +-1 m, +-0.5 rad
    ->Unit(benchmark::kMillisecond);

void BM_CorrelativePrecompute(benchmark::State& state) {
  CorrelativeMatcherOptions options;
  options.branch_and_bound_depth = static_cast<int>(state.range(0));
  for (auto _ : state) {
    const CorrelativeMatcher matcher(options, TheOffice().grid);
    benchmark::DoNotOptimize(&matcher);
  }
  state.counters["cells"] =
      static_cast<double>(TheOffice().grid.width()) * TheOffice().grid.height();
}
BENCHMARK(BM_CorrelativePrecompute)->Arg(7)->Unit(benchmark::kMillisecond);

// Scan-to-scan ICP from a guess 5 cm and 3 degrees off. Arg: 0 point-to-point, 1 point-to-line.
void BM_IcpScanToScan(benchmark::State& state) {
  IcpOptions options;
  options.metric = state.range(0) == 0 ? IcpMetric::kPointToPoint : IcpMetric::kPointToLine;
  const std::vector<Eigen::Vector2d> ref = DecimatedScan(0.05);
  RandomEngine rng(3);
  ScanPointsOptions points;
  points.voxel_size_m = 0.05;
  const Pose2 offset(0.04, -0.03, 0.05);
  const std::vector<Eigen::Vector2d> src = ScanToBasePoints(
      TheOffice().world.Scan(kTruth * offset, Time(), RangeFinderSpec{}, &rng), points);
  int iterations = 0;
  for (auto _ : state) {
    const IcpMatcher matcher(options, ref);  // the k-d tree and normals are part of the cost
    const std::optional<MatchResult> m = matcher.Match(src, Pose2());
    iterations = m ? m->iterations : -1;
    benchmark::DoNotOptimize(m);
  }
  state.counters["points"] = static_cast<double>(src.size());
  state.counters["iterations"] = iterations;
}
BENCHMARK(BM_IcpScanToScan)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

struct Intel {
  std::vector<CarmenScan> scans;   // corrected poses: the reference
  std::vector<SyncedScan> synced;  // with the recovered raw odometry
  OccupancyGrid grid{OccupancyGridOptions{}};
};

// The intel-corrected log, read once; nullptr when the dataset is missing.
const Intel* TheIntel() {
  static const Intel* intel = []() -> Intel* {
    const char* env = std::getenv("SLAMRIG_DATA_DIR");
    const std::filesystem::path dir =
        env != nullptr ? std::filesystem::path(env)
                       : std::filesystem::path(SLAMRIG_SOURCE_DIR) / ".." / "shared" / "datasets";
    const std::filesystem::path path = dir / "carmen_corrected" / "intel-corrected.log.gz";
    if (!std::filesystem::exists(path)) return nullptr;
    const CarmenLog log = ReadCarmenLog(path.string());
    auto* i = new Intel;
    i->scans = log.scans;
    i->synced = SyncToScans(CarmenToDataset(log).records, ScanSyncOptions{}).scans;
    for (const CarmenScan& s : log.scans) i->grid.InsertScan(s.scan, s.logged_pose);
    return i;
  }();
  return intel;
}

// Loop-closure search on the intel map: scan 400 from 5 m and 1.5 rad off, +-7 m, +-pi.
// Args: voxel size in mm, branch-and-bound depth.
void BM_CorrelativeSearchIntel(benchmark::State& state) {
  const Intel* intel = TheIntel();
  if (intel == nullptr) {
    state.SkipWithError("intel-corrected.log.gz not found (set SLAMRIG_DATA_DIR)");
    return;
  }
  CorrelativeMatcherOptions options;
  options.min_score = 0.4;
  options.branch_and_bound_depth = static_cast<int>(state.range(1));
  const CorrelativeMatcher matcher(options, intel->grid);
  ScanPointsOptions points;
  points.voxel_size_m = static_cast<double>(state.range(0)) / 1000.0;
  const CarmenScan& scan = intel->scans[400];
  const std::vector<Eigen::Vector2d> cloud = ScanToBasePoints(scan.scan, points);
  const Pose2 truth = scan.logged_pose;
  const Pose2 initial(truth.x() + 4.0, truth.y() - 3.0, truth.theta() + 1.5);
  double error_m = -1.0;
  int nodes = 0;
  for (auto _ : state) {
    const std::optional<MatchResult> m = matcher.Match(cloud, initial);
    error_m = m ? (m->pose.translation() - truth.translation()).norm() : -1.0;
    nodes = m ? m->iterations : -1;
    benchmark::DoNotOptimize(m);
  }
  state.counters["points"] = static_cast<double>(cloud.size());
  state.counters["error_m"] = error_m;
  state.counters["yaw_step_mrad"] = 1000.0 * matcher.AngularStep(cloud);
  state.counters["nodes"] = nodes;
}
BENCHMARK(BM_CorrelativeSearchIntel)
    ->Args({50, 7})
    ->Args({100, 7})
    ->Args({100, 6})
    ->Args({100, 8})
    ->Args({100, 9})
    ->Unit(benchmark::kMillisecond);

// The pf relocaliser's global search (slam/pf/particle_filter.cc, GlobalMatches) with its default
// RelocalisationOptions on the intel map: the whole map (up to search_window_m about its centre),
// every heading, the global_candidates best distinct places, scan 400's points within
// search_max_range_m at the pf's 5 cm voxels, min_score 0. Arg: the decimation of the raster
// (relocalisation.search_resolution_m / the map's 0.05 m; 4 is the default's 0.2 m). At 1, each
// lost update of a default pf run cost three such searches.
void BM_RelocaliserSearchIntel(benchmark::State& state) {
  const Intel* intel = TheIntel();
  if (intel == nullptr) {
    state.SkipWithError("intel-corrected.log.gz not found (set SLAMRIG_DATA_DIR)");
    return;
  }
  const RelocalisationOptions relocalisation;
  const int decimation = static_cast<int>(state.range(0));
  const Eigen::Vector2d extent =
      Eigen::Vector2d(intel->grid.width(), intel->grid.height()) * intel->grid.resolution();
  const Eigen::Vector2d centre = intel->grid.origin() + 0.5 * extent;
  CorrelativeMatcherOptions options;
  options.linear_window_m = std::min(relocalisation.search_window_m, 0.5 * extent.maxCoeff());
  options.angular_window_rad = std::numbers::pi;
  options.min_score = 0.0;
  const CorrelativeMatcher matcher(options, intel->grid, decimation);
  ScanPointsOptions points;
  const CarmenScan& scan = intel->scans[400];
  std::vector<Eigen::Vector2d> cloud;
  for (const Eigen::Vector2d& p : ScanToBasePoints(scan.scan, points)) {
    if (p.norm() <= relocalisation.search_max_range_m) cloud.push_back(p);
  }
  const Pose2 truth = scan.logged_pose;
  double error_m = -1.0;
  int nodes = 0;
  for (auto _ : state) {
    const std::vector<MatchResult> places = matcher.MatchDistinct(
        cloud, Pose2(centre.x(), centre.y(), 0.0), relocalisation.global_candidates,
        relocalisation.distinct_radius_m, relocalisation.distinct_angle_rad);
    error_m =
        places.empty() ? -1.0 : (places.front().pose.translation() - truth.translation()).norm();
    nodes = places.empty() ? -1 : places.front().iterations;
    benchmark::DoNotOptimize(places);
  }
  state.counters["points"] = static_cast<double>(cloud.size());
  state.counters["error_m"] = error_m;  // of the best place, before the local match refines it
  state.counters["yaw_step_mrad"] = 1000.0 * matcher.AngularStep(cloud);
  state.counters["nodes"] = nodes;  // of the three searches together
}
BENCHMARK(BM_RelocaliserSearchIntel)->Arg(1)->Arg(2)->Arg(4)->Unit(benchmark::kMillisecond);

// IcpOdometry over all intel scans with the recovered raw odometry as the prior. Counters: the
// position RMSE against the corrected poses (both anchored at the first scan) of ICP odometry and
// of dead reckoning.
void BM_IcpOdometryIntel(benchmark::State& state) {
  const Intel* intel = TheIntel();
  if (intel == nullptr) {
    state.SkipWithError("intel-corrected.log.gz not found (set SLAMRIG_DATA_DIR)");
    return;
  }
  if (intel->synced.size() != intel->scans.size()) {
    state.SkipWithError("synchronised scans do not pair with the log's scans");
    return;
  }
  std::vector<Pose2> estimate(intel->synced.size());
  IcpOdometryCounts counts;
  for (auto _ : state) {
    IcpOdometry icp{IcpOdometryOptions{}};
    for (std::size_t k = 0; k < intel->synced.size(); ++k) {
      estimate[k] = icp.Add(intel->synced[k].scan, intel->synced[k].increment).pose;
    }
    counts = icp.counts();
  }
  const std::vector<Pose2> dead_reckoning = DeadReckoningPoses(intel->synced);
  const Pose2 anchor = intel->scans.front().logged_pose;
  auto rmse = [&](const std::vector<Pose2>& poses) {
    double sum = 0.0;
    for (std::size_t k = 0; k < poses.size(); ++k) {
      sum += ((anchor * poses[k]).translation() - intel->scans[k].logged_pose.translation())
                 .squaredNorm();
    }
    return std::sqrt(sum / static_cast<double>(poses.size()));
  };
  state.counters["scans"] = static_cast<double>(counts.scans);
  state.counters["matched"] = counts.matched;
  state.counters["degenerate"] = counts.degenerate;
  state.counters["failed"] = counts.failed;
  // Relative pose error per scan step: translation (m) and yaw (rad), means.
  auto rpe = [&](const std::vector<Pose2>& poses, bool yaw) {
    double sum = 0.0;
    for (std::size_t k = 1; k < poses.size(); ++k) {
      const Pose2 e = intel->scans[k - 1]
                          .logged_pose.Between(intel->scans[k].logged_pose)
                          .Between(poses[k - 1].Between(poses[k]));
      sum += yaw ? std::abs(e.theta()) : e.translation().norm();
    }
    return sum / static_cast<double>(poses.size() - 1);
  };
  state.counters["icp_rpe_m"] = rpe(estimate, false);
  state.counters["odometry_rpe_m"] = rpe(dead_reckoning, false);
  state.counters["icp_rpe_rad"] = rpe(estimate, true);
  state.counters["odometry_rpe_rad"] = rpe(dead_reckoning, true);
  state.counters["icp_rmse_m"] = rmse(estimate);
  state.counters["odometry_rmse_m"] = rmse(dead_reckoning);
}
BENCHMARK(BM_IcpOdometryIntel)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace slamrig::slam

BENCHMARK_MAIN();
