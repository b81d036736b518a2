// `slamrig map LOG --out DIR`: the occupancy map of a log from its logged (or true) poses.

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>

#include "apps/cli_args.h"
#include "apps/commands.h"
#include "slam/grid/occupancy_grid.h"
#include "slam/io/atomic_file.h"
#include "slam/io/carmen_reader.h"
#include "slam/io/log_reader.h"
#include "slam/io/map_image.h"
#include "slam/io/map_server.h"
#include "slam/io/tum_io.h"
#include "slam/types/error.h"
#include "slam/types/format.h"

namespace slamrig::app {
namespace {

using slam::CarmenLog;
using slam::OccupancyGrid;

std::string Join(const std::map<std::string, int>& counts) {
  std::string out;
  for (const auto& [reason, n] : counts) {
    out += (out.empty() ? "" : ", ") + std::to_string(n) + " " + reason;
  }
  return out;
}

}  // namespace

int RunMapCommand(const std::vector<std::string>& args) {
  std::string log_path, out_dir, poses = "auto";
  bool lenient = false;
  slam::OccupancyGridOptions grid_options;
  ArgParser parser("slamrig map", "LOG --out DIR [options]",
                   "Builds the occupancy grid of a CARMEN log (plain or .gz) from the poses it\n"
                   "carries and writes map.pgm + map.yaml (ROS map_server), map.png (the map with\n"
                   "the trajectory) and trajectory.tum (the poses used, one per scan).");
  parser.AddPositional("LOG", "CARMEN log; a path, or relative to SLAMRIG_DATA_DIR", &log_path);
  parser.AddOption("out", "DIR", "output folder (created)", &out_dir);
  parser.AddOption("resolution", "M", "cell size in metres", &grid_options.resolution_m);
  parser.AddOption("max-range", "M", "returns beyond this are treated as no return",
                   &grid_options.max_range_m);
  parser.AddOption("poses", "SOURCE",
                   "auto (TRUEPOS when present, else logged), logged (the laser line's pose) or "
                   "truth (TRUEPOS, interpolated at scan time)",
                   &poses);
  parser.AddFlag("lenient", "skip and count malformed lines instead of failing", &lenient);
  if (!parser.Parse(args)) return 0;
  if (out_dir.empty()) throw ConfigError("slamrig map: --out DIR is required");
  if (poses != "auto" && poses != "logged" && poses != "truth") {
    throw ConfigError("slamrig map: --poses: expected auto, logged or truth, got '" + poses + "'");
  }
  for (const std::string& e : grid_options.Validate()) {
    throw ConfigError("slamrig map: " + e);
  }

  // Read everything before creating any output, so bad input leaves nothing behind.
  const auto start = std::chrono::steady_clock::now();
  slam::CarmenReadOptions read_options;
  read_options.lenient = lenient;
  const CarmenLog log = slam::ReadCarmenLog(slam::ResolveLogPath(log_path), read_options);
  if (log.scans.empty())
    throw ParseError(log.path + ": no laser scans (FLASER, ROBOTLASER1, ...) to map");
  const bool use_truth = poses == "truth" || (poses == "auto" && !log.true_poses.empty());
  if (use_truth && log.true_poses.empty()) {
    throw ParseError(log.path + ": --poses truth, but the log has no TRUEPOS lines");
  }
  Trajectory truth;
  for (const auto& t : log.true_poses) truth.Append(t.time, t.map_from_base);

  OccupancyGrid grid(grid_options);
  Trajectory used;
  std::map<std::string, int> skipped;
  int beams = 0, hits = 0;
  for (const slam::CarmenScan& s : log.scans) {
    std::optional<Pose2> pose;
    if (use_truth) {
      pose = truth.Interpolate(s.scan.time);
      if (!pose) {
        ++skipped["outside the TRUEPOS time span"];
        continue;
      }
    } else if (s.has_pose) {
      pose = s.logged_pose;
    } else {
      ++skipped["without a pose (RAWLASER)"];
      continue;
    }
    hits += grid.InsertScan(s.scan, *pose);
    beams += static_cast<int>(s.scan.ranges_m.size());
    used.Append(s.scan.time, *pose);
  }
  if (used.empty())
    throw ParseError(log.path + ": no scan could be placed (" + Join(skipped) + ")");
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  std::filesystem::create_directories(out_dir);
  const std::string dir = out_dir + "/";
  slam::WriteMapServerMap(grid, dir + "map");
  slam::MapImageOptions image_options;
  image_options.title = std::filesystem::path(log.path).filename().string() + " at " +
                        Fixed(grid.resolution(), 3) + " m";
  slam::WriteMapPng(dir + "map.png", grid,
                    {{&used, use_truth ? "TRUEPOS trajectory" : "logged trajectory", 200, 60, 0}},
                    image_options);
  slam::WriteTum(dir + "trajectory.tum", used);

  std::string line = std::filesystem::path(log.path).filename().string() + ": " +
                     std::to_string(used.size()) + " scans mapped";
  if (!skipped.empty()) line += ", skipped " + Join(skipped);
  if (!log.stats.skipped.empty()) line += "; lines skipped: " + Join(log.stats.skipped);
  if (!log.stats.unknown_messages.empty())
    line += "; unknown messages: " + Join(log.stats.unknown_messages);
  line += "; " + std::to_string(hits) + " hits of " + std::to_string(beams) + " beams; map " +
          std::to_string(grid.width()) + "x" + std::to_string(grid.height()) + " cells at " +
          Fixed(grid.resolution(), 3) + " m; " + Fixed(seconds, 2) + " s -> " + out_dir;
  std::puts(line.c_str());
  for (const std::string& note : log.notes) std::printf("  note: %s\n", note.c_str());
  return 0;
}

}  // namespace slamrig::app
