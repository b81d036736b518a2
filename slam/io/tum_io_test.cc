#include "slam/io/tum_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

#include "slam/types/error.h"
#include "tests/util/temp_dir.h"

namespace slamrig::slam {
namespace {

using ::testing::HasSubstr;

TEST(TumIoTest, RoundTripsRandomTrajectoriesExactly) {
  testing::TempDir dir;
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> xy(-500, 500), th(-3.14159, 3.14159);
  Trajectory t;
  std::int64_t ns = 1'298'445'274'541'885'123;
  for (int i = 0; i < 1000; ++i) {
    ns += 25'000'000 + i;
    // Sequenced draws, the last coordinate first (the order these cases were generated in).
    const double theta = th(rng), y = xy(rng), x = xy(rng);
    t.Append(Time::FromNanoseconds(ns), Pose2(x, y, theta));
  }
  WriteTum(dir.File("t.tum"), t);
  const Trajectory back = ReadTum(dir.File("t.tum"));
  ASSERT_EQ(back.size(), t.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    EXPECT_EQ(back[i].time, t[i].time);
    EXPECT_EQ(back[i].pose.x(), t[i].pose.x());
    EXPECT_EQ(back[i].pose.y(), t[i].pose.y());
    EXPECT_NEAR(back[i].pose.theta(), t[i].pose.theta(), 1e-14);
  }
}

TEST(TumIoTest, ReadsYawFromQuaternion) {
  testing::TempDir dir;
  // 90 degrees about z.
  const auto path =
      dir.Write("q.tum", "# header\n\n1.5 1 2 0 0 0 0.7071067811865476 0.7071067811865476\n");
  const Trajectory t = ReadTum(path);
  ASSERT_EQ(t.size(), 1u);
  EXPECT_NEAR(t[0].pose.theta(), 1.5707963267948966, 1e-12);
  EXPECT_EQ(t[0].time, Time::FromSeconds(1.5));
}

TEST(TumIoTest, BadLinesNameFileLineAndField) {
  testing::TempDir dir;
  auto error = [&](const std::string& text) {
    try {
      ReadTum(dir.Write("b.tum", text));
    } catch (const ParseError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_THAT(error("1 2 3 0 0 0 0 1\n2 2 3 0 0 0\n"), HasSubstr("b.tum:2: expected 8 fields"));
  EXPECT_THAT(error("1 2 x 0 0 0 0 1\n"),
              HasSubstr("b.tum:1: ty: expected a finite number, got 'x'"));
  EXPECT_THAT(error("1 2 3 0 0 0 0 2\n"), HasSubstr("quaternion: norm"));
  EXPECT_THAT(error("1 2 3 0 1 0 0 0\n"), HasSubstr("leaves the plane"));
  EXPECT_THAT(error("2 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n"), HasSubstr("b.tum:2: timestamp"));
  // Found by fuzz/ (tum target): stamps past int64 nanoseconds overflowed (undefined behaviour).
  EXPECT_THAT(error("18327992021 0 0 0 0 0 0 1\n"),
              HasSubstr("b.tum:1: timestamp: expected seconds within +-9.2e9, got '18327992021'"));
  EXPECT_THAT(error("-9.3e9 0 0 0 0 0 0 1\n"), HasSubstr("b.tum:1: timestamp: expected seconds"));
  EXPECT_THAT(error("9223372035.999999999 0 0 0 0 0 0 1\n"), ::testing::IsEmpty());
}

}  // namespace
}  // namespace slamrig::slam
