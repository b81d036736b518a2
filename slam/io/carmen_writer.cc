#include "slam/io/carmen_writer.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace slamrig::slam {
namespace {

void Append(std::string* out, double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), " %.17g", value);
  *out += buffer;
}

void AppendPose(std::string* out, const Pose2& p) {
  Append(out, p.x());
  Append(out, p.y());
  Append(out, p.theta());
}

constexpr const char* kHost = "slamrig";

}  // namespace

CarmenWriter::CarmenWriter(std::string path)
    : path_(std::move(path)), tmp_path_(path_ + ".tmp" + std::to_string(::getpid())) {
  std::FILE* f = std::fopen(tmp_path_.c_str(), "wb");
  if (f == nullptr) throw std::runtime_error(path_ + ": cannot write: " + std::strerror(errno));
  file_ = f;
  WriteLine("# CARMEN log written by slamrig");
  WriteLine("# message formats defined: PARAM ODOM ROBOTLASER1 TRUEPOS");
}

CarmenWriter::~CarmenWriter() {
  if (file_ != nullptr) {
    std::fclose(static_cast<std::FILE*>(file_));
    std::remove(tmp_path_.c_str());
  }
}

void CarmenWriter::WriteLine(const std::string& line) {
  auto* f = static_cast<std::FILE*>(file_);
  if (f == nullptr) throw std::logic_error("CarmenWriter used after Commit()");
  if (std::fwrite(line.data(), 1, line.size(), f) != line.size() || std::fputc('\n', f) == EOF) {
    throw std::runtime_error(path_ + ": write failed: " + std::strerror(errno));
  }
}

void CarmenWriter::Stamp(Time time) {
  char buffer[96];
  const double t = time.seconds();
  std::snprintf(buffer, sizeof(buffer), " %.17g %s %.17g", t, kHost, t);
  pending_ += buffer;
}

void CarmenWriter::WriteParam(const std::string& key, const std::string& value) {
  WriteLine("PARAM " + key + " " + value + " " + kHost + " 0");
}

void CarmenWriter::WriteOdometry(const OdometryPose& odom, double tv_m_s, double rv_rad_s) {
  pending_ = "ODOM";
  AppendPose(&pending_, odom.odom_from_base);
  Append(&pending_, tv_m_s);
  Append(&pending_, rv_rad_s);
  Append(&pending_, 0.0);
  Stamp(odom.time);
  WriteLine(pending_);
}

void CarmenWriter::WriteLaser(const LaserScan& scan, const Pose2& odom_from_base_at_scan) {
  pending_ = "ROBOTLASER1 0";
  const double n = static_cast<double>(scan.ranges_m.size());
  Append(&pending_, scan.angle_min_rad);
  Append(&pending_, scan.angle_increment_rad * (n > 0 ? n - 1 : 0));  // field of view
  Append(&pending_, scan.angle_increment_rad);
  Append(&pending_, scan.range_max_m);
  pending_ += " 0.01 0 " + std::to_string(scan.ranges_m.size());
  char buffer[24];
  for (const float r : scan.ranges_m) {
    std::snprintf(buffer, sizeof(buffer), " %.9g", static_cast<double>(r));
    pending_ += buffer;
  }
  pending_ += " 0";  // no remissions
  AppendPose(&pending_, odom_from_base_at_scan * scan.base_from_laser);
  AppendPose(&pending_, odom_from_base_at_scan);
  pending_ += " 0 0 0 0 0";  // tv rv forward_safety side_safety turn_axis
  Stamp(scan.time);
  WriteLine(pending_);
}

void CarmenWriter::WriteTruePos(const GroundTruthPose& truth, const Pose2& odom_from_base) {
  pending_ = "TRUEPOS";
  AppendPose(&pending_, truth.map_from_base);
  AppendPose(&pending_, odom_from_base);
  Stamp(truth.time);
  WriteLine(pending_);
}

void CarmenWriter::Commit() {
  auto* f = static_cast<std::FILE*>(file_);
  file_ = nullptr;
  const bool ok = std::fflush(f) == 0;
  const bool closed = std::fclose(f) == 0;
  std::error_code ec;
  if (ok && closed) std::filesystem::rename(tmp_path_, path_, ec);
  if (!ok || !closed || ec) {
    std::remove(tmp_path_.c_str());
    throw std::runtime_error(path_ + ": cannot finish writing the log");
  }
}

}  // namespace slamrig::slam
