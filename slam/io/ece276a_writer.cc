// Writer of the UCSD ECE276A project 2 layout (see ece276a_reader.cc for the reading side).
#include "slam/io/ece276a_writer.h"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "slam/io/atomic_file.h"
#include "slam/io/kinect_disparity.h"
#include "slam/io/npz_writer.h"
#include "slam/types/error.h"

namespace slamrig::slam {
namespace {

namespace fs = std::filesystem;

std::string EncodePng(const cv::Mat& image, const std::string& path) {
  std::vector<unsigned char> bytes;
  if (!cv::imencode(".png", image, bytes)) throw OutputError(path + ": cannot encode PNG");
  return std::string(bytes.begin(), bytes.end());
}

// Rows of a (rows.size(), n) matrix, C order.
std::vector<double> Flatten(const std::vector<std::vector<double>>& rows) {
  std::vector<double> out;
  for (const auto& row : rows) out.insert(out.end(), row.begin(), row.end());
  return out;
}

void RemoveAll(const std::string& path) {
  std::error_code error;
  fs::remove_all(path, error);
  if (error) throw OutputError(path + ": cannot remove: " + error.message());
}

}  // namespace

Ece276aSink::Ece276aSink(std::string dir, Ece276aWriteOptions options)
    : dir_(std::move(dir)), options_(options) {
  // Partial folders left by a run that was killed go; the first frame makes new ones.
  const std::string n = std::to_string(options_.dataset);
  RemoveAll(Path("dataRGBD/RGB" + n + ".partial"));
  RemoveAll(Path("dataRGBD/Disparity" + n + ".partial"));
}

Ece276aSink::~Ece276aSink() {
  if (committed_) return;
  const std::string n = std::to_string(options_.dataset);
  std::error_code ignored;  // a destructor cannot report; the folders are only partial output
  fs::remove_all(Path("dataRGBD/RGB" + n + ".partial"), ignored);
  fs::remove_all(Path("dataRGBD/Disparity" + n + ".partial"), ignored);
}

std::string Ece276aSink::Path(const std::string& name) const {
  return (fs::path(dir_) / name).string();
}

void Ece276aSink::Add(const Record& record, const GroundTruthPose* /*truth*/) {
  if (const auto* ticks = std::get_if<WheelTicks>(&record)) {
    const auto side = [&](const std::vector<std::int32_t>& t, const char* name) {
      if (t.empty() || t.size() > 2) {
        throw ConfigError("ECE276A layout: " + std::string(name) + " side has " +
                          std::to_string(t.size()) + " wheels; the Encoders file holds 1 or 2");
      }
      return std::pair<double, double>(t.front(), t.back());
    };
    const auto [fr, rr] = side(ticks->right_ticks, "right");
    const auto [fl, rl] = side(ticks->left_ticks, "left");
    encoder_t_.push_back(ticks->time.seconds());
    counts_[0].push_back(fr);
    counts_[1].push_back(fl);
    counts_[2].push_back(rr);
    counts_[3].push_back(rl);
  } else if (const auto* imu = std::get_if<ImuSample>(&record)) {
    imu_t_.push_back(imu->time.seconds());
    for (int k = 0; k < 3; ++k) {
      gyro_[k].push_back(imu->angular_velocity_rad_s[k]);
      accel_g_[k].push_back(imu->linear_acceleration_m_s2[k] / options_.gravity_m_s2);
    }
  } else if (const auto* scan = std::get_if<LaserScan>(&record)) {
    if (scan_t_.empty()) {
      beams_ = scan->ranges_m.size();
      angle_min_ = scan->angle_min_rad;
      angle_increment_ = scan->angle_increment_rad;
      range_min_ = scan->range_min_m;
      range_max_ = scan->range_max_m;
    } else if (scan->ranges_m.size() != beams_ || scan->angle_min_rad != angle_min_ ||
               scan->angle_increment_rad != angle_increment_ || scan->range_min_m != range_min_ ||
               scan->range_max_m != range_max_) {
      throw ConfigError("ECE276A layout: scan " + std::to_string(scan_t_.size() + 1) +
                        " changes the beam count, angles or range limits; the Hokuyo file "
                        "holds one geometry");
    }
    scan_t_.push_back(scan->time.seconds());
    ranges_.insert(ranges_.end(), scan->ranges_m.begin(), scan->ranges_m.end());
  } else if (const auto* frame = std::get_if<RgbdFrame>(&record)) {
    const std::string n = std::to_string(options_.dataset);
    const std::string k = std::to_string(frame_t_.size() + 1);
    const std::string rgb_path = Path("dataRGBD/RGB" + n + ".partial/rgb" + n + "_" + k + ".png");
    const std::string disparity_path =
        Path("dataRGBD/Disparity" + n + ".partial/disparity" + n + "_" + k + ".png");
    if (frame_t_.empty()) {
      for (const std::string& sub : {"RGB" + n, "Disparity" + n}) {
        const std::string partial = Path("dataRGBD/" + sub + ".partial");
        std::error_code error;
        fs::create_directories(partial, error);
        if (error) throw OutputError(partial + ": cannot create: " + error.message());
      }
    }
    const std::size_t pixels = static_cast<std::size_t>(frame->width) * frame->height;
    if (frame->width <= 0 || frame->height <= 0 || frame->rgb.size() != 3 * pixels ||
        frame->depth_m.size() != pixels) {
      throw ConfigError("ECE276A layout: RGB-D frame " + k + " has inconsistent image sizes");
    }
    cv::Mat3b rgb(frame->height, frame->width);
    std::memcpy(rgb.data, frame->rgb.data(), frame->rgb.size());
    cv::Mat bgr;
    cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
    cv::Mat_<std::uint16_t> disparity(frame->height, frame->width);
    for (int v = 0; v < frame->height; ++v) {
      for (int u = 0; u < frame->width; ++u) {
        const double z = frame->depth_m[static_cast<std::size_t>(v) * frame->width + u];
        std::uint16_t d = kKinectNoDisparity;
        if (z > 0.0) {
          const double raw = std::round(KinectDisparityFromDepth(z));
          if (raw >= 0.0 && raw < kKinectNoDisparity) d = static_cast<std::uint16_t>(raw);
        }
        disparity(v, u) = d;
      }
    }
    WriteFileAtomically(rgb_path, EncodePng(bgr, rgb_path));
    WriteFileAtomically(disparity_path, EncodePng(disparity, disparity_path));
    frame_t_.push_back(frame->time.seconds());
  }
  // OdometryPose: the layout has no odometry file (the reports integrate the encoders).
}

void Ece276aSink::Commit() {
  if (committed_) return;
  const std::string n = std::to_string(options_.dataset);
  // A stream without records has no file: one an earlier run left in the folder goes.
  const auto write = [&](const std::string& name, const std::vector<NpzArray>& arrays) {
    const std::string path = Path(name + n + ".npz");
    if (arrays.empty()) {
      RemoveAll(path);
      return;
    }
    try {
      WriteFileAtomically(path, MakeNpz(arrays));
    } catch (const std::invalid_argument& e) {
      throw OutputError(path + ": " + e.what());
    }
    files_.push_back(path);
  };
  if (encoder_t_.empty()) {
    write("Encoders", {});
  } else {
    write("Encoders", {{"counts", "<i4", {4, encoder_t_.size()}, Flatten(counts_)},
                       {"time_stamps", "<f8", {encoder_t_.size()}, encoder_t_}});
  }
  if (imu_t_.empty()) {
    write("Imu", {});
  } else {
    write("Imu", {{"angular_velocity", "<f8", {3, imu_t_.size()}, Flatten(gyro_)},
                  {"linear_acceleration", "<f8", {3, imu_t_.size()}, Flatten(accel_g_)},
                  {"time_stamps", "<f8", {imu_t_.size()}, imu_t_}});
  }
  if (scan_t_.empty()) {
    write("Hokuyo", {});
  } else {
    const std::size_t scans = scan_t_.size();
    std::vector<double> ranges(beams_ * scans);
    for (std::size_t i = 0; i < scans; ++i) {
      for (std::size_t b = 0; b < beams_; ++b) ranges[b * scans + i] = ranges_[i * beams_ + b];
    }
    const double angle_max = angle_min_ + static_cast<double>(beams_ - 1) * angle_increment_;
    write("Hokuyo", {{"angle_increment", "<f8", {}, {angle_increment_}},
                     {"angle_max", "<f8", {}, {angle_max}},
                     {"angle_min", "<f8", {}, {angle_min_}},
                     {"range_max", "<f8", {}, {range_max_}},
                     {"range_min", "<f8", {}, {range_min_}},
                     {"ranges", "<f4", {beams_, scans}, std::move(ranges)},
                     {"time_stamps", "<f8", {scans}, scan_t_}});
  }
  // The image folders take their final names before the npz that indexes them appears.
  for (const std::string& sub : {"RGB" + n, "Disparity" + n}) {
    const std::string final_dir = Path("dataRGBD/" + sub);
    RemoveAll(final_dir);
    if (frame_t_.empty()) continue;
    std::error_code error;
    fs::rename(final_dir + ".partial", final_dir, error);
    if (error)
      throw OutputError(final_dir + ": cannot move the images in place: " + error.message());
    files_.push_back(final_dir);
  }
  if (frame_t_.empty()) {
    write("Kinect", {});
    std::error_code ignored;  // dataRGBD itself only if nothing else (another dataset) is in it
    fs::remove(Path("dataRGBD"), ignored);
  } else {
    write("Kinect", {{"disparity_time_stamps", "<f8", {frame_t_.size()}, frame_t_},
                     {"rgb_time_stamps", "<f8", {frame_t_.size()}, frame_t_}});
  }
  committed_ = true;
}

}  // namespace slamrig::slam
