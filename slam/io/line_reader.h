#pragma once

#include <string>
#include <string_view>

namespace slamrig::slam {

/// Reads a text file line by line, gzip-compressed or plain (zlib detects which), and knows the
/// current line number for error messages. Throws ParseError when the file cannot be opened or
/// is corrupt, and when a gzip stream ends before its end, unless `recover_cut`: then every
/// line that decompresses is returned and cut() says the stream was cut short.
class LineReader {
 public:
  explicit LineReader(std::string path, bool recover_cut = false);
  ~LineReader();
  LineReader(const LineReader&) = delete;
  LineReader& operator=(const LineReader&) = delete;

  /// Reads the next line without its end-of-line characters; false at end of file.
  bool Next(std::string_view* line);
  /// 1-based number of the line last returned.
  int line_number() const { return line_number_; }
  /// The line last returned ended with an end of line (only the last line of a file may not).
  bool terminated() const { return terminated_; }
  /// The gzip stream was cut short (seen once its last whole data was read; with recover_cut).
  bool cut() const { return cut_; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  void* file_ = nullptr;  // gzFile, kept opaque so that zlib.h stays out of headers
  std::string buffer_;
  int line_number_ = 0;
  bool recover_cut_ = false;
  bool terminated_ = true;
  bool cut_ = false;
};

}  // namespace slamrig::slam
