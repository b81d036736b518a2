#include "slam/io/log_reader.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "slam/io/bag/bag_reader.h"
#include "slam/io/carmen_reader.h"
#include "slam/io/ece276a_reader.h"
#include "slam/types/error.h"

namespace slamrig::slam {
namespace {

namespace fs = std::filesystem;

bool Exists(const fs::path& p) {
  std::error_code ec;
  return fs::exists(p, ec);
}

}  // namespace

const char* LogFormatName(LogFormat format) {
  switch (format) {
    case LogFormat::kCarmen:
      return "carmen";
    case LogFormat::kEce276a:
      return "ece276a";
    case LogFormat::kRos2Bag:
      return "ros2bag";
  }
  return "?";
}

std::string DataDir() {
  const char* env = std::getenv("SLAMRIG_DATA_DIR");
  if (env != nullptr && *env != '\0') return env;
  const fs::path here = fs::path("..") / "shared" / "datasets";
#ifdef SLAMRIG_SOURCE_DIR
  if (!Exists(here)) return (fs::path(SLAMRIG_SOURCE_DIR) / ".." / "shared" / "datasets").string();
#endif
  return here.string();
}

std::string ResolveLogPath(const std::string& path) {
  if (Exists(path) || LooksLikeEce276a(path)) return path;
  const fs::path in_data = fs::path(DataDir()) / path;
  if (fs::path(path).is_relative() && (Exists(in_data) || LooksLikeEce276a(in_data.string()))) {
    return in_data.string();
  }
  return path;
}

LogFormat DetectLogFormat(const std::string& path) {
  if (LooksLikeEce276a(path)) return LogFormat::kEce276a;
  if (LooksLikeBag(path)) return LogFormat::kRos2Bag;
  if (!Exists(path)) throw ParseError(path + ": no such file or dataset");
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    throw ParseError(path +
                     ": a folder, but neither a ROS 2 bag (no metadata.yaml, .mcap or .db3) nor an "
                     "ECE276A dataset (give the file or DIR/NUMBER)");
  }
  // CARMEN logs are text, gzip-compressed or not; the reader reports any line it cannot parse.
  std::ifstream in(path, std::ios::binary);
  char magic[2] = {0, 0};
  in.read(magic, 2);
  const bool gzip = in.gcount() == 2 && static_cast<unsigned char>(magic[0]) == 0x1f &&
                    static_cast<unsigned char>(magic[1]) == 0x8b;
  if (gzip || in.gcount() < 2 || (magic[0] != '\0' && magic[1] != '\0')) return LogFormat::kCarmen;
  throw ParseError(path + ": not a log slamrig can read (CARMEN text or .gz, ROS 2 bag, ECE276A)");
}

Dataset ReadLog(const std::string& path, const LogReadOptions& options) {
  const std::string resolved = ResolveLogPath(path);
  const LogFormat format = DetectLogFormat(resolved);
  Dataset data;
  switch (format) {
    case LogFormat::kEce276a:
      data = ReadEce276a(FindEce276aFiles(resolved));
      break;
    case LogFormat::kRos2Bag: {
      BagReaderOptions bag;  // wheel ticks with the ticks per revolution the bag records
      bag.topics = options.topics;
      data = ReadBag(resolved, bag);
      break;
    }
    case LogFormat::kCarmen: {
      CarmenReadOptions carmen;
      carmen.lenient = options.lenient;
      data = CarmenToDataset(ReadCarmenLog(resolved, carmen));
      break;
    }
  }
  data.format = LogFormatName(format);
  return data;
}

}  // namespace slamrig::slam
