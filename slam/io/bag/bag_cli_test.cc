// `slamrig simulate --format mcap|sqlite3` and `slamrig slam BAG` end to end: the bag of a
// simulated run holds the same sensor data as its CARMEN log, both storages read back to the
// same records, the same arguments give the same bytes, and a damaged bag is one error line.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "slam/io/bag/bag_reader.h"
#include "slam/io/carmen_reader.h"
#include "slam/io/dataset.h"
#include "tests/util/run_command.h"
#include "tests/util/temp_dir.h"

namespace slamrig::slam {
namespace {

namespace fs = std::filesystem;

std::string ReadAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string Simulate(const slamrig::testing::TempDir& dir, const std::string& name,
                     const std::string& format) {
  const std::string out = dir.File(name);
  const auto r = slamrig::testing::RunCommand(std::string(SLAMRIG_BINARY) +
                                              " simulate office --duration 8 --seed 3 --format " +
                                              format + " --out " + out);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return out;
}

std::vector<LaserScan> Scans(const Dataset& data) {
  std::vector<LaserScan> scans;
  for (const Record& r : data.records) {
    if (const auto* s = std::get_if<LaserScan>(&r)) scans.push_back(*s);
  }
  return scans;
}

TEST(BagCliTest, SimulatedBagsMatchTheCarmenLog) {
  slamrig::testing::TempDir dir;
  const std::string mcap = Simulate(dir, "m", "mcap");
  const std::string sqlite = Simulate(dir, "s", "sqlite3");
  const std::string carmen = Simulate(dir, "c", "carmen");
  const Dataset from_mcap = ReadBag(mcap + "/run");
  const Dataset from_sqlite = ReadBag(sqlite + "/run");
  const Dataset from_log = CarmenToDataset(ReadCarmenLog(carmen + "/run.log"));

  // Both storages hold the same messages.
  ASSERT_EQ(from_mcap.records.size(), from_sqlite.records.size());
  for (std::size_t i = 0; i < from_mcap.records.size(); ++i) {
    ASSERT_EQ(from_mcap.records[i].index(), from_sqlite.records[i].index()) << i;
    ASSERT_EQ(RecordTime(from_mcap.records[i]), RecordTime(from_sqlite.records[i])) << i;
  }
  // The scans and the truth at each scan are the ones the CARMEN log carries.
  const std::vector<LaserScan> bag_scans = Scans(from_mcap), log_scans = Scans(from_log);
  ASSERT_EQ(bag_scans.size(), 320u);  // 8 s at 40 Hz
  ASSERT_EQ(bag_scans.size(), log_scans.size());
  for (std::size_t i = 0; i < bag_scans.size(); ++i) {
    ASSERT_EQ(bag_scans[i].time, log_scans[i].time) << i;
    ASSERT_EQ(bag_scans[i].ranges_m, log_scans[i].ranges_m) << i;
    // CARMEN stores the laser's world pose, so its mount comes back with rounding errors.
    ASSERT_NEAR(bag_scans[i].base_from_laser.x(), log_scans[i].base_from_laser.x(), 1e-12) << i;
  }
  ASSERT_EQ(from_mcap.reference.size(), from_log.reference.size());
  for (std::size_t i = 0; i < from_log.reference.size(); ++i) {
    EXPECT_EQ(from_mcap.reference[i].time, from_log.reference[i].time);
    EXPECT_EQ(from_mcap.reference[i].map_from_base.x(), from_log.reference[i].map_from_base.x());
    EXPECT_EQ(from_mcap.reference[i].map_from_base.y(), from_log.reference[i].map_from_base.y());
    EXPECT_NEAR(from_mcap.reference[i].map_from_base.theta(),
                from_log.reference[i].map_from_base.theta(), 1e-15);
  }
  // Same arguments, same bytes.
  const std::string again = Simulate(dir, "m2", "mcap");
  EXPECT_EQ(ReadAll(again + "/run/run_0.mcap"), ReadAll(mcap + "/run/run_0.mcap"));
  EXPECT_EQ(ReadAll(again + "/run/metadata.yaml"), ReadAll(mcap + "/run/metadata.yaml"));
}

TEST(BagCliTest, SlamReadsABagAndRejectsADamagedOne) {
  slamrig::testing::TempDir dir;
  const std::string sim = Simulate(dir, "m", "mcap");
  const std::string out = dir.File("slam");
  auto r = slamrig::testing::RunCommand(std::string(SLAMRIG_BINARY) + " slam " + sim +
                                        "/run --algorithm dead-reckoning --quiet --out " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(ReadAll(out + "/metrics.json").find("\"log_format\": \"ros2bag\""), std::string::npos);
  EXPECT_TRUE(fs::exists(out + "/trajectory.tum"));

  // Cut the file: one error line naming it, exit code 1, nothing written.
  const std::string file = sim + "/run/run_0.mcap";
  fs::resize_file(file, fs::file_size(file) / 2);
  const std::string bad_out = dir.File("bad");
  r = slamrig::testing::RunCommand(std::string(SLAMRIG_BINARY) + " slam " + sim +
                                   "/run --algorithm dead-reckoning --quiet --out " + bad_out);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find(file + ": truncated"), std::string::npos) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_FALSE(fs::exists(bad_out));

  r = slamrig::testing::RunCommand(std::string(SLAMRIG_BINARY) +
                                   " simulate office --format rosbag1 --out " + dir.File("x"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--format: expected carmen, mcap, sqlite3 or ece276a, got 'rosbag1'"),
            std::string::npos)
      << r.output;
}

// Topic names other than the defaults: `simulate --topic` writes them, `slam --topic` reads them,
// and without the flag the renamed scans are skipped and said to be.
TEST(BagCliTest, RenamedTopicsAreWrittenAndRead) {
  slamrig::testing::TempDir dir;
  const std::string out = dir.File("r");
  auto r = slamrig::testing::RunCommand(std::string(SLAMRIG_BINARY) +
                                        " simulate office --duration 4 --format sqlite3 --topic "
                                        "scan=/front/scan --out " +
                                        out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  BagReaderOptions options;
  options.topics.scan = "/front/scan";
  EXPECT_EQ(Scans(ReadBag(out + "/run", options)).size(), 160u);  // 4 s at 40 Hz
  EXPECT_TRUE(Scans(ReadBag(out + "/run")).empty());

  const std::string slam = std::string(SLAMRIG_BINARY) + " slam " + out +
                           "/run --algorithm dead-reckoning --quiet --out ";
  r = slamrig::testing::RunCommand(slam + dir.File("with") + " --topic scan=/front/scan");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir.File("with") + "/trajectory.tum"));
  r = slamrig::testing::RunCommand(slam + dir.File("without"));
  EXPECT_NE(r.output.find("(no scans)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("skipped topic /front/scan (sensor_msgs/msg/LaserScan): 160 messages"),
            std::string::npos)
      << r.output;
  r = slamrig::testing::RunCommand(slam + dir.File("bad") + " --topic scan=front");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--topic: topics.scan = 'front'"), std::string::npos) << r.output;
}

// A recording killed with SIGKILL leaves no bag folder that looks complete: DIR/run appears only
// by the rename after metadata.yaml and the storage file are closed.
TEST(BagCliTest, KilledRecordingLeavesNoBag) {
  slamrig::testing::TempDir dir;
  const std::string out = dir.File("k");
  const auto r = slamrig::testing::RunCommand(
      "(" + std::string(SLAMRIG_BINARY) + " simulate office --duration 600 --format mcap --out " +
      out + " & pid=$!; sleep 0.5; kill -9 $pid; wait $pid; echo killed $?)");
  ASSERT_NE(r.output.find("killed 137"), std::string::npos) << r.output;  // 128 + SIGKILL
  EXPECT_FALSE(fs::exists(out + "/run")) << r.output;
  // What is left is the temporary folder, without metadata.yaml (or nothing at all, when the
  // kill came while a loaded machine was still starting the program).
  if (!fs::exists(out)) return;
  for (const auto& entry : fs::directory_iterator(out)) {
    EXPECT_FALSE(fs::exists(entry.path() / "metadata.yaml")) << entry.path();
  }
}

}  // namespace
}  // namespace slamrig::slam
