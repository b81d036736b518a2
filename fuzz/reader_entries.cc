#include "fuzz/reader_entries.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "fuzz/scratch_dir.h"
#include "scenarios/scenario_spec.h"
#include "scenarios/sweep_spec.h"
#include "sim/robot_yaml.h"
#include "sim/world_yaml.h"
#include "slam/io/bag/bag_reader.h"
#include "slam/io/carmen_reader.h"
#include "slam/io/ece276a_reader.h"
#include "slam/io/map_server.h"
#include "slam/io/npz_reader.h"
#include "slam/io/tum_io.h"
#include "slam/types/error.h"

namespace slamrig::fuzz {
namespace {

// A broken promise of a reader's result: escapes RunReaderEntry, so the fuzzer reports it.
void Expect(bool condition, const std::string& what) {
  if (!condition) throw std::logic_error("reader result breaks its contract: " + what);
}

bool Finite(const Pose2& p) {
  return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.theta());
}

template <typename T, typename TimeOf>
void ExpectNonDecreasing(const std::vector<T>& items, TimeOf time_of, const std::string& what) {
  for (std::size_t i = 1; i < items.size(); ++i) {
    Expect(time_of(items[i - 1]) <= time_of(items[i]), what + " times go backwards");
  }
}

void CheckCarmen(const slam::CarmenLog& log) {
  for (const slam::CarmenScan& s : log.scans) {
    Expect(!s.scan.ranges_m.empty(), "CARMEN scan without beams");
    Expect(std::all_of(s.scan.ranges_m.begin(), s.scan.ranges_m.end(),
                       [](float r) { return std::isfinite(r) && r >= 0.0f; }),
           "CARMEN scan with a negative or non-finite range");
    Expect(Finite(s.logged_pose) && Finite(s.odom_pose), "CARMEN scan with a non-finite pose");
  }
  for (const slam::CarmenOdometry& o : log.odometry) {
    Expect(Finite(o.odometry.odom_from_base), "CARMEN odometry with a non-finite pose");
  }
  // A real log's stamps may go backwards; each message keeps its own stamp and the reader counts
  // them (stats.out_of_order_times, over all messages in file order). Within one kind there
  // are at most that many steps back, and none when it counted none.
  const auto steps_back = [](const auto& items, auto time_of) {
    int n = 0;
    for (std::size_t i = 1; i < items.size(); ++i) n += time_of(items[i]) < time_of(items[i - 1]);
    return n;
  };
  const int scans_back =
      steps_back(log.scans, [](const slam::CarmenScan& s) { return s.scan.time; });
  const int odometry_back =
      steps_back(log.odometry, [](const slam::CarmenOdometry& o) { return o.odometry.time; });
  Expect(scans_back <= log.stats.out_of_order_times,
         "CARMEN scan times go backwards more often than the reader counted");
  Expect(odometry_back <= log.stats.out_of_order_times,
         "CARMEN odometry times go backwards more often than the reader counted");
  Expect(log.stats.out_of_order_times == 0 || !log.notes.empty(),
         "CARMEN stamps out of order without a note");
}

// CARMEN log, read strictly and leniently: the bytes are the log file.
void RunCarmen(std::string_view data) {
  const std::string path = ScratchDir::Get().Write("input.log", data);
  bool strict_accepted = false;
  try {
    CheckCarmen(slam::ReadCarmenLog(path, {.lenient = false}));
    strict_accepted = true;
  } catch (const ParseError&) {
  }
  // Leniency only turns errors into skips: a log read strictly is read leniently too.
  try {
    CheckCarmen(slam::ReadCarmenLog(path, {.lenient = true}));
  } catch (const ParseError&) {
    Expect(!strict_accepted, "a log accepted strictly is rejected leniently");
    throw;
  }
}

void CheckNpz(const std::map<std::string, slam::NpyArray>& arrays) {
  for (const auto& [name, array] : arrays) {
    std::size_t count = 1;
    for (const std::size_t d : array.shape) count *= d;
    Expect(array.values.size() == count, "npy array " + name + " size differs from its shape");
  }
}

// ECE276A records are merged in time order.
void CheckDataset(const slam::Dataset& dataset) {
  ExpectNonDecreasing(dataset.records, RecordTime, "ECE276A record");
}

// numpy .npz archive: the bytes are the archive, read as such and then as each of the
// ECE276A files (encoders; IMU and Hokuyo beside a one-row encoder file).
void RunNpz(std::string_view data) {
  const ScratchDir& dir = ScratchDir::Get();
  const std::string npz = dir.Write("Encoders20.npz", data);
  CheckNpz(slam::ReadNpz(npz));
  const std::string encoders_csv = dir.Write("encoders21.csv", "0.0,1,2,3,4\n");
  for (const slam::Ece276aFiles& files : {slam::Ece276aFiles{.encoders = npz,
                                         .imu = "",
                                         .hokuyo = "",
                                         .kinect = "",
                                         .kinect_images = "",
                                         .dataset = 0},
                                          slam::Ece276aFiles{.encoders = encoders_csv,
                                          .imu = npz,
                                          .hokuyo = "",
                                          .kinect = "",
                                          .kinect_images = "",
                                          .dataset = 0},
                                          slam::Ece276aFiles{.encoders = encoders_csv,
                                          .imu = "",
                                          .hokuyo = npz,
                                          .kinect = "",
                                          .kinect_images = "",
                                          .dataset = 0}}) {
    try {
      CheckDataset(slam::ReadEce276a(files));
    } catch (const ParseError&) {
    }
  }
}

// ECE276A csv: the encoder file, then (after a NUL byte, optional) the IMU file.
void RunEce276aCsv(std::string_view data) {
  const ScratchDir& dir = ScratchDir::Get();
  slam::Ece276aFiles files;
  files.encoders = dir.Write("encoders20.csv", FirstPart(data));
  if (data.find('\0') != std::string_view::npos) {
    files.imu = dir.Write("imu20.csv", SecondPart(data));
  }
  CheckDataset(slam::ReadEce276a(files));
}

// TUM trajectory: the bytes are the file.
void RunTum(std::string_view data) {
  const Trajectory trajectory = slam::ReadTum(ScratchDir::Get().Write("input.tum", data));
  for (const StampedPose& p : trajectory.poses()) Expect(Finite(p.pose), "TUM non-finite pose");
  ExpectNonDecreasing(
      trajectory.poses(), [](const StampedPose& p) { return p.time; }, "TUM");
}

// map_server map: the YAML (its `image:` should be map.pgm), a NUL byte, then the PGM.
void RunMapServer(std::string_view data) {
  const ScratchDir& dir = ScratchDir::Get();
  dir.Write("map.pgm", SecondPart(data));
  const slam::MapImage map = slam::ReadMapServerMap(dir.Write("map.yaml", FirstPart(data)));
  Expect(map.width > 0 && map.height > 0, "map without cells");
  Expect(map.occupancy.size() ==
             static_cast<std::size_t>(map.width) * static_cast<std::size_t>(map.height),
         "map occupancy size differs from width * height");
  Expect(std::all_of(map.occupancy.begin(), map.occupancy.end(),
                     [](std::int8_t v) { return v >= -1 && v <= 100; }),
         "map occupancy outside -1..100");
  Expect(std::isfinite(map.resolution_m) && map.resolution_m > 0.0, "map resolution not > 0");
  Expect(Finite(map.origin), "map origin not finite");
}

// World file (worlds/*.yaml; `maps/` resolves to worlds/maps): read, written, read back.
void RunWorldYaml(std::string_view data) {
  const ScratchDir& dir = ScratchDir::Get();
  const std::string yaml = sim::WorldSpecToYaml(sim::LoadWorldSpec(dir.Write("world.yaml", data)));
  const std::string again = sim::WorldSpecToYaml(sim::LoadWorldSpec(dir.Write("world.yaml", yaml)));
  Expect(yaml == again, "world YAML does not read back to the same world");
}

// Robot file (robots/*.yaml): read, written, read back.
void RunRobotYaml(std::string_view data) {
  const ScratchDir& dir = ScratchDir::Get();
  const std::string yaml = sim::RobotSpecToYaml(sim::LoadRobotSpec(dir.Write("robot.yaml", data)));
  const std::string again = sim::RobotSpecToYaml(sim::LoadRobotSpec(dir.Write("robot.yaml", yaml)));
  Expect(yaml == again, "robot YAML does not read back to the same robot");
}

// Scenario file, written as scenarios/input.yaml (so ../worlds/ and ../robots/ resolve).
void RunScenarioYaml(std::string_view data) {
  scenario::LoadScenario(ScratchDir::Get().Write("scenarios/input.yaml", data));
}

// Sweep file, written as scenarios/sweeps/input.yaml (so ../office_loop.yaml resolves); the
// grid is expanded as the sweep runner does.
void RunSweepYaml(std::string_view data) {
  const scenario::SweepSpec spec =
      scenario::LoadSweepSpec(ScratchDir::Get().Write("scenarios/sweeps/input.yaml", data));
  const std::vector<scenario::SweepRun> runs = scenario::ExpandSweep(spec);
  std::size_t expected = spec.seeds.size();
  for (const scenario::SweepParameter& p : spec.parameters) expected *= p.values.size();
  Expect(runs.size() == expected, "sweep grid size differs from the product of its lists");
}

// ROS 2 bag: the bytes are one MCAP or sqlite3 file (ReadBag tells them apart by the magic),
// so that one target fuzzes both storages and the CDR decoders of every message type behind
// them; the seeds are bags `slamrig simulate --format mcap|sqlite3` wrote.
void RunBag(std::string_view data) {
  const ScratchDir& dir = ScratchDir::Get();
  // sqlite3 may leave a journal beside a file it could not read; the next input starts clean.
  dir.Remove("input.bag-journal");
  const slam::Dataset dataset = slam::ReadBag(dir.Write("input.bag", data));
  ExpectNonDecreasing(dataset.records, RecordTime, "bag record");
  ExpectNonDecreasing(
      dataset.reference, [](const GroundTruthPose& p) { return p.time; }, "bag ground truth");
}

}  // namespace

