#pragma once

#include <string>
#include <string_view>

namespace slamrig::slam {

/// Reads a text file line by line, gzip-compressed or plain (zlib detects which), and knows the
/// current line number for error messages. Throws ParseError when the file cannot be opened or
/// is corrupt.
class LineReader {
 public:
  explicit LineReader(std::string path);
  ~LineReader();
  LineReader(const LineReader&) = delete;
  LineReader& operator=(const LineReader&) = delete;

  /// Reads the next line without its end-of-line characters; false at end of file.
  bool Next(std::string_view* line);
  /// 1-based number of the line last returned.
  int line_number() const { return line_number_; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  void* file_ = nullptr;  // gzFile, kept opaque so that zlib.h stays out of headers
  std::string buffer_;
  int line_number_ = 0;
};

}  // namespace slamrig::slam
