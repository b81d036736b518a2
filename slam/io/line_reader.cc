#include "slam/io/line_reader.h"

#include <zlib.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "slam/types/error.h"

namespace slamrig::slam {

LineReader::LineReader(std::string path, bool recover_cut)
    : path_(std::move(path)), recover_cut_(recover_cut) {
  std::error_code ec;
  if (!std::filesystem::exists(path_, ec)) throw ParseError(path_ + ": no such file");
  if (std::filesystem::is_directory(path_, ec)) throw ParseError(path_ + ": is a directory");
  gzFile f = gzopen(path_.c_str(), "rb");
  if (f == nullptr) throw ParseError(path_ + ": cannot open: " + std::strerror(errno));
  gzbuffer(f, 1 << 17);
  file_ = f;
}

LineReader::~LineReader() {
  if (file_ != nullptr) gzclose(static_cast<gzFile>(file_));
}

bool LineReader::Next(std::string_view* line) {
  gzFile f = static_cast<gzFile>(file_);
  buffer_.clear();
  char chunk[8192];
  bool got_any = false;
  terminated_ = false;
  while (gzgets(f, chunk, sizeof(chunk)) != nullptr) {
    got_any = true;
    buffer_.append(chunk);
    if (!buffer_.empty() && buffer_.back() == '\n') {
      terminated_ = true;
      break;
    }
  }
  int error = Z_OK;
  const char* message = gzerror(f, &error);
  // zlib reports a stream that ends early as Z_BUF_ERROR, after handing out what it decompressed.
  if (error == Z_BUF_ERROR && recover_cut_) {
    cut_ = true;
  } else if (error != Z_OK && error != Z_STREAM_END) {
    throw ParseError(path_ + ":" + std::to_string(line_number_ + 1) +
                     ": corrupt or truncated compressed data: " + message);
  }
  if (!got_any) return false;
  ++line_number_;
  while (!buffer_.empty() && (buffer_.back() == '\n' || buffer_.back() == '\r')) buffer_.pop_back();
  *line = buffer_;
  return true;
}

}  // namespace slamrig::slam