const std::vector<ReaderEntry>& ReaderEntries() {
  static const std::vector<ReaderEntry> entries = {
      {"carmen", RunCarmen, "a CARMEN log (plain or gzip)"},
      {"npz", RunNpz, "a numpy .npz archive"},
      {"ece276a_csv", RunEce276aCsv, "encoders csv [NUL imu csv]"},
      {"tum", RunTum, "a TUM trajectory"},
      {"map_server", RunMapServer, "map_server YAML with image: map.pgm, NUL, PGM image"},
      {"world_yaml", RunWorldYaml, "a world file"},
      {"robot_yaml", RunRobotYaml, "a robot file"},
      {"scenario_yaml", RunScenarioYaml, "a scenario file (in scenarios/)"},
      {"sweep_yaml", RunSweepYaml, "a sweep file (in scenarios/sweeps/)"},
      {"bag", RunBag, "a ROS 2 bag file: MCAP or sqlite3 (.db3)"},
  };
  return entries;
}

const ReaderEntry* FindReaderEntry(std::string_view name) {
  for (const ReaderEntry& entry : ReaderEntries()) {
    if (entry.name == name) return &entry;
  }
  return nullptr;
}

ReaderResult RunReaderEntry(const ReaderEntry& entry, std::string_view data) {
  try {
    entry.run(data);
    return {};
  } catch (const ParseError& e) {
    return {ReaderOutcome::kRejected, e.what()};
  } catch (const ConfigError& e) {
    return {ReaderOutcome::kRejected, e.what()};
  }
}

std::string_view FirstPart(std::string_view data) { return data.substr(0, data.find('\0')); }

std::string_view SecondPart(std::string_view data) {
  const std::size_t nul = data.find('\0');
  return nul == std::string_view::npos ? std::string_view() : data.substr(nul + 1);
}

}  // namespace slamrig::fuzz
