#pragma once

#include <string>
#include <vector>

#include "slam/io/dataset.h"
#include "slam/types/pose2.h"

namespace slamrig::slam {

/// The files of one ECE276A robot dataset (UCSD ECE276A project 2: encoders, IMU, Hokuyo).
struct Ece276aFiles {
  std::string encoders;  ///< Encoders<N>.npz or encoders<N>.csv.gz (required)
  std::string imu;       ///< Imu<N>.npz or imu<N>.csv.gz (empty: none)
  std::string hokuyo;    ///< Hokuyo<N>.npz (empty: none; the shared copy has no lidar)
};

/// How ECE276A logs are turned into records.
struct Ece276aReadOptions {
  /// The Hokuyo's mounting pose on base_link: 0.13323 m ahead of the rear axle's centre
  /// (RobotConfiguration.pdf: 298.33 mm lidar position minus half the 330.20 mm wheel base).
  Pose2 base_from_lidar{0.13323, 0.0, 0.0};
  double gravity_m_s2 = 9.80665;  ///< the IMU's accelerations are in g
};

/// Finds the files of a dataset from `path`: a dataset folder plus number ("DIR/20"), or any one
/// of its files ("DIR/Encoders20.npz", "DIR/imu21.csv.gz", "DIR/Hokuyo23.npz"). npz files win
/// over csv.gz. Throws ParseError when no encoder file is found.
Ece276aFiles FindEce276aFiles(const std::string& path);

/// True if `path` names an ECE276A dataset as FindEce276aFiles understands it.
bool LooksLikeEce276a(const std::string& path);

/// Reads a dataset (Ece276aFiles) into records merged in time order (scans after the encoder and
/// IMU records with the same stamp): encoder counts [FR, FL, RR, RL] become WheelTicks with right
/// {FR, RR} and left {FL, RL}; IMU rows become ImuSamples (rad/s, m/s^2); Hokuyo columns become
/// LaserScans. Times are unix seconds. There is no reference. Throws ParseError naming the file,
/// array and row for missing arrays, mismatched shapes or non-finite values.
Dataset ReadEce276a(const Ece276aFiles& files, const Ece276aReadOptions& options = {});

}  // namespace slamrig::slam
