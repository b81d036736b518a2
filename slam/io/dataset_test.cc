#include "slam/io/dataset.h"

#include <gtest/gtest.h>

#include <random>

#include "tests/util/temp_dir.h"

namespace slamrig::slam {
namespace {

std::string PoseText(const Pose2& p) {
  char s[120];
  std::snprintf(s, sizeof(s), "%.12g %.12g %.12g", p.x(), p.y(), p.theta());
  return s;
}

// A GMapping-style corrected log: each scan's pose is a corrected pose P_k; each ODOM line is
// P_{k-1} composed with the true odometry increment since scan k-1; echo lines after scans.
TEST(DatasetTest, RecoversRawOdometryFromCorrectedLog) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 0.05);
  std::vector<Pose2> corrected, raw;
  Pose2 truth(0.6, -0.03, -0.35);
  Pose2 odometry = truth;  // recovered odometry starts at the first corrected pose
  std::string text;
  double t = 10.0;
  for (int k = 0; k < 30; ++k) {
    if (k > 0) {
      // Two ODOM lines between scans: half and all of this step's raw motion.
      const Pose2 step(0.4, 0.02 * k, 0.1 * std::sin(k));
      const Pose2 half(0.2, 0.01 * k, 0.05 * std::sin(k));
      text += "ODOM " + PoseText(corrected.back() * half) + " 0 0 0 " + std::to_string(t += 0.1) +
              " h 0\n";
      text += "ODOM " + PoseText(corrected.back() * step) + " 0 0 0 " + std::to_string(t += 0.1) +
              " h 0\n";
      odometry = odometry * step;
      // Sequenced draws, the last coordinate first (the order these cases were generated in).
      const double yaw = 0.2 * noise(rng), y = noise(rng), x = noise(rng);
      truth = corrected.back() * step * Pose2(x, y, yaw);
    }
    corrected.push_back(truth);
    raw.push_back(odometry);
    std::string flaser = "FLASER 3 1 2 3 " + PoseText(truth) + " " + PoseText(truth) + " " +
                         std::to_string(t += 0.1) + " pippo 0\n";
    text += flaser + "ODOM " + PoseText(truth) + " 0 0 0 0 pippo 0\n";
  }
  testing::TempDir dir;
  const CarmenLog log = ReadCarmenLog(dir.Write("c.log", text));
  ASSERT_TRUE(log.is_corrected);
  const Dataset data = CarmenToDataset(log);
  ASSERT_EQ(data.reference.size(), 30u);
  // The odometry pose just before each scan is the chained raw odometry.
  std::size_t scan = 0;
  Pose2 last_odometry;
  for (const Record& r : data.records) {
    if (const auto* o = std::get_if<OdometryPose>(&r)) last_odometry = o->odom_from_base;
    if (std::holds_alternative<LaserScan>(r)) {
      EXPECT_NEAR(last_odometry.x(), raw[scan].x(), 1e-6) << scan;
      EXPECT_NEAR(last_odometry.y(), raw[scan].y(), 1e-6) << scan;
      EXPECT_NEAR(NormalizeAngle(last_odometry.theta() - raw[scan].theta()), 0.0, 1e-6) << scan;
      EXPECT_NEAR(data.reference[scan].map_from_base.x(), corrected[scan].x(), 1e-9);
      ++scan;
    }
  }
  EXPECT_EQ(scan, 30u);
}

TEST(DatasetTest, RawLogUsesOdometryAndTruePos) {
  testing::TempDir dir;
  const std::string text =
      "ODOM 0 0 0 0 0 0 1.0 h 1.0\n"
      "FLASER 2 1 1 0.1 0 0 0.1 0 0 1.1 h 1.1\n"
      "TRUEPOS 0.11 0 0 0.1 0 0 1.1 h 1.1\n";
  const Dataset data = CarmenToDataset(ReadCarmenLog(dir.Write("r.log", text)));
  ASSERT_EQ(data.records.size(), 3u);
  EXPECT_EQ(std::get<OdometryPose>(data.records[1]).odom_from_base, Pose2(0.1, 0, 0));
  EXPECT_TRUE(std::holds_alternative<LaserScan>(data.records[2]));
  ASSERT_EQ(data.reference.size(), 1u);
  EXPECT_EQ(data.reference_kind, "TRUEPOS");
}

}  // namespace
}  // namespace slamrig::slam
