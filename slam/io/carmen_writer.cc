#include "slam/io/carmen_writer.h"

#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "slam/types/error.h"

namespace slamrig::slam {
namespace {

// Numbers are written in their shortest form that reads back exactly (std::to_chars): a log
// read back gives bit-identical records, and formatting costs a fraction of printf's.
template <typename T>
void Append(std::string* out, T value) {
  char buffer[32];
  buffer[0] = ' ';
  const auto end = std::to_chars(buffer + 1, buffer + sizeof(buffer), value).ptr;
  out->append(buffer, end);
}

void AppendPose(std::string* out, const Pose2& p) {
  Append(out, p.x());
  Append(out, p.y());
  Append(out, p.theta());
}

constexpr const char* kHost = "slamrig";
constexpr std::size_t kFlushBytes = 1 << 20;

}  // namespace

CarmenWriter::CarmenWriter(std::string path)
    : path_(std::move(path)), tmp_path_(path_ + ".tmp" + std::to_string(::getpid())) {
  std::FILE* f = std::fopen(tmp_path_.c_str(), "wb");
  if (f == nullptr) throw OutputError(path_ + ": cannot write: " + std::strerror(errno));
  file_ = f;
  buffer_.reserve(2 * kFlushBytes);
  buffer_ += "# CARMEN log written by slamrig\n";
  buffer_ += "# message formats defined: PARAM ODOM ROBOTLASER1 TRUEPOS\n";
}

CarmenWriter::~CarmenWriter() {
  if (file_ != nullptr) {
    std::fclose(static_cast<std::FILE*>(file_));
    std::remove(tmp_path_.c_str());
  }
}

void CarmenWriter::EndLine() {
  if (file_ == nullptr) throw std::logic_error("CarmenWriter used after Commit()");
  buffer_ += '\n';
  if (buffer_.size() >= kFlushBytes) Flush();
}

void CarmenWriter::Flush() {
  auto* f = static_cast<std::FILE*>(file_);
  if (std::fwrite(buffer_.data(), 1, buffer_.size(), f) != buffer_.size()) {
    throw OutputError(path_ + ": write failed: " + std::strerror(errno));
  }
  buffer_.clear();
}

void CarmenWriter::Stamp(Time time) {
  const double t = time.seconds();
  Append(&buffer_, t);
  buffer_ += ' ';
  buffer_ += kHost;
  Append(&buffer_, t);
}

void CarmenWriter::WriteParam(const std::string& key, const std::string& value) {
  buffer_ += "PARAM " + key + " " + value + " " + kHost + " 0";
  EndLine();
}

void CarmenWriter::WriteOdometry(const OdometryPose& odom, double tv_m_s, double rv_rad_s) {
  buffer_ += "ODOM";
  AppendPose(&buffer_, odom.odom_from_base);
  Append(&buffer_, tv_m_s);
  Append(&buffer_, rv_rad_s);
  Append(&buffer_, 0.0);
  Stamp(odom.time);
  EndLine();
}

void CarmenWriter::WriteLaser(const LaserScan& scan, const Pose2& odom_from_base_at_scan) {
  buffer_ += "ROBOTLASER1 0";
  const double n = static_cast<double>(scan.ranges_m.size());
  Append(&buffer_, scan.angle_min_rad);
  Append(&buffer_, scan.angle_increment_rad * (n > 0 ? n - 1 : 0));  // field of view
  Append(&buffer_, scan.angle_increment_rad);
  Append(&buffer_, scan.range_max_m);
  buffer_ += " 0.01 0";
  Append(&buffer_, scan.ranges_m.size());
  for (const float r : scan.ranges_m) Append(&buffer_, r);
  buffer_ += " 0";  // no remissions
  AppendPose(&buffer_, odom_from_base_at_scan * scan.base_from_laser);
  AppendPose(&buffer_, odom_from_base_at_scan);
  buffer_ += " 0 0 0 0 0";  // tv rv forward_safety side_safety turn_axis
  Stamp(scan.time);
  EndLine();
}

void CarmenWriter::WriteTruePos(const GroundTruthPose& truth, const Pose2& odom_from_base) {
  buffer_ += "TRUEPOS";
  AppendPose(&buffer_, truth.map_from_base);
  AppendPose(&buffer_, odom_from_base);
  Stamp(truth.time);
  EndLine();
}

void CarmenWriter::Commit() {
  auto* f = static_cast<std::FILE*>(file_);
  if (f == nullptr) throw std::logic_error("CarmenWriter committed twice");
  Flush();
  file_ = nullptr;
  const bool ok = std::fflush(f) == 0;
  const bool closed = std::fclose(f) == 0;
  const std::string reason = std::strerror(errno);
  std::error_code ec;
  if (ok && closed) std::filesystem::rename(tmp_path_, path_, ec);
  if (!ok || !closed || ec) {
    std::remove(tmp_path_.c_str());
    throw OutputError(path_ + ": cannot finish writing the log: " + (ec ? ec.message() : reason));
  }
}

}  // namespace slamrig::slam
