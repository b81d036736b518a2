#pragma once

#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace slamrig::slam {

/// A CDR payload that cannot be decoded: too short, a bad length, a bad encapsulation header.
/// The message names the byte offset; callers add the file, topic and message index.
class CdrError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Serializes one ROS 2 message as plain little-endian CDR (OMG CDR / XCDR1, what rmw_fastrtps
/// and rmw_cyclonedds put on the wire and rosbag2 stores): the 4-byte encapsulation header
/// 00 01 00 00 (CDR_LE), then every primitive aligned to its own size (1, 2, 4 or 8 bytes)
/// relative to the first byte after the header; strings are a uint32 length that counts the
/// terminating NUL, the bytes and the NUL; sequences a uint32 element count and the elements;
/// fixed arrays just the elements. Structs add no alignment of their own.
class CdrWriter {
 public:
  /// Clears `out` and writes the encapsulation header into it; `out` must outlive the writer.
  explicit CdrWriter(std::string* out);

  void Int32(std::int32_t v) { Pod(v); }
  void Uint32(std::uint32_t v) { Pod(v); }
  void Float32(float v) { Pod(v); }
  void Float64(double v) { Pod(v); }
  void Uint8(std::uint8_t v) { Pod(v); }
  /// `sequence<uint8>`: count, then the bytes.
  void ByteSequence(std::span<const std::uint8_t> bytes);
  /// A CDR string: uint32 length including the NUL, the bytes, the NUL.
  void String(std::string_view s);
  /// `sequence<float>`: count, then the elements.
  void Float32Sequence(std::span<const float> values);
  /// `sequence<double>`: count, then the elements.
  void Float64Sequence(std::span<const double> values);
  /// A fixed-size `double[N]` array: the elements only.
  void Float64Array(std::span<const double> values);
  /// A fixed-size array of `n` zero doubles (unused covariance matrices).
  void ZeroFloat64Array(std::size_t n);

 private:
  void Align(std::size_t n);
  template <typename T>
  void Pod(T v) {
    Align(sizeof(T));
    char bytes[sizeof(T)];
    std::memcpy(bytes, &v, sizeof(T));
    out_->append(bytes, sizeof(T));
  }

  std::string* out_;
};

/// Bounds-checked reader of a little-endian CDR payload written as CdrWriter describes. Every
/// read checks the remaining length first and throws CdrError naming the offset; a sequence
/// length is checked against the bytes left before anything is allocated.
class CdrReader {
 public:
  /// Checks the encapsulation header (CDR_LE: 00 01, options ignored).
  explicit CdrReader(std::string_view data);

  std::int32_t Int32() { return Pod<std::int32_t>("int32"); }
  std::uint32_t Uint32() { return Pod<std::uint32_t>("uint32"); }
  float Float32() { return Pod<float>("float32"); }
  double Float64() { return Pod<double>("float64"); }
  std::string String();
  std::vector<float> Float32Sequence();
  std::vector<double> Float64Sequence();
  /// `sequence<uint8>` (or int8): count, then the bytes.
  std::string ByteSequence();
  /// A fixed array of `n` doubles.
  std::vector<double> Float64Array(std::size_t n);
  /// Skips a fixed array of `n` doubles.
  void SkipFloat64Array(std::size_t n);
  /// Reads a sequence's element count and checks that `count * min_element_bytes` bytes remain.
  std::uint32_t SequenceLength(std::size_t min_element_bytes);

 private:
  void Align(std::size_t n);
  void Need(std::size_t n, const char* what) const;
  template <typename T>
  T Pod(const char* what) {
    Align(sizeof(T));
    Need(sizeof(T), what);
    T v;
    std::memcpy(&v, data_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }

  std::string_view data_;
  std::size_t pos_ = 4;
};

}  // namespace slamrig::slam
