#include "slam/io/ece276a_reader.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <cstring>
#include <fstream>

#include "slam/io/npz_reader.h"
#include "slam/odometry/wheel_odometry.h"
#include "slam/types/error.h"
#include "tests/util/dataset.h"
#include "tests/util/temp_dir.h"

namespace slamrig::slam {
namespace {

// --- A minimal .npz writer (stored zip entries), independent of the reader under test. ---

std::string U16(std::uint32_t v) {
  return std::string{static_cast<char>(v & 0xff), static_cast<char>((v >> 8) & 0xff)};
}
std::string U32(std::uint32_t v) { return U16(v & 0xffff) + U16(v >> 16); }

struct NpyInput {
  std::string name;
  std::string descr;
  std::vector<std::size_t> shape;
  bool fortran;
  std::string data;  // raw little-endian elements in the stated order
};

std::string Npy(const NpyInput& a) {
  std::string shape = "(";
  for (const std::size_t s : a.shape) shape += std::to_string(s) + ", ";
  if (a.shape.size() > 1) shape.resize(shape.size() - 2);
  shape += ")";
  std::string header = "{'descr': '" + a.descr +
                       "', 'fortran_order': " + (a.fortran ? "True" : "False") +
                       ", 'shape': " + shape + ", }";
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  return std::string("\x93NUMPY\x01\x00", 8) + U16(static_cast<std::uint32_t>(header.size())) +
         header + a.data;
}

void WriteNpz(const std::string& path, const std::vector<NpyInput>& arrays) {
  std::string out, central;
  for (const NpyInput& a : arrays) {
    const std::string name = a.name + ".npy";
    const std::string body = Npy(a);
    const auto crc = static_cast<std::uint32_t>(
        crc32(0L, reinterpret_cast<const Bytef*>(body.data()), static_cast<uInt>(body.size())));
    const auto offset = static_cast<std::uint32_t>(out.size());
    const auto size = static_cast<std::uint32_t>(body.size());
    out += U32(0x04034b50) + U16(20) + U16(0) + U16(0) + U16(0) + U16(0) + U32(crc) + U32(size) +
           U32(size) + U16(static_cast<std::uint32_t>(name.size())) + U16(0) + name + body;
    central += U32(0x02014b50) + U16(20) + U16(20) + U16(0) + U16(0) + U16(0) + U16(0) + U32(crc) +
               U32(size) + U32(size) + U16(static_cast<std::uint32_t>(name.size())) + U16(0) +
               U16(0) + U16(0) + U16(0) + U32(0) + U32(offset) + name;
  }
  const auto central_at = static_cast<std::uint32_t>(out.size());
  out += central + U32(0x06054b50) + U16(0) + U16(0) +
         U16(static_cast<std::uint32_t>(arrays.size())) +
         U16(static_cast<std::uint32_t>(arrays.size())) +
         U32(static_cast<std::uint32_t>(central.size())) + U32(central_at) + U16(0);
  std::ofstream(path, std::ios::binary) << out;
}

template <typename T>
std::string Raw(const std::vector<T>& values) {
  std::string s(values.size() * sizeof(T), '\0');
  std::memcpy(s.data(), values.data(), s.size());
  return s;
}

// A three-second robot log: encoders at 40 Hz, IMU at 100 Hz, a 1081-beam Hokuyo at 40 Hz.
struct SmallLog {
  std::vector<double> enc_t, imu_t, lidar_t;
  std::vector<std::int16_t> counts_fortran;  // (4, N): FR FL RR RL of sample 0, then sample 1 ...
};

SmallLog WriteSmallLog(const testing::TempDir& dir, bool with_nan) {
  SmallLog log;
  const double t0 = 1298445274.5;
  for (int i = 0; i < 120; ++i) {
    log.enc_t.push_back(t0 + 0.025 * i);
    for (const std::int16_t c :
         {std::int16_t(i % 5), std::int16_t(i % 3), std::int16_t(i % 7), std::int16_t(1)}) {
      log.counts_fortran.push_back(c);
    }
  }
  std::vector<double> w, a;  // (3, N) in Fortran order
  for (int i = 0; i < 300; ++i) {
    log.imu_t.push_back(t0 + 0.003 + 0.01 * i);
    for (int k = 0; k < 3; ++k) w.push_back(0.01 * k + 0.001 * i);
    for (int k = 0; k < 3; ++k) a.push_back(k == 2 ? 1.0 : 0.0);
  }
  const int beams = 1081, scans = 120;
  std::vector<float> ranges(static_cast<std::size_t>(beams * scans));  // (1081, N) in C order
  for (int b = 0; b < beams; ++b) {
    for (int s = 0; s < scans; ++s)
      ranges[static_cast<std::size_t>(b * scans + s)] =
          static_cast<float>(1.0 + 0.001 * b + 0.01 * s);
  }
  if (with_nan) ranges[5 * scans + 7] = std::nanf("");
  for (int s = 0; s < scans; ++s) log.lidar_t.push_back(t0 + 0.025 * s);  // same stamps as encoders
  const std::size_t n_enc = log.enc_t.size(), n_imu = log.imu_t.size();
  WriteNpz(dir.File("Encoders99.npz"),
           {{"counts", "<i2", {4, n_enc}, true, Raw(log.counts_fortran)},
            {"time_stamps", "<f8", {n_enc}, false, Raw(log.enc_t)}});
  WriteNpz(dir.File("Imu99.npz"), {{"angular_velocity", "<f8", {3, n_imu}, true, Raw(w)},
                                   {"linear_acceleration", "<f8", {3, n_imu}, true, Raw(a)},
                                   {"time_stamps", "<f8", {n_imu}, false, Raw(log.imu_t)}});
  const double angle_min = -2.356194490192345, angle_max = 2.356194490192345;
  WriteNpz(dir.File("Hokuyo99.npz"),
           {{"angle_min", "<f8", {}, false, Raw(std::vector<double>{angle_min})},
            {"angle_max", "<f8", {}, false, Raw(std::vector<double>{angle_max})},
            {"angle_increment",
             "<f8",
             {},
             false,
             Raw(std::vector<double>{(angle_max - angle_min) / 1080})},
            {"range_min", "<f8", {}, false, Raw(std::vector<double>{0.1})},
            {"range_max", "<f8", {}, false, Raw(std::vector<double>{30.0})},
            {"ranges",
             "<f4",
             {static_cast<std::size_t>(beams), static_cast<std::size_t>(scans)},
             false,
             Raw(ranges)},
            {"time_stamps", "<f8", {static_cast<std::size_t>(scans)}, false, Raw(log.lidar_t)}});
  return log;
}

TEST(Ece276aReaderTest, ReadsNpzEncodersImuAndHokuyoInTimeOrder) {
  testing::TempDir dir;
  const SmallLog log = WriteSmallLog(dir, /*with_nan=*/true);
  const Ece276aFiles files = FindEce276aFiles(dir.File("99"));
  EXPECT_EQ(files.hokuyo, dir.File("Hokuyo99.npz"));
  EXPECT_EQ(FindEce276aFiles(dir.File("Imu99.npz")).encoders, dir.File("Encoders99.npz"));
  EXPECT_TRUE(LooksLikeEce276a(dir.File("Hokuyo99.npz")));
  EXPECT_FALSE(LooksLikeEce276a(dir.File("intel.log")));

  const Dataset data = ReadEce276a(files);
  ASSERT_EQ(data.records.size(), 120u + 300u + 120u);
  EXPECT_TRUE(data.reference.empty());
  EXPECT_THAT(data.notes, ::testing::ElementsAre("1 non-finite Hokuyo ranges read as no return"));
  int ticks = 0, imus = 0, scans = 0;
  for (std::size_t i = 0; i < data.records.size(); ++i) {
    const Record& r = data.records[i];
    if (i > 0) {
      ASSERT_LE(RecordTime(data.records[i - 1]), RecordTime(r)) << i;
    }
    if (const auto* t = std::get_if<WheelTicks>(&r)) {
      // [FR, FL, RR, RL] -> right {FR, RR}, left {FL, RL}.
      const std::size_t k = static_cast<std::size_t>(ticks);
      EXPECT_EQ(t->right_ticks, (std::vector<std::int32_t>{log.counts_fortran[4 * k],
                                                           log.counts_fortran[4 * k + 2]}));
      EXPECT_EQ(t->left_ticks, (std::vector<std::int32_t>{log.counts_fortran[4 * k + 1],
                                                          log.counts_fortran[4 * k + 3]}));
      EXPECT_EQ(t->time, Time::FromSeconds(log.enc_t[k]));
      ++ticks;
    } else if (const auto* imu = std::get_if<ImuSample>(&r)) {
      EXPECT_NEAR(imu->angular_velocity_rad_s.z(), 0.02 + 0.001 * imus, 1e-12);
      EXPECT_NEAR(imu->linear_acceleration_m_s2.z(), 9.80665, 1e-12);
      ++imus;
    } else {
      const auto& scan = std::get<LaserScan>(r);
      // Encoder records with the scan's stamp come before it.
      ASSERT_TRUE(std::holds_alternative<WheelTicks>(data.records[i - 1]));
      ASSERT_EQ(scan.ranges_m.size(), 1081u);
      EXPECT_NEAR(scan.BeamAngle(1080), 2.356194490192345, 1e-12);
      EXPECT_NEAR(scan.ranges_m[540], 1.0 + 0.001 * 540 + 0.01 * scans, 1e-6);
      EXPECT_EQ(scan.base_from_laser, Pose2(0.13323, 0.0, 0.0));
      if (scans == 7) {
        EXPECT_FALSE(scan.IsHit(5));
      }
      ++scans;
    }
  }
  EXPECT_EQ(ticks, 120);
  EXPECT_EQ(imus, 300);
  EXPECT_EQ(scans, 120);
}

TEST(Ece276aReaderTest, CsvAndNpzGiveTheSameRecords) {
  testing::TempDir dir;
  const SmallLog log = WriteSmallLog(dir, false);
  gzFile f = gzopen(dir.File("encoders98.csv.gz").c_str(), "wb");
  gzputs(f, "# unix_time_s,FR,FL,RR,RL\n");
  for (std::size_t i = 0; i < log.enc_t.size(); ++i) {
    char line[128];
    std::snprintf(line, sizeof(line), "%.6f,%d,%d,%d,%d\n", log.enc_t[i], log.counts_fortran[4 * i],
                  log.counts_fortran[4 * i + 1], log.counts_fortran[4 * i + 2],
                  log.counts_fortran[4 * i + 3]);
    gzputs(f, line);
  }
  gzclose(f);
  const Dataset csv = ReadEce276a(FindEce276aFiles(dir.File("98")));
  const Dataset npz = ReadEce276a(Ece276aFiles{dir.File("Encoders99.npz"), "", "", "", "", 0});
  ASSERT_EQ(csv.records.size(), 120u);
  ASSERT_EQ(npz.records.size(), 120u);
  for (std::size_t i = 0; i < 120; ++i) {
    EXPECT_EQ(std::get<WheelTicks>(csv.records[i]).right_ticks,
              std::get<WheelTicks>(npz.records[i]).right_ticks);
    EXPECT_EQ(std::get<WheelTicks>(csv.records[i]).time, std::get<WheelTicks>(npz.records[i]).time);
  }
}

TEST(Ece276aReaderTest, BadFilesAreParseErrorsNamingTheFileAndPlace) {
  testing::TempDir dir;
  gzFile f = gzopen(dir.File("encoders97.csv.gz").c_str(), "wb");
  gzputs(f, "# header\n1.0,1,2,3,4\n2.0,1,x,3,4\n");
  gzclose(f);
  try {
    ReadEce276a(FindEce276aFiles(dir.File("97")));
    FAIL();
  } catch (const ParseError& e) {
    EXPECT_STREQ(e.what(),
                 (dir.File("encoders97.csv.gz") + ":3: column 3: expected a finite number, got 'x'")
                     .c_str());
  }
  WriteNpz(dir.File("Encoders96.npz"),
           {{"counts", "<i2", {3, 1}, true, Raw(std::vector<std::int16_t>{1, 2, 3})},
            {"time_stamps", "<f8", {1}, false, Raw(std::vector<double>{1.0})}});
  EXPECT_THROW(ReadEce276a(FindEce276aFiles(dir.File("96"))), ParseError);
  EXPECT_THROW(FindEce276aFiles(dir.File("95")), ParseError);
  // Found by fuzz/ (ece276a_csv target): stamps past int64 nanoseconds became garbage times
  // and broke the time order of the records.
  dir.Write("encoders93.csv", "1.0,1,2,3,4\n12988819529.5,1,2,3,4\n");
  try {
    ReadEce276a(Ece276aFiles{dir.File("encoders93.csv"), "", "", "", "", 0});
    FAIL();
  } catch (const ParseError& e) {
    EXPECT_STREQ(e.what(), (dir.File("encoders93.csv") +
                            ":2: column 1: time 12988819529.500000 s is outside +-9.2e9 s")
                               .c_str());
  }
  WriteNpz(dir.File("Encoders92.npz"),
           {{"counts", "<i2", {4, 1}, true, Raw(std::vector<std::int16_t>{1, 2, 3, 4})},
            {"time_stamps", "<f8", {1}, false, Raw(std::vector<double>{-1e10})}});
  try {
    ReadEce276a(FindEce276aFiles(dir.File("92")));
    FAIL();
  } catch (const ParseError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("Encoders92.npz: time_stamps[0]: "));
  }
  // Found by fuzz/ (npz target): a deflated entry claiming 4 GiB made the reader allocate it,
  // and a huge npy shape overflowed the element count.
  const std::string name = "counts.npy";
  const std::string deflated("\x03\x00", 2);  // an empty deflate stream
  const std::string fields = U16(8) + U16(0) + U16(0) + U32(0) + U32(2) + U32(0xFFFFFFF0u) +
                             U16(static_cast<std::uint32_t>(name.size()));
  const std::string local = U32(0x04034b50) + U16(20) + U16(0) + fields + U16(0) + name + deflated;
  const std::string central = U32(0x02014b50) + U16(20) + U16(20) + U16(0) + fields + U16(0) +
                              U16(0) + U16(0) + U16(0) + U32(0) + U32(0) + name;
  dir.Write("Encoders91.npz", local + central + U32(0x06054b50) + U16(0) + U16(0) + U16(1) +
                                  U16(1) + U32(static_cast<std::uint32_t>(central.size())) +
                                  U32(static_cast<std::uint32_t>(local.size())) + U16(0));
  try {
    ReadNpz(dir.File("Encoders91.npz"));
    FAIL();
  } catch (const ParseError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("counts.npy: uncompressed size 4294967280 is "
                                               "impossible for 2 deflated bytes"));
  }
  for (const char* shape : {"(2305843009213693952,)", "(99999999999999999999999,)"}) {
    const std::string header =
        std::string("{'descr': '<f8', 'fortran_order': False, 'shape': ") + shape + ", }\n";
    const std::string npy = std::string("\x93NUMPY\x01\x00", 8) +
                            U16(static_cast<std::uint32_t>(header.size())) + header + "12345678";
    EXPECT_THROW(
        {
          try {
            ParseNpy(npy, "big.npy");
          } catch (const ParseError& e) {
            EXPECT_THAT(e.what(), ::testing::HasSubstr("big.npy: npy shape"));
            throw;
          }
        },
        ParseError)
        << shape;
  }
  dir.Write("Encoders94.npz", "not a zip");
  EXPECT_THROW(ReadNpz(dir.File("Encoders94.npz")), ParseError);
}

