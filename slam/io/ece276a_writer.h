#pragma once

#include <string>
#include <vector>

#include "slam/io/record_sink.h"

namespace slamrig::slam {

/// How a run is written in the ECE276A layout.
struct Ece276aWriteOptions {
  int dataset = 20;               ///< the <N> of the file names
  double gravity_m_s2 = 9.80665;  ///< the IMU file's accelerations are in g
};

/// Writes records in the file layout of the UCSD ECE276A project 2 data, the one the reports'
/// own Python reads (and ReadEce276a): below `dir`,
///  - Encoders<N>.npz: `counts` int32 (4, n) [FR, FL, RR, RL] ticks since the previous reading
///    (a robot with one wheel per side gives each side's count to both of its columns, so the
///    reports' (FR + RR) / 2 is that wheel's count), `time_stamps` float64 (n,);
///  - Imu<N>.npz: `angular_velocity` (3, n) rad/s, `linear_acceleration` (3, n) in g,
///    `time_stamps`;
///  - Hokuyo<N>.npz: `ranges` float32 (beams, n), scalars `angle_min`, `angle_max`,
///    `angle_increment`, `range_min`, `range_max`, `time_stamps`;
///  - Kinect<N>.npz: `rgb_time_stamps` and `disparity_time_stamps` (equal: one stamp per frame),
///    with dataRGBD/RGB<N>/rgb<N>_<k>.png (8-bit colour) and dataRGBD/Disparity<N>/
///    disparity<N>_<k>.png (16-bit raw disparity, k from 1): d = round((3.31 - 1.03 / depth) /
///    0.00304), the inverse of Wang's Eq. 18, and 2047 (kKinectNoDisparity) where there is no
///    reading or the depth is beyond what the 11-bit disparity holds.
/// Times are the records' seconds. The format has no place for the sensors' mounting, the lidar's
/// per-beam timing, the camera's intrinsics or odometry poses: the reader takes those from its
/// options, and OdometryPose records are not written. A file appears only for a stream that has
/// records. The images go to RGB<N>.partial and Disparity<N>.partial folders, renamed and the npz
/// files written at Commit(); a sink destroyed without Commit() removes its partial folders.
/// Throws OutputError naming a file that cannot be written, and ConfigError for records the
/// layout cannot hold (more than two wheels a side, scans of changing geometry).
class Ece276aSink : public RecordSink {
 public:
  Ece276aSink(std::string dir, Ece276aWriteOptions options = {});
  ~Ece276aSink() override;
  Ece276aSink(const Ece276aSink&) = delete;
  Ece276aSink& operator=(const Ece276aSink&) = delete;

  void Add(const Record& record, const GroundTruthPose* truth) override;
  void Commit() override;

  int encoder_readings() const { return static_cast<int>(encoder_t_.size()); }
  int imu_samples() const { return static_cast<int>(imu_t_.size()); }
  int scans() const { return static_cast<int>(scan_t_.size()); }
  int frames() const { return static_cast<int>(frame_t_.size()); }
  /// The files and folders Commit() wrote.
  const std::vector<std::string>& files() const { return files_; }

 private:
  std::string Path(const std::string& name) const;

  std::string dir_;
  Ece276aWriteOptions options_;
  bool committed_ = false;
  std::vector<double> encoder_t_;
  std::vector<std::vector<double>> counts_ = std::vector<std::vector<double>>(4);
  std::vector<double> imu_t_;
  std::vector<std::vector<double>> gyro_ = std::vector<std::vector<double>>(3);
  std::vector<std::vector<double>> accel_g_ = std::vector<std::vector<double>>(3);
  std::vector<double> scan_t_;
  std::vector<float> ranges_;  // scan after scan, beams_ each
  std::size_t beams_ = 0;
  double angle_min_ = 0.0, angle_increment_ = 0.0, range_min_ = 0.0, range_max_ = 0.0;
  std::vector<double> frame_t_;
  std::vector<std::string> files_;
};

}  // namespace slamrig::slam
