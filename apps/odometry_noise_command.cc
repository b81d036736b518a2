// `slamrig odometry-noise LOG`: a log's own odometry error per scan against its reference, as the
// figures `--perturb odometry.noise_per_m=...` takes.

#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "apps/cli_args.h"
#include "apps/commands.h"
#include "apps/topic_flags.h"
#include "slam/io/log_perturbation.h"
#include "slam/io/log_reader.h"
#include "slam/types/error.h"
#include "slam/types/validation.h"

namespace slamrig::app {

int RunOdometryNoiseCommand(const std::vector<std::string>& args) {
  std::string log_path, odometry = "auto";
  std::vector<std::string> perturb_flags, topic_flags;
  std::uint64_t seed = 1;
  bool lenient = false;
  slam::OdometryNoiseSpacing spacing;
  ArgParser parser(
      "slamrig odometry-noise", "LOG [options]",
      "Measures a log's odometry against its reference (one reference pose per scan, as the\n"
      "corrected CARMEN logs have): per scan pair, the odometry increment u between the scans\n"
      "against the reference's g. Prints one line: scans, path, the RMS translation and rotation\n"
      "error per scan, the noise_per_m and noise_per_rad that give the same mean squared error\n"
      "under --perturb's model (per-axis sigma = noise_per_m |t|, sigma = noise_per_rad |theta|)\n"
      "and the systematic scale; then the reference's total turn, the systematic rotation scale\n"
      "and the rotation error per metre travelled and per radian turned (a least-squares split).\n"
      "Adding independent noise k times the log's own figures makes\n"
      "the total sqrt(1 + k^2) times the own; for a total of N times, add sqrt(N^2 - 1) times.\n"
      "--every-m / --every-rad compare only the scans at which the reference has moved that far\n"
      "or turned that much since the last one compared (a simulated log at the spacing of a\n"
      "corrected CARMEN log: --every-m 1 --every-rad 0.5).");
  parser.AddPositional("LOG", "log path; a path, or relative to SLAMRIG_DATA_DIR", &log_path);
  parser.AddOption("odometry", "SOURCE", "auto, wheel_ticks or poses", &odometry);
  parser.AddRepeated("perturb", "KEY=VALUE", "perturb the records first, as `slamrig slam` does",
                     &perturb_flags);
  parser.AddOption("seed", "N", "seed of --perturb", &seed);
  parser.AddOption("every-m", "M", "compare scans this far apart on the reference (0: all)",
                   &spacing.travel_m);
  parser.AddOption("every-rad", "RAD", "or turned this much (0: all)", &spacing.turn_rad);
  parser.AddFlag("lenient", "skip and count malformed CARMEN lines instead of failing", &lenient);
  parser.AddRepeated("topic", "KEY=NAME", "a ROS 2 bag's topic to read, e.g. scan=/front/scan",
                     &topic_flags);
  if (!parser.Parse(args)) return 0;
  slam::ScanSyncOptions sync;
  if (odometry == "wheel_ticks") {
    sync.source = slam::OdometrySource::kWheelTicks;
  } else if (odometry == "poses") {
    sync.source = slam::OdometrySource::kOdometryPoses;
  } else if (odometry != "auto") {
    throw ConfigError("slamrig odometry-noise: --odometry " + odometry +
                      ": expected auto, wheel_ticks or poses");
  }
  const slam::LogPerturbation perturbation = slam::LogPerturbationFromFlags(perturb_flags);
  slam::LogReadOptions read;
  read.lenient = lenient;
  read.topics = ParseTopicFlags("slamrig odometry-noise", topic_flags);
  slam::Dataset data = slam::ReadLog(slam::ResolveLogPath(log_path), read);
  slam::ApplyLogPerturbation(&data, perturbation, seed, sync.robot);
  sync.source = slam::ResolveOdometrySource(data.records, sync.source);
  for (const auto& [flag, value] :
       {std::pair{"--every-m", spacing.travel_m}, std::pair{"--every-rad", spacing.turn_rad}}) {
    if (!(value >= 0.0 && std::isfinite(value))) {
      throw ConfigError(std::string("slamrig odometry-noise: ") + flag + " " + FormatNumber(value) +
                        ": must be a finite number >= 0");
    }
  }
  const slam::OdometryNoiseMeasurement m = slam::MeasureOdometryNoise(data, sync, spacing);
  std::printf(
      "%s: scans %d, path %.1f m, per scan RMS %.4f m %.4f rad, noise_per_m %.4f, "
      "noise_per_rad %.4f, scale %.4f, turned %.1f rad, rotation_scale %.4f, "
      "rotation_per_m %.4f, rotation_per_rad %.4f\n",
      log_path.c_str(), m.increments + 1, m.path_m, m.rms_translation_m, m.rms_rotation_rad,
      m.noise_per_m, m.noise_per_rad, m.scale, m.turn_rad, m.rotation_scale, m.rotation_per_m,
      m.rotation_per_rad);
  return 0;
}

}  // namespace slamrig::app
