// `slamrig simulate --format mcap|sqlite3` and `slamrig slam BAG` end to end: the bag of a
// simulated run holds the same sensor data as its CARMEN log, both storages read back to the
// same records, the same arguments give the same bytes, and a damaged bag is one error line.

#include <gtest/gtest.h>

#include <filesystem>

#include "slam/io/bag/bag_reader.h"
#include "slam/io/carmen_reader.h"
#include "slam/io/dataset.h"
#include "slam/types/error.h"
#include "tests/util/read_file.h"
#include "tests/util/run_command.h"
#include "tests/util/temp_dir.h"

namespace slamrig::slam {
namespace {

using slamrig::testing::ReadFile;

namespace fs = std::filesystem;

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
  EXPECT_EQ(ReadFile(again + "/run/run_0.mcap"), ReadFile(mcap + "/run/run_0.mcap"));
  EXPECT_EQ(ReadFile(again + "/run/metadata.yaml"), ReadFile(mcap + "/run/metadata.yaml"));
}

TEST(BagCliTest, SlamReadsABagAndRejectsADamagedOne) {
  slamrig::testing::TempDir dir;
  const std::string sim = Simulate(dir, "m", "mcap");
  const std::string out = dir.File("slam");
  auto r = slamrig::testing::RunCommand(std::string(SLAMRIG_BINARY) + " slam " + sim +
                                        "/run --algorithm dead-reckoning --quiet --out " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(ReadFile(out + "/metrics.json").find("\"log_format\": \"ros2bag\""), std::string::npos);
  EXPECT_TRUE(fs::exists(out + "/trajectory.tum"));

  // Cut the file, as a recording killed mid-way leaves it: the run scores the messages before
  // the cut and says so on stderr (and among the notes); --strict refuses it: one error line
  // naming it, exit code 1, nothing written.
  const std::string file = sim + "/run/run_0.mcap";
  fs::resize_file(file, fs::file_size(file) / 2);
  const std::string cut_out = dir.File("cut");
  const std::string slam = std::string(SLAMRIG_BINARY) + " slam " + sim +
                           "/run --algorithm dead-reckoning --quiet --out ";
  r = slamrig::testing::RunCommand("(" + slam + cut_out + " 2>&1 >/dev/null)");  // stderr only
  EXPECT_EQ(r.exit_code, 0) << r.output;
  const std::string note =
      "note: " + file + " truncated at byte " + GroupedCount(fs::file_size(file)) + ": recovered ";
  EXPECT_TRUE(r.output.starts_with(note)) << r.output;
  EXPECT_TRUE(r.output.ends_with(" scans of an unknown total; the rest is lost\n")) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_NE(ReadFile(cut_out + "/metrics.json").find(note.substr(6)), std::string::npos);
  EXPECT_TRUE(fs::exists(cut_out + "/trajectory.tum"));

  const std::string bad_out = dir.File("bad");
  r = slamrig::testing::RunCommand(slam + bad_out + " --strict");
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
// and without the flag the error lists the bag's topics and the flag that maps the scans.
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

  const std::string slam = std::string(SLAMRIG_BINARY) + " slam " + out +
                           "/run --algorithm dead-reckoning --quiet --out ";
  r = slamrig::testing::RunCommand(slam + dir.File("with") + " --topic scan=/front/scan");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir.File("with") + "/trajectory.tum"));
  r = slamrig::testing::RunCommand(slam + dir.File("without"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_EQ(r.output, "slamrig: error: " + out +
                          "/run: no sensor_msgs/msg/LaserScan on /scan; the bag has /clock (Clock, "
                          "401), /front/scan (LaserScan, 160), /ground_truth/odom (Odometry, 160), "
                          "/imu (Imu, 400), /joint_states (JointState, 160), /odom (Odometry, "
                          "160), /tf (TFMessage, 160), /tf_static (TFMessage, 1): try --topic "
                          "scan=/front/scan\n");
  EXPECT_FALSE(fs::exists(dir.File("without")));
  r = slamrig::testing::RunCommand(slam + dir.File("bad") + " --topic scan=front");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--topic: topics.scan = 'front'"), std::string::npos) << r.output;
}

// `slamrig slam DIR` on what `slamrig simulate --out DIR` wrote reads the run inside: the same
// result as naming DIR/run.log or the bag DIR/run; a folder with two runs names both.
TEST(BagCliTest, SlamOnASimulateFolderFindsItsRun) {
  slamrig::testing::TempDir dir;
  for (const std::string format : {"carmen", "mcap"}) {
    SCOPED_TRACE(format);
    const std::string sim = Simulate(dir, format, format);
    const std::string run = sim + (format == "carmen" ? "/run.log" : "/run");
    const std::string slam =
        std::string(SLAMRIG_BINARY) + " slam --algorithm dead-reckoning --quiet ";
    auto r = slamrig::testing::RunCommand(slam + sim + " --out " + dir.File(format + "_dir"));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    r = slamrig::testing::RunCommand(slam + run + " --out " + dir.File(format + "_run"));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(ReadFile(dir.File(format + "_dir/trajectory.tum")),
              ReadFile(dir.File(format + "_run/trajectory.tum")));
  }
  fs::copy(dir.File("mcap/run"), dir.File("carmen/run"), fs::copy_options::recursive);
  const auto r = slamrig::testing::RunCommand(std::string(SLAMRIG_BINARY) + " slam " +
                                              dir.File("carmen") + " --out " + dir.File("two"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_EQ(r.output, "slamrig: error: " + dir.File("carmen") + ": a folder with 2 runs (" +
                          dir.File("carmen/run") + ", " + dir.File("carmen/run.log") +
                          "): give one\n");
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
    // What the killed writer had written reads up to its last whole chunk, or is one clean
    // error when it had not written one yet.
    if (!entry.is_directory()) continue;
    try {
      const Dataset data = ReadBag(entry.path().string());
      EXPECT_NE(data.truncated.find(" truncated at byte "), std::string::npos) << data.truncated;
      std::printf("killed recording: %s\n", data.truncated.c_str());
    } catch (const ParseError& e) {
      EXPECT_NE(std::string(e.what()).find(entry.path().string()), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace slamrig::slam
