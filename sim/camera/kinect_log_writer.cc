#include "sim/camera/kinect_log_writer.h"

#include <zlib.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "sim/camera/kinect_disparity.h"
#include "slam/io/atomic_file.h"

namespace slamrig::sim {
namespace {

constexpr std::uint16_t kNoReading = 2047;

void Put16(std::string* s, std::uint32_t v) {
  s->push_back(static_cast<char>(v & 0xff));
  s->push_back(static_cast<char>((v >> 8) & 0xff));
}

void Put32(std::string* s, std::uint32_t v) {
  Put16(s, v & 0xffff);
  Put16(s, v >> 16);
}

// One .npy (format 1.0) of a float64 vector: magic, header padded to a multiple of 64, data.
std::string MakeNpy(const std::vector<double>& values) {
  std::string header = "{'descr': '<f8', 'fortran_order': False, 'shape': (" +
                       std::to_string(values.size()) + ",), }";
  const std::size_t unpadded = 10 + header.size() + 1;
  header.append((64 - unpadded % 64) % 64, ' ');
  header.push_back('\n');
  std::string npy = "\x93NUMPY";
  npy.push_back('\x01');
  npy.push_back('\x00');
  Put16(&npy, static_cast<std::uint32_t>(header.size()));
  npy += header;
  for (double v : values) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &v, sizeof(bits));
    for (int b = 0; b < 8; ++b) npy.push_back(static_cast<char>((bits >> (8 * b)) & 0xff));
  }
  return npy;
}

std::string EncodePng(const cv::Mat& image, const std::string& path) {
  std::vector<unsigned char> bytes;
  if (!cv::imencode(".png", image, bytes)) throw std::runtime_error(path + ": cannot encode PNG");
  return std::string(bytes.begin(), bytes.end());
}

}  // namespace

std::string MakeNpz(const std::vector<std::pair<std::string, std::vector<double>>>& arrays) {
  // A stored (uncompressed) zip: local headers with data, then the central directory.
  constexpr std::uint32_t kDosDate = (0 << 9) | (1 << 5) | 1;  // 1980-01-01
  std::string zip, central;
  for (const auto& [name, values] : arrays) {
    const std::string file = name + ".npy";
    const std::string data = MakeNpy(values);
    const auto crc = static_cast<std::uint32_t>(
        crc32(0L, reinterpret_cast<const Bytef*>(data.data()), static_cast<uInt>(data.size())));
    const auto size = static_cast<std::uint32_t>(data.size());
    const auto offset = static_cast<std::uint32_t>(zip.size());
    Put32(&zip, 0x04034b50);
    Put16(&zip, 20);  // version needed
    Put16(&zip, 0);   // flags
    Put16(&zip, 0);   // stored
    Put16(&zip, 0);   // time
    Put16(&zip, kDosDate);
    Put32(&zip, crc);
    Put32(&zip, size);
    Put32(&zip, size);
    Put16(&zip, static_cast<std::uint32_t>(file.size()));
    Put16(&zip, 0);  // extra
    zip += file;
    zip += data;
    Put32(&central, 0x02014b50);
    Put16(&central, 20);  // made by
    Put16(&central, 20);  // needed
    Put16(&central, 0);
    Put16(&central, 0);
    Put16(&central, 0);
    Put16(&central, kDosDate);
    Put32(&central, crc);
    Put32(&central, size);
    Put32(&central, size);
    Put16(&central, static_cast<std::uint32_t>(file.size()));
    Put16(&central, 0);  // extra
    Put16(&central, 0);  // comment
    Put16(&central, 0);  // disk
    Put16(&central, 0);  // internal attributes
    Put32(&central, 0);  // external attributes
    Put32(&central, offset);
    central += file;
  }
  const auto central_offset = static_cast<std::uint32_t>(zip.size());
  zip += central;
  Put32(&zip, 0x06054b50);
  Put16(&zip, 0);
  Put16(&zip, 0);
  Put16(&zip, static_cast<std::uint32_t>(arrays.size()));
  Put16(&zip, static_cast<std::uint32_t>(arrays.size()));
  Put32(&zip, static_cast<std::uint32_t>(central.size()));
  Put32(&zip, central_offset);
  Put16(&zip, 0);
  return zip;
}

KinectLogWriter::KinectLogWriter(std::string dir, int dataset)
    : dir_(std::move(dir)), dataset_(dataset) {
  const std::string n = std::to_string(dataset_);
  for (const std::string& sub : {"dataRGBD/RGB" + n, "dataRGBD/Disparity" + n}) {
    std::error_code error;
    std::filesystem::create_directories(std::filesystem::path(dir_) / sub, error);
    if (error) throw std::runtime_error(dir_ + "/" + sub + ": " + error.message());
  }
}

void KinectLogWriter::Write(const RgbdFrame& frame) {
  const std::string n = std::to_string(dataset_);
  const std::string k = std::to_string(stamps_s_.size() + 1);
  const std::string rgb_path = dir_ + "/dataRGBD/RGB" + n + "/rgb" + n + "_" + k + ".png";
  const std::string disparity_path =
      dir_ + "/dataRGBD/Disparity" + n + "/disparity" + n + "_" + k + ".png";
  cv::Mat3b rgb(frame.height, frame.width);
  std::memcpy(rgb.data, frame.rgb.data(), frame.rgb.size());
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  cv::Mat_<std::uint16_t> disparity(frame.height, frame.width);
  for (int v = 0; v < frame.height; ++v) {
    for (int u = 0; u < frame.width; ++u) {
      const double z = frame.depth_m[static_cast<std::size_t>(v) * frame.width + u];
      std::uint16_t d = kNoReading;
      if (z > 0.0) {
        const double raw = std::round(KinectDisparityFromDepth(z));
        if (raw >= 0.0 && raw < kNoReading) d = static_cast<std::uint16_t>(raw);
      }
      disparity(v, u) = d;
    }
  }
  slam::WriteFileAtomically(rgb_path, EncodePng(bgr, rgb_path));
  slam::WriteFileAtomically(disparity_path, EncodePng(disparity, disparity_path));
  stamps_s_.push_back(frame.time.seconds());
}

void KinectLogWriter::Finish() {
  const std::string path = dir_ + "/Kinect" + std::to_string(dataset_) + ".npz";
  slam::WriteFileAtomically(
      path, MakeNpz({{"disparity_time_stamps", stamps_s_}, {"rgb_time_stamps", stamps_s_}}));
}

}  // namespace slamrig::sim
