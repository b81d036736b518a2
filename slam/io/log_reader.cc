#include "slam/io/log_reader.h"

#include <algorithm>
#include <cstdio>
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

bool IsFolder(const std::string& p) {
  std::error_code ec;
  return fs::is_directory(p, ec);
}

// A folder that no reader reads as a whole, but that may hold runs.
bool IsFolderOfRuns(const std::string& p) {
  return IsFolder(p) && !LooksLikeEce276a(p) && !LooksLikeBag(p);
}

// "Encoders20.npz" or "encoders20.csv.gz" -> "20"; "" for any other name.
std::string EncoderFileNumber(const std::string& name) {
  for (const auto& [prefix, suffix] :
       {std::pair<std::string_view, std::string_view>{"Encoders", ".npz"},
        {"encoders", ".csv.gz"}}) {
    if (!name.starts_with(prefix) || !name.ends_with(suffix)) continue;
    const std::string number =
        name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
    if (!number.empty() &&
        std::all_of(number.begin(), number.end(), [](char c) { return c >= '0' && c <= '9'; })) {
      return number;
    }
  }
  return "";
}

// Printable bytes, tabs and line ends only: what a CARMEN text log starts with.
bool LooksLikeText(std::string_view head) {
  return std::none_of(head.begin(), head.end(), [](char c) {
    const auto u = static_cast<unsigned char>(c);
    return (u < 0x20 && c != '\t' && c != '\n' && c != '\r' && c != '\f' && c != '\v') || u == 0x7f;
  });
}

std::string HexBytes(std::string_view bytes) {
  std::string out;
  char hex[4];
  for (const char c : bytes) {
    std::snprintf(hex, sizeof(hex), "%s%02x", out.empty() ? "" : " ",
                  static_cast<unsigned>(static_cast<unsigned char>(c)));
    out += hex;
  }
  return out;
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

std::vector<std::string> RunsInFolder(const std::string& folder) {
  std::vector<std::string> runs;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_directory(ec)) {
      if (LooksLikeBag(entry.path().string())) runs.push_back(entry.path().string());
    } else if (name.ends_with(".log") || name.ends_with(".log.gz")) {
      runs.push_back(entry.path().string());
    } else if (const std::string number = EncoderFileNumber(name); !number.empty()) {
      const std::string dataset = (fs::path(folder) / number).string();
      if (std::find(runs.begin(), runs.end(), dataset) == runs.end()) runs.push_back(dataset);
    }
  }
  std::sort(runs.begin(), runs.end());
  return runs;
}

std::string ResolveLogPath(const std::string& path) {
  std::string resolved = path;
  const fs::path in_data = fs::path(DataDir()) / path;
  if (!Exists(path) && !LooksLikeEce276a(path) && fs::path(path).is_relative() &&
      (Exists(in_data) || LooksLikeEce276a(in_data.string()))) {
    resolved = in_data.string();
  }
  if (IsFolderOfRuns(resolved)) {
    const std::vector<std::string> runs = RunsInFolder(resolved);
    if (runs.size() == 1) return runs.front();
  }
  return resolved;
}

LogFormat DetectLogFormat(const std::string& path) {
  if (LooksLikeEce276a(path)) return LogFormat::kEce276a;
  if (LooksLikeBag(path)) return LogFormat::kRos2Bag;
  if (!Exists(path)) throw ParseError(path + ": no such file or dataset");
  if (IsFolder(path)) {
    const std::vector<std::string> runs = RunsInFolder(path);
    if (runs.empty()) {
      throw ParseError(path +
                       ": a folder, but neither a ROS 2 bag (no metadata.yaml, .mcap or .db3) nor "
                       "an ECE276A dataset (give the file or DIR/NUMBER), and no run in it (no "
                       "*.log, bag folder or ECE276A encoder file)");
    }
    std::string list;
    for (const std::string& run : runs) list += (list.empty() ? "" : ", ") + run;
    throw ParseError(path + ": a folder with " + std::to_string(runs.size()) + " runs (" + list +
                     "): give one");
  }
  // CARMEN logs are text, gzip-compressed or not; the reader reports any line it cannot parse.
  std::ifstream in(path, std::ios::binary);
  char head[256];
  in.read(head, sizeof(head));
  const std::string_view h(head, static_cast<std::size_t>(in.gcount()));
  const bool gzip = h.size() >= 2 && static_cast<unsigned char>(h[0]) == 0x1f &&
                    static_cast<unsigned char>(h[1]) == 0x8b;
  if (gzip || LooksLikeText(h)) return LogFormat::kCarmen;
  throw ParseError(
      path + ": not a log: no MCAP magic, no SQLite header, not gzip, not text (" +
      (h.size() > 8 ? "starts with " + HexBytes(h.substr(0, 8)) + " ..." : "bytes " + HexBytes(h)) +
      ")");
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
      bag.strict = options.strict;
      data = ReadBag(resolved, bag);
      break;
    }
    case LogFormat::kCarmen: {
      CarmenReadOptions carmen;
      carmen.lenient = options.lenient;
      carmen.strict = options.strict;
      data = CarmenToDataset(ReadCarmenLog(resolved, carmen));
      break;
    }
  }
  data.format = LogFormatName(format);
  return data;
}

}  // namespace slamrig::slam
