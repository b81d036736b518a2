// Reader for the UCSD ECE276A project 2 robot logs (Encoders/Imu/Hokuyo/Kinect .npz with the
// dataRGBD images, and the csv.gz conversions in shared/datasets/ece276a_pr2_partial, whose
// SOURCE.md gives the layouts).
#include "slam/io/ece276a_reader.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "slam/io/kinect_disparity.h"
#include "slam/io/line_reader.h"
#include "slam/io/npz_reader.h"
#include "slam/types/error.h"

namespace slamrig::slam {
namespace {

namespace fs = std::filesystem;

// Columns of a csv.gz file (header lines starting with '#' skipped), all rows the same width.
std::vector<std::vector<double>> ReadCsv(const std::string& path, std::size_t columns) {
  LineReader reader(path);
  std::vector<std::vector<double>> rows;
  std::string_view line;
  while (reader.Next(&line)) {
    if (line.empty() || line.front() == '#') continue;
    std::vector<double> row;
    std::size_t start = 0;
    while (start <= line.size()) {
      const std::size_t comma = std::min(line.find(',', start), line.size());
      const std::string field(line.substr(start, comma - start));
      char* end = nullptr;
      const double v = std::strtod(field.c_str(), &end);
      if (field.empty() || end != field.c_str() + field.size() || !std::isfinite(v)) {
        throw ParseError(path + ":" + std::to_string(reader.line_number()) + ": column " +
                         std::to_string(row.size() + 1) + ": expected a finite number, got '" +
                         field + "'");
      }
      row.push_back(v);
      start = comma + 1;
    }
    // Column 1 is the unix time in every layout; Time holds int64 nanoseconds (+-292 years).
    if (!(std::abs(row[0]) <= 9.2e9)) {
      throw ParseError(path + ":" + std::to_string(reader.line_number()) + ": column 1: time " +
                       std::to_string(row[0]) + " s is outside +-9.2e9 s");
    }
    if (row.size() != columns) {
      throw ParseError(path + ":" + std::to_string(reader.line_number()) + ": expected " +
                       std::to_string(columns) + " columns, got " + std::to_string(row.size()));
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

const NpyArray& Array(const std::map<std::string, NpyArray>& arrays, const std::string& key,
                      const std::string& path) {
  const auto it = arrays.find(key);
  if (it == arrays.end()) throw ParseError(path + ": no array '" + key + "'");
  return it->second;
}

// A (rows x n) array, checked; element (r, i) at values[r * n + i].
const NpyArray& Matrix(const std::map<std::string, NpyArray>& arrays, const std::string& key,
                       std::size_t rows, std::size_t n, const std::string& path) {
  const NpyArray& a = Array(arrays, key, path);
  if (a.shape.size() != 2 || a.shape[0] != rows || a.shape[1] != n) {
    std::ostringstream s;
    s << path << ": " << key << ": expected shape (" << rows << ", " << n << ")";
    throw ParseError(s.str());
  }
  return a;
}

double Scalar(const std::map<std::string, NpyArray>& arrays, const std::string& key,
              const std::string& path) {
  const NpyArray& a = Array(arrays, key, path);
  if (a.size() != 1 || !std::isfinite(a.values[0])) {
    throw ParseError(path + ": " + key + ": expected one finite number");
  }
  return a.values[0];
}

std::vector<double> Stamps(const std::map<std::string, NpyArray>& arrays, const std::string& key,
                           const std::string& path) {
  const NpyArray& a = Array(arrays, key, path);
  if (a.shape.size() != 1) throw ParseError(path + ": " + key + ": expected a 1-D array");
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!std::isfinite(a.values[i])) {
      throw ParseError(path + ": " + key + "[" + std::to_string(i) + "]: not a finite time");
    }
  }
  return a.values;
}

void CheckFinite(double v, const std::string& path, const std::string& what, std::size_t index) {
  if (!std::isfinite(v)) {
    throw ParseError(path + ": " + what + " column " + std::to_string(index) + ": not finite");
  }
}

// Time holds int64 nanoseconds: stamps past about +-292 years from 1970 cannot be represented.
void CheckStamp(double t, const std::string& path, std::size_t index) {
  if (!(std::abs(t) <= 9.2e9)) {
    throw ParseError(path + ": time_stamps[" + std::to_string(index) + "]: " + std::to_string(t) +
                     " s is outside +-9.2e9 s");
  }
}

// The stamps `key` of `path`, each representable and none earlier than the one before.
std::vector<double> SortedStamps(const std::map<std::string, NpyArray>& arrays,
                                 const std::string& key, const std::string& path) {
  const std::vector<double> t = Stamps(arrays, key, path);
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (!(std::abs(t[i]) <= 9.2e9)) {
      throw ParseError(path + ": " + key + "[" + std::to_string(i) + "]: " + std::to_string(t[i]) +
                       " s is outside +-9.2e9 s");
    }
    if (i > 0 && t[i] < t[i - 1]) {
      throw ParseError(path + ": " + key + "[" + std::to_string(i) + "]: earlier than the stamp " +
                       "before it; images are indexed in time order");
    }
  }
  return t;
}

// One image of the Kinect layout: `type` (CV_8UC3 or CV_16UC1), of the size of the first one read
// (*width, *height; 0 until then). `what` says which frame it is.
cv::Mat ReadKinectImage(const std::string& path, int type, const std::string& what, int* width,
                        int* height) {
  std::error_code error;
  if (!fs::is_regular_file(path, error)) throw ParseError(path + ": missing (" + what + ")");
  cv::Mat image = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (image.empty()) {
    throw ParseError(path + ": not an image OpenCV can read, corrupt or truncated (" + what + ")");
  }
  if (image.type() != type) {
    throw ParseError(path + ": expected " +
                     std::string(type == CV_16UC1 ? "a 16-bit one-channel" : "an 8-bit colour") +
                     " PNG, got " + std::to_string(image.channels()) + " channel(s) of " +
                     std::to_string(8 * image.elemSize1()) + " bits (" + what + ")");
  }
  if (*width == 0) {
    *width = image.cols;
    *height = image.rows;
  } else if (image.cols != *width || image.rows != *height) {
    throw ParseError(path + ": " + std::to_string(image.cols) + " x " + std::to_string(image.rows) +
                     " pixels, the frames before it " + std::to_string(*width) + " x " +
                     std::to_string(*height) + " (" + what + ")");
  }
  return image;
}

bool IsNpz(const std::string& path) { return fs::path(path).extension() == ".npz"; }

// The dataset number and folder of a path, e.g. ("DIR", "20") for DIR/Encoders20.npz or DIR/20.
bool SplitDataset(const std::string& path, std::string* dir, std::string* number) {
  const fs::path p(path);
  std::string name = p.filename().string();
  for (const char* suffix : {".csv.gz", ".npz"}) {
    const std::string s = suffix;
    if (name.size() > s.size() && name.compare(name.size() - s.size(), s.size(), s) == 0) {
      name.resize(name.size() - s.size());
    }
  }
  std::size_t digits = name.size();
  while (digits > 0 && std::isdigit(static_cast<unsigned char>(name[digits - 1]))) --digits;
  if (digits == name.size()) return false;
  std::string prefix = name.substr(0, digits);
  std::transform(prefix.begin(), prefix.end(), prefix.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  if (!prefix.empty() && prefix != "encoders" && prefix != "imu" && prefix != "hokuyo" &&
      prefix != "kinect")
    return false;
  *dir = p.has_parent_path() ? p.parent_path().string() : ".";
  *number = name.substr(digits);
  return true;
}

std::string FindOne(const std::string& dir, const std::string& npz, const std::string& csv) {
  for (const std::string& name : {npz, csv}) {
    if (name.empty()) continue;
    const fs::path candidate = fs::path(dir) / name;
    if (fs::exists(candidate)) return candidate.string();
  }
  return "";
}

// A record with its sort key: time, then encoders/IMU before a scan, a scan before a frame, of
// the same stamp.
struct KeyedRecord {
  double time_s;
  int order;
  Record record;
};

// Encoders: counts (4, N) [FR, FL, RR, RL] since the previous reading.
void ReadEncoders(const std::string& path, std::vector<KeyedRecord>* keyed) {
  std::vector<double> t;
  std::vector<std::array<double, 4>> counts;
  if (IsNpz(path)) {
    const auto arrays = ReadNpz(path);
    t = Stamps(arrays, "time_stamps", path);
    const NpyArray& c = Matrix(arrays, "counts", 4, t.size(), path);
    for (std::size_t i = 0; i < t.size(); ++i) {
      counts.push_back({c.values[i], c.values[t.size() + i], c.values[2 * t.size() + i],
                        c.values[3 * t.size() + i]});
    }
  } else {
    for (const auto& row : ReadCsv(path, 5)) {
      t.push_back(row[0]);
      counts.push_back({row[1], row[2], row[3], row[4]});
    }
  }
  for (std::size_t i = 0; i < t.size(); ++i) {
    CheckStamp(t[i], path, i);
    for (int k = 0; k < 4; ++k) {
      CheckFinite(counts[i][static_cast<std::size_t>(k)], path, "counts", i);
    }
    const auto tick = [&](int k) {
      return static_cast<std::int32_t>(std::lround(counts[i][static_cast<std::size_t>(k)]));
    };
    keyed->push_back(
        {t[i], 0, WheelTicks{Time::FromSeconds(t[i]), {tick(0), tick(2)}, {tick(1), tick(3)}}});
  }
}

// IMU: angular velocity (3, N) rad/s and linear acceleration (3, N) in g.
void ReadImu(const std::string& path, double gravity_m_s2, std::vector<KeyedRecord>* keyed) {
  std::vector<double> t;
  std::vector<std::array<double, 6>> rows;  // ax ay az wx wy wz
  if (IsNpz(path)) {
    const auto arrays = ReadNpz(path);
    t = Stamps(arrays, "time_stamps", path);
    const NpyArray& w = Matrix(arrays, "angular_velocity", 3, t.size(), path);
    const NpyArray& a = Matrix(arrays, "linear_acceleration", 3, t.size(), path);
    const std::size_t n = t.size();
    for (std::size_t i = 0; i < n; ++i) {
      rows.push_back({a.values[i], a.values[n + i], a.values[2 * n + i], w.values[i],
                      w.values[n + i], w.values[2 * n + i]});
    }
  } else {
    for (const auto& row : ReadCsv(path, 7)) {
      t.push_back(row[0]);
      rows.push_back({row[1], row[2], row[3], row[4], row[5], row[6]});
    }
  }
  for (std::size_t i = 0; i < t.size(); ++i) {
    CheckStamp(t[i], path, i);
    for (std::size_t k = 0; k < 6; ++k) CheckFinite(rows[i][k], path, "imu", i);
    ImuSample imu;
    imu.time = Time::FromSeconds(t[i]);
    imu.linear_acceleration_m_s2 =
        Eigen::Vector3d(rows[i][0], rows[i][1], rows[i][2]) * gravity_m_s2;
    imu.angular_velocity_rad_s = Eigen::Vector3d(rows[i][3], rows[i][4], rows[i][5]);
    keyed->push_back({t[i], 0, imu});
  }
}

// Hokuyo: ranges (1081, N) float32 metres, scalar angle/range limits.
void ReadHokuyo(const std::string& path, const Ece276aReadOptions& options,
                std::vector<KeyedRecord>* keyed, std::vector<std::string>* notes) {
  const auto arrays = ReadNpz(path);
  const std::vector<double> t = Stamps(arrays, "time_stamps", path);
  const NpyArray& ranges = Array(arrays, "ranges", path);
  if (ranges.shape.size() != 2 || ranges.shape[1] != t.size() || ranges.shape[0] < 2) {
    throw ParseError(path + ": ranges: expected shape (beams, " + std::to_string(t.size()) + ")");
  }
  const std::size_t beams = ranges.shape[0];
  LaserScan prototype;
  prototype.angle_min_rad = Scalar(arrays, "angle_min", path);
  const double angle_max = Scalar(arrays, "angle_max", path);
  prototype.angle_increment_rad =
      arrays.count("angle_increment") > 0
          ? Scalar(arrays, "angle_increment", path)
          : (angle_max - prototype.angle_min_rad) / static_cast<double>(beams - 1);
  prototype.range_min_m = Scalar(arrays, "range_min", path);
  prototype.range_max_m = Scalar(arrays, "range_max", path);
  prototype.base_from_laser = options.base_from_lidar;
  int nan_beams = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    CheckStamp(t[i], path, i);
    LaserScan scan = prototype;
    scan.time = Time::FromSeconds(t[i]);
    scan.ranges_m.resize(beams);
    for (std::size_t b = 0; b < beams; ++b) {
      double r = ranges.values[b * t.size() + i];
      // NaN/inf readings are no-returns: counted, never passed on.
      if (!std::isfinite(r)) {
        r = prototype.range_max_m;
        ++nan_beams;
      }
      scan.ranges_m[b] = static_cast<float>(r);
    }
    keyed->push_back({t[i], 1, std::move(scan)});
  }
  if (nan_beams > 0) {
    notes->push_back(std::to_string(nan_beams) + " non-finite Hokuyo ranges read as no return");
  }
}

// Kinect: each disparity image with the RGB image nearest in time, as the reports pair them.
void ReadKinect(const Ece276aFiles& files, const Ece276aReadOptions& options,
                std::vector<KeyedRecord>* keyed, std::vector<std::string>* notes) {
  const std::string& path = files.kinect;
  if (options.kinect_every < 1) {
    throw ConfigError("kinect_every = " + std::to_string(options.kinect_every) + "; must be >= 1");
  }
  const auto arrays = ReadNpz(path);
  const std::vector<double> td = SortedStamps(arrays, "disparity_time_stamps", path);
  const std::vector<double> tr = SortedStamps(arrays, "rgb_time_stamps", path);
  if (tr.empty() && !td.empty()) {
    throw ParseError(path + ": rgb_time_stamps: empty, but there are disparity images");
  }
  const std::string n = std::to_string(files.dataset);
  const fs::path images(files.kinect_images);
  int width = 0, height = 0;
  double widest_gap_s = 0.0;
  std::size_t invalid = 0, frames = 0;
  for (std::size_t i = 0; i < td.size(); i += static_cast<std::size_t>(options.kinect_every)) {
    std::size_t j =
        static_cast<std::size_t>(std::lower_bound(tr.begin(), tr.end(), td[i]) - tr.begin());
    if (j == tr.size() || (j > 0 && td[i] - tr[j - 1] <= tr[j] - td[i])) --j;
    widest_gap_s = std::max(widest_gap_s, std::abs(tr[j] - td[i]));
    const std::string di = std::to_string(i + 1), rj = std::to_string(j + 1);
    const cv::Mat disparity = ReadKinectImage(
        (images / ("Disparity" + n) / ("disparity" + n + "_" + di + ".png")).string(), CV_16UC1,
        "disparity image " + di + " of " + path, &width, &height);
    const cv::Mat bgr = ReadKinectImage(
        (images / ("RGB" + n) / ("rgb" + n + "_" + rj + ".png")).string(), CV_8UC3,
        "RGB image " + rj + " of " + path + ", nearest disparity image " + di, &width, &height);
    RgbdFrame frame;
    frame.time = Time::FromSeconds(td[i]);
    frame.width = width;
    frame.height = height;
    frame.intrinsics = options.camera_intrinsics;
    frame.base_from_camera = options.base_from_camera;
    frame.depth_offset_x_m = options.depth_offset_x_m;
    cv::Mat rgb;
    cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
    frame.rgb.assign(rgb.data, rgb.data + rgb.total() * 3);
    frame.depth_m.resize(static_cast<std::size_t>(width) * height);
    for (int v = 0; v < height; ++v) {
      for (int u = 0; u < width; ++u) {
        const std::uint16_t d = disparity.at<std::uint16_t>(v, u);
        const double z = d >= kKinectNoDisparity ? 0.0 : KinectDepthFromDisparity(d);
        if (z == 0.0) ++invalid;
        frame.depth_m[static_cast<std::size_t>(v) * width + u] = static_cast<float>(z);
      }
    }
    keyed->push_back({td[i], 2, std::move(frame)});
    ++frames;
  }
  std::ostringstream note;
  note << frames << " Kinect frames (every " << options.kinect_every
       << ". disparity image, the nearest RGB image at most " << widest_gap_s * 1e3 << " ms away); "
       << invalid << " pixels without a depth reading";
  notes->push_back(note.str());
}

}  // namespace

bool LooksLikeEce276a(const std::string& path) {
  std::string dir, number;
  if (!SplitDataset(path, &dir, &number)) return false;
  return !FindOne(dir, "Encoders" + number + ".npz", "encoders" + number + ".csv.gz").empty();
}

Ece276aFiles FindEce276aFiles(const std::string& path) {
  std::string dir, number;
  if (!SplitDataset(path, &dir, &number)) {
    throw ParseError(
        path + ": not an ECE276A dataset (expected DIR/<number> or DIR/Encoders<number>.npz)");
  }
  Ece276aFiles files;
  files.encoders = FindOne(dir, "Encoders" + number + ".npz", "encoders" + number + ".csv.gz");
  if (files.encoders.empty()) {
    throw ParseError(path + ": no Encoders" + number + ".npz or encoders" + number + ".csv.gz in " +
                     dir);
  }
  files.imu = FindOne(dir, "Imu" + number + ".npz", "imu" + number + ".csv.gz");
  files.hokuyo = FindOne(dir, "Hokuyo" + number + ".npz", "");
  files.kinect = FindOne(dir, "Kinect" + number + ".npz", "");
  files.kinect_images = (fs::path(dir) / "dataRGBD").string();
  files.dataset = std::stoi(number.substr(0, 9));
  return files;
}

Dataset ReadEce276a(const Ece276aFiles& files, const Ece276aReadOptions& options) {
  std::vector<KeyedRecord> keyed;
  Dataset data;
  data.source = files.encoders;
  ReadEncoders(files.encoders, &keyed);
  if (!files.imu.empty()) ReadImu(files.imu, options.gravity_m_s2, &keyed);
  if (!files.hokuyo.empty()) {
    ReadHokuyo(files.hokuyo, options, &keyed, &data.notes);
  } else {
    data.notes.push_back("no Hokuyo file: encoders and IMU only (dead reckoning, no map)");
  }
  if (!files.kinect.empty()) ReadKinect(files, options, &keyed, &data.notes);
  std::stable_sort(keyed.begin(), keyed.end(), [](const KeyedRecord& a, const KeyedRecord& b) {
    return a.time_s != b.time_s ? a.time_s < b.time_s : a.order < b.order;
  });
  data.records.reserve(keyed.size());
  for (KeyedRecord& k : keyed) data.records.push_back(std::move(k.record));
  return data;
}

}  // namespace slamrig::slam
