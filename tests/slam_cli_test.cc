// `slamrig slam` and `slamrig eval` as a user runs them: files written, scores that agree with
// each other, determinism, and bad input rejected without leaving output behind.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

#include "tests/util/dataset.h"
#include "tests/util/read_file.h"
#include "tests/util/run_command.h"
#include "tests/util/temp_dir.h"

namespace slamrig {
namespace {

using slamrig::testing::ReadFile;

using testing::RunCommand;

// The first configuration's "ate_rmse_m" in the metrics.json of `slamrig slam`.
double SlamAteRmse(const std::string& json) {
  const std::size_t at = json.find("\"ate_rmse_m\": ");
  return at == std::string::npos ? -1.0 : std::stod(json.substr(at + 14));
}

// The "rmse" of the first "ate" object's "translation_m" in the metrics.json of `slamrig eval`.
double AteRmse(const std::string& json) {
  const std::size_t ate = json.find("\"ate\": {");
  const std::size_t rmse = json.find("\"rmse\": ", json.find("\"translation_m\"", ate));
  if (ate == std::string::npos || rmse == std::string::npos) return -1.0;
  return std::stod(json.substr(rmse + 8));
}

int CountPoses(const std::string& tum) {
  std::istringstream in(tum);
  std::string line;
  int n = 0;
  while (std::getline(in, line)) n += !line.empty() && line[0] != '#';
  return n;
}

const std::string kBinary = SLAMRIG_BINARY;

TEST(SlamCliTest, SlamWritesEverythingAndEvalAgreesWithIt) {
  SLAMRIG_REQUIRE_DATASET(log, "carmen_corrected/intel-corrected.log.gz");
  testing::TempDir dir;
  const std::string out = dir.File("slam");
  const auto slam =
      RunCommand(kBinary + " slam " + log + " --max-scans 120 --particles 30 --quiet --out " + out);
  ASSERT_EQ(slam.exit_code, 0) << slam.output;
  for (const char* f : {"trajectory.tum", "trajectory_mean.tum", "reference.tum", "map.pgm",
                        "map.yaml", "map.png", "metrics.json"}) {
    EXPECT_TRUE(std::filesystem::exists(out + "/" + f)) << f;
  }
  EXPECT_EQ(CountPoses(ReadFile(out + "/trajectory.tum")), 120);
  const double slam_rmse = SlamAteRmse(ReadFile(out + "/metrics.json"));
  EXPECT_GT(slam_rmse, 0.0);
  EXPECT_LT(slam_rmse, 0.5);

  const auto eval = RunCommand(kBinary + " eval --estimate " + out + "/trajectory.tum --truth " +
                               out + "/reference.tum --out " + dir.File("eval"));
  ASSERT_EQ(eval.exit_code, 0) << eval.output;
  EXPECT_NEAR(AteRmse(ReadFile(dir.File("eval") + "/metrics.json")), slam_rmse, 1e-6);

  // Relations generated from the reference, evaluated on the estimate.
  const auto relations =
      RunCommand(kBinary + " eval --estimate " + out + "/trajectory.tum --truth " + out +
                 "/reference.tum --make-relations " + dir.File("r.relations") + " --relations " +
                 dir.File("r.relations"));
  ASSERT_EQ(relations.exit_code, 0) << relations.output;
  EXPECT_NE(relations.output.find("relations: "), std::string::npos) << relations.output;
}

TEST(SlamCliTest, SameSeedSameTrajectoryFile) {
  SLAMRIG_REQUIRE_DATASET(log, "carmen_corrected/intel-corrected.log.gz");
  testing::TempDir dir;
  for (const char* run : {"a", "b"}) {
    const auto r =
        RunCommand(kBinary + " slam " + log +
                   " --max-scans 80 --particles 20 --seed 7 --quiet --out " + dir.File(run));
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  EXPECT_EQ(ReadFile(dir.File("a") + "/trajectory.tum"),
            ReadFile(dir.File("b") + "/trajectory.tum"));
}

TEST(SlamCliTest, DeadReckoningOnTheEce276aEncodersAndImu) {
  SLAMRIG_REQUIRE_DATASET(encoders, "ece276a_pr2_partial/Encoders20.npz");
  testing::TempDir dir;
  const auto r = RunCommand(kBinary + " slam " + encoders + " --algorithm dead-reckoning --out " +
                            dir.File("dr"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(CountPoses(ReadFile(dir.File("dr") + "/trajectory.tum")), 4956);
  const auto pf = RunCommand(kBinary + " slam " + encoders + " --out " + dir.File("pf"));
  EXPECT_EQ(pf.exit_code, 1);
  EXPECT_NE(pf.output.find("no laser scans"), std::string::npos) << pf.output;
  EXPECT_FALSE(std::filesystem::exists(dir.File("pf")));
}

TEST(SlamCliTest, BadInputIsOneLineAndNoOutput) {
  testing::TempDir dir;
  const auto missing =
      RunCommand(kBinary + " slam " + dir.File("nope.log") + " --out " + dir.File("o"));
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.output.find("nope.log"), std::string::npos) << missing.output;
  EXPECT_FALSE(std::filesystem::exists(dir.File("o")));
  const auto bad_algorithm =
      RunCommand(kBinary + " slam x.log --algorithm foo --out " + dir.File("o"));
  EXPECT_EQ(bad_algorithm.exit_code, 2);
  EXPECT_NE(bad_algorithm.output.find("--algorithm"), std::string::npos) << bad_algorithm.output;
  const auto bad_particles =
      RunCommand(kBinary + " slam x.log --particles 0 --out " + dir.File("o"));
  EXPECT_EQ(bad_particles.exit_code, 2);
  EXPECT_NE(bad_particles.output.find("particles = 0; must be > 0"), std::string::npos)
      << bad_particles.output;
  const auto eval = RunCommand(kBinary + " eval --truth " + dir.File("t.tum"));
  EXPECT_EQ(eval.exit_code, 2);
}

}  // namespace
}  // namespace slamrig
