#include "slam/io/map_server.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <system_error>

#include "slam/config/yaml_node.h"
#include "slam/io/atomic_file.h"
#include "slam/types/error.h"

namespace slamrig::slam {
namespace {

constexpr std::uint8_t kFreePixel = 254;
constexpr std::uint8_t kOccupiedPixel = 0;
constexpr std::uint8_t kUnknownPixel = 205;

// Bounding box of cells that are not unknown, in cells [x0, x1) x [y0, y1).
struct CellBox {
  int x0, y0, x1, y1;
};

CellBox ObservedBox(const OccupancyGrid& grid) {
  CellBox box{grid.width(), grid.height(), 0, 0};
  for (int y = 0; y < grid.height(); ++y) {
    for (int x = 0; x < grid.width(); ++x) {
      if (grid.LogOdds({x, y}) == 0.0f) continue;
      box.x0 = std::min(box.x0, x);
      box.y0 = std::min(box.y0, y);
      box.x1 = std::max(box.x1, x + 1);
      box.y1 = std::max(box.y1, y + 1);
    }
  }
  if (box.x1 <= box.x0) box = {0, 0, std::min(1, grid.width()), std::min(1, grid.height())};
  return box;
}

std::string FormatDouble(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.10g", v);
  return buffer;
}

// Reads a netpbm grey image (P5 binary or P2 ascii, maxval <= 255) into rows top to bottom.
cv::Mat ReadPgm(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ParseError(path + ": cannot open map image");
  std::string magic;
  in >> magic;
  if (magic != "P5" && magic != "P2")
    throw ParseError(path + ": not a PGM file (magic '" + magic + "')");
  auto next_int = [&](const char* field) {
    while (in >> std::ws && in.peek() == '#') {
      std::string comment;
      std::getline(in, comment);
    }
    long value = -1;
    if (!(in >> value) || value <= 0 || value > 65535) {
      throw ParseError(path + ": PGM header field " + field + " missing or out of range");
    }
    return static_cast<int>(value);
  };
  const int width = next_int("width");
  const int height = next_int("height");
  const int maxval = next_int("maxval");
  if (maxval > 255)
    throw ParseError(path + ": 16-bit PGM (maxval " + std::to_string(maxval) + ") not supported");
  // Every pixel takes at least one byte of the file (P5: one, P2: a digit): a header promising
  // more pixels than the file has bytes is refused before the image is allocated.
  const std::int64_t pixels = static_cast<std::int64_t>(width) * height;
  const std::streamoff header_end = in.tellg();
  in.seekg(0, std::ios::end);
  const std::streamoff left = in.tellg() - header_end;
  in.seekg(header_end);
  if (pixels > left) {
    throw ParseError(path + ": truncated PGM: expected " + std::to_string(pixels) +
                     " pixels, found " + std::to_string(std::max<std::streamoff>(left - 1, 0)) +
                     " bytes");
  }
  cv::Mat image(height, width, CV_8UC1);
  if (magic == "P5") {
    in.get();  // the single whitespace after maxval
    in.read(reinterpret_cast<char*>(image.data), static_cast<std::streamsize>(pixels));
    if (in.gcount() != static_cast<std::streamsize>(pixels)) {
      throw ParseError(path + ": truncated PGM: expected " + std::to_string(pixels) +
                       " pixels, found " + std::to_string(in.gcount()));
    }
  } else {
    for (std::int64_t i = 0; i < pixels; ++i) {
      int v = -1;
      if (!(in >> v) || v < 0 || v > maxval) {
        throw ParseError(path + ": pixel " + std::to_string(i) + " missing or out of range");
      }
      image.data[i] = static_cast<std::uint8_t>(v);
    }
  }
  if (maxval != 255) image.convertTo(image, CV_8UC1, 255.0 / maxval);
  return image;
}

}  // namespace

std::string WriteMapServerMap(const OccupancyGrid& grid, const std::string& base,
                              const MapServerWriteOptions& options) {
  const CellBox box = ObservedBox(grid);
  const int width = box.x1 - box.x0;
  const int height = box.y1 - box.y0;
  std::string pgm = "P5\n# slamrig occupancy map\n" + std::to_string(width) + " " +
                    std::to_string(height) + "\n255\n";
  const std::size_t header = pgm.size();
  pgm.resize(header + static_cast<std::size_t>(width) * height);
  for (int row = 0; row < height; ++row) {
    const int y = box.y1 - 1 - row;  // image rows go top (high y) to bottom
    for (int x = box.x0; x < box.x1; ++x) {
      std::uint8_t pixel = kUnknownPixel;
      if (grid.LogOdds({x, y}) != 0.0f) {
        const double p = grid.Probability({x, y});
        if (options.mode == "scale") {
          pixel = static_cast<std::uint8_t>(std::lround(255.0 * (1.0 - p)));
        } else if (p > options.occupied_thresh) {
          pixel = kOccupiedPixel;
        } else if (p < options.free_thresh) {
          pixel = kFreePixel;
        }
      }
      pgm[header + static_cast<std::size_t>(row) * width + (x - box.x0)] = static_cast<char>(pixel);
    }
  }
  const std::string pgm_path = base + ".pgm";
  const std::string yaml_path = base + ".yaml";
  const Eigen::Vector2d origin =
      grid.origin() + Eigen::Vector2d(box.x0, box.y0) * grid.resolution();
  const std::string yaml =
      "image: " + std::filesystem::path(pgm_path).filename().string() + "\n" +
      "mode: " + options.mode + "\n" + "resolution: " + FormatDouble(grid.resolution()) + "\n" +
      "origin: [" + FormatDouble(origin.x()) + ", " + FormatDouble(origin.y()) + ", 0.0]\n" +
      "negate: 0\n" + "occupied_thresh: " + FormatDouble(options.occupied_thresh) + "\n" +
      "free_thresh: " + FormatDouble(options.free_thresh) + "\n";
  WriteFileAtomically(pgm_path, pgm);
  WriteFileAtomically(yaml_path, yaml);
  return yaml_path;
}

MapImage ReadMapServerMap(const std::string& yaml_path) {
  const YamlNode root = YamlNode::LoadFile(yaml_path);
  const YamlNode image_node = root.Required("image");
  const std::string image_name = image_node.As<std::string>();
  MapImage map;
  map.resolution_m = root.Get<double>("resolution");
  if (!(map.resolution_m > 0.0)) root.Required("resolution").Fail("must be > 0");
  const YamlNode origin_node = root.Required("origin");
  const auto origin = origin_node.Elements();
  if (origin.size() != 3) origin_node.Fail("expected [x, y, yaw]");
  map.origin = Pose2(origin[0].As<double>(), origin[1].As<double>(), origin[2].As<double>());
  const int negate = root.Get<int>("negate");
  if (negate != 0 && negate != 1) root.Required("negate").Fail("must be 0 or 1");
  const double occupied_thresh = root.Get<double>("occupied_thresh");
  const double free_thresh = root.Get<double>("free_thresh");
  if (!(occupied_thresh > 0.0 && occupied_thresh <= 1.0)) {
    root.Required("occupied_thresh").Fail("must be in (0, 1]");
  }
  if (!(free_thresh >= 0.0 && free_thresh < occupied_thresh)) {
    root.Required("free_thresh").Fail("must be in [0, occupied_thresh)");
  }
  std::string mode = "trinary";
  root.Read("mode", &mode);
  if (mode != "trinary" && mode != "scale" && mode != "raw") {
    root.Required("mode").Fail("must be trinary, scale or raw, got '" + mode + "'");
  }
  root.CheckAllKeysUsed();

  std::filesystem::path image_path(image_name);
  if (image_path.is_relative())
    image_path = std::filesystem::path(yaml_path).parent_path() / image_path;
  std::error_code error;  // e.g. a name too long for the OS: does not exist either
  if (!std::filesystem::exists(image_path, error)) {
    image_node.Fail("map image '" + image_path.string() + "' does not exist");
  }
  const std::string ext = image_path.extension().string();
  cv::Mat image;
  if (ext == ".pgm" || ext == ".PGM") {
    image = ReadPgm(image_path.string());
  } else {
    image = cv::imread(image_path.string(), cv::IMREAD_GRAYSCALE);
    if (image.empty()) throw ParseError(image_path.string() + ": cannot decode map image");
  }
  map.width = image.cols;
  map.height = image.rows;
  map.occupancy.assign(static_cast<std::size_t>(map.width) * map.height, -1);
  for (int row = 0; row < map.height; ++row) {
    const int y = map.height - 1 - row;
    for (int x = 0; x < map.width; ++x) {
      const std::uint8_t value = image.at<std::uint8_t>(row, x);
      std::int8_t& cell = map.occupancy[static_cast<std::size_t>(y) * map.width + x];
      if (mode == "raw") {
        cell = value <= 100 ? static_cast<std::int8_t>(value) : std::int8_t{-1};
        continue;
      }
      const double p = negate ? value / 255.0 : (255.0 - value) / 255.0;
      if (p > occupied_thresh) {
        cell = 100;
      } else if (p < free_thresh) {
        cell = 0;
      } else if (mode == "scale") {
        cell = static_cast<std::int8_t>(
            std::lround(99.0 * (p - free_thresh) / (occupied_thresh - free_thresh)));
      }
    }
  }
  return map;
}

OccupancyGrid GridFromMapImage(const MapImage& map, float log_odds) {
  OccupancyGridOptions options;
  options.resolution_m = map.resolution_m;
  options.max_log_odds = std::max(options.max_log_odds, log_odds);
  options.min_log_odds = std::min(options.min_log_odds, -log_odds);
  OccupancyGrid grid(options, map.origin.translation(), map.width, map.height);
  for (int y = 0; y < map.height; ++y) {
    for (int x = 0; x < map.width; ++x) {
      const std::int8_t v = map.at(x, y);
      if (v >= 0) grid.Set({x, y}, v >= 50 ? log_odds : -log_odds);
    }
  }
  return grid;
}

}  // namespace slamrig::slam
