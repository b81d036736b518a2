// Issue 4's real-data check: intel-corrected with its recovered raw odometry. The PF (improved
// defaults, 100 particles) must stay within 0.15 m ATE RMSE of the GMapping-corrected poses
// while dead reckoning on the same odometry is off by more than a metre; and the same seed must
// reproduce the trajectory bit for bit.
#include <gtest/gtest.h>

#include "slam/eval/trajectory_error.h"
#include "slam/io/carmen_reader.h"
#include "slam/io/dataset.h"
#include "slam/odometry/scan_sync.h"
#include "slam/pf/slam_run.h"
#include "tests/util/dataset.h"

namespace slamrig::slam {
namespace {

TEST(ParticleFilterIntelTest, BeatsTheReferenceBoundAndDeadReckoning) {
  SLAMRIG_REQUIRE_DATASET(path, "carmen_corrected/intel-corrected.log.gz");
  const Dataset data = CarmenToDataset(ReadCarmenLog(path));
  const ScanSyncResult synced = SyncToScans(data.records, ScanSyncOptions{});
  ASSERT_EQ(synced.scans.size(), 910u);
  Trajectory reference;
  for (const GroundTruthPose& g : data.reference) reference.Append(g.time, g.map_from_base);

  const double dr =
      ComputeAte(RunDeadReckoning(synced.scans, OccupancyGridOptions{}).trajectory, reference)
          .translation_m.rmse;
  ParticleFilterOptions options;
  options.num_particles = 100;
  const SlamRunResult pf = RunParticleFilter(synced.scans, options);
  const double pf_rmse = ComputeAte(pf.trajectory, reference).translation_m.rmse;
  RecordProperty("dead_reckoning_ate_rmse_m", std::to_string(dr));
  RecordProperty("pf_ate_rmse_m", std::to_string(pf_rmse));
  EXPECT_GT(dr, 1.0);
  EXPECT_LE(pf_rmse, 0.15) << "dead reckoning " << dr;

  options.num_threads = 2;
  const SlamRunResult again = RunParticleFilter(synced.scans, options);
  for (std::size_t i = 0; i < pf.trajectory.size(); ++i) {
    ASSERT_EQ(pf.trajectory[i].pose, again.trajectory[i].pose) << i;
  }
}

}  // namespace
}  // namespace slamrig::slam