// The shared course data: npz and csv agree, the encoder totals match SOURCE.md, and encoder +
// gyro dead reckoning brings the robot back near its start (the course robot drives a loop).
TEST(Ece276aReaderTest, RealDataset20) {
  SLAMRIG_REQUIRE_DATASET(encoders, "ece276a_pr2_partial/Encoders20.npz");
  const Dataset npz = ReadEce276a(FindEce276aFiles(encoders));
  const std::string csv_path =
      (std::filesystem::path(encoders).parent_path() / "encoders20.csv.gz").string();
  const std::string imu_csv =
      (std::filesystem::path(encoders).parent_path() / "imu20.csv.gz").string();
  const Dataset csv = ReadEce276a(Ece276aFiles{csv_path, imu_csv, "", "", "", 0});
  ASSERT_EQ(npz.records.size(), 4956u + 12187u);
  ASSERT_EQ(csv.records.size(), npz.records.size());
  double right = 0.0, left = 0.0;
  WheelOdometry odometry(WheelOdometryOptions{});
  Pose2 last;
  for (std::size_t i = 0; i < npz.records.size(); ++i) {
    // The csv carries microseconds.
    ASSERT_LT(std::abs(RecordTime(npz.records[i]).ns - RecordTime(csv.records[i]).ns), 1000) << i;
    if (const auto* t = std::get_if<WheelTicks>(&npz.records[i])) {
      right += 0.5 * (t->right_ticks[0] + t->right_ticks[1]) * 0.0022;
      left += 0.5 * (t->left_ticks[0] + t->left_ticks[1]) * 0.0022;
      last = odometry.AddTicks(*t).odom_from_base;
    } else {
      odometry.AddImu(std::get<ImuSample>(npz.records[i]));
    }
  }
  EXPECT_NEAR(right, 95.91, 0.01);
  EXPECT_NEAR(left, 95.81, 0.01);
  RecordProperty("dead_reckoning_end_m", std::to_string(last.translation().norm()));
  // 3.0 m after 95.9 m with this reader and WheelOdometry's defaults: within 5 % of the path.
  EXPECT_LT(last.translation().norm(), 0.05 * 95.9);
}

}  // namespace
}  // namespace slamrig::slam
