// intel-corrected with its recovered raw odometry, through the estimator pipeline: the PF
// (default options, 200 particles as scenarios/intel_log.yaml runs it) must stay within 0.15 m ATE
// RMSE of the GMapping-corrected poses while dead reckoning on the same odometry is off by more
// than a metre; the same seed reproduces the trajectory bit for bit whatever the thread count;
// every pose carries its own scan's stamp.
#include <gtest/gtest.h>

#include "slam/eval/trajectory_error.h"
#include "slam/io/carmen_reader.h"
#include "slam/io/dataset.h"
#include "slam/pipeline/estimator_runner.h"
#include "tests/util/dataset.h"

namespace slamrig::slam {
namespace {

TEST(PipelineIntelTest, ParticleFilterBeatsTheReferenceBoundAndDeadReckoning) {
  SLAMRIG_REQUIRE_DATASET(path, "carmen_corrected/intel-corrected.log.gz");
  const Dataset data = CarmenToDataset(ReadCarmenLog(path));
  Trajectory reference;
  for (const GroundTruthPose& g : data.reference) reference.Append(g.time, g.map_from_base);

  const EstimatorRun dr =
      RunEstimator(DefaultEstimatorConfig("dead_reckoning", "dead-reckoning"), data.records, 1);
  ASSERT_EQ(dr.online.size(), 910u);
  const double dr_rmse = ComputeAte(dr.final, reference).translation_m.rmse;
  EstimatorConfig config = DefaultEstimatorConfig("pf", "pf");
  ReadEstimatorFields(YamlNode::LoadString("{particles: 200, threads: 2}", "test"), &config);
  const EstimatorRun pf = RunEstimator(config, data.records, 1);
  const double pf_rmse = ComputeAte(pf.final, reference).translation_m.rmse;
  RecordProperty("dead_reckoning_ate_rmse_m", std::to_string(dr_rmse));
  RecordProperty("pf_ate_rmse_m", std::to_string(pf_rmse));
  EXPECT_GT(dr_rmse, 1.0);
  EXPECT_LE(pf_rmse, 0.15) << "dead reckoning " << dr_rmse;

  // Honest stamps: pose k carries scan k's own stamp (intel's go backwards in places).
  ASSERT_EQ(pf.final.size(), reference.size());
  for (std::size_t i = 0; i < reference.size(); ++i) {
    ASSERT_EQ(pf.final[i].time, reference[i].time) << i;
  }
  EXPECT_FALSE(reference.time_ordered());

  const YamlNode threads = YamlNode::LoadString("threads: 1", "test");
  ReadEstimatorFields(threads, &config);
  const EstimatorRun again = RunEstimator(config, data.records, 1);
  for (std::size_t i = 0; i < pf.final.size(); ++i) {
    ASSERT_EQ(pf.final[i].pose, again.final[i].pose) << i;
  }
}

}  // namespace
}  // namespace slamrig::slam
