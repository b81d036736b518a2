#include "slam/io/bag/cdr.h"

namespace slamrig::slam {

// Encapsulation: representation identifier CDR_LE (0x0001, big-endian on the wire), then two
// option bytes (OMG DDS-XTypes 1.3, 7.6.3.1.2).
constexpr char kCdrLeHeader[4] = {0x00, 0x01, 0x00, 0x00};
constexpr std::size_t kHeaderBytes = 4;

CdrWriter::CdrWriter(std::string* out) : out_(out) {
  out_->clear();
  out_->append(kCdrLeHeader, kHeaderBytes);
}

void CdrWriter::Align(std::size_t n) {
  const std::size_t rem = (out_->size() - kHeaderBytes) % n;
  if (rem != 0) out_->append(n - rem, '\0');
}

void CdrWriter::String(std::string_view s) {
  Uint32(static_cast<std::uint32_t>(s.size() + 1));
  out_->append(s.data(), s.size());
  out_->push_back('\0');
}

void CdrWriter::Float32Sequence(std::span<const float> values) {
  Uint32(static_cast<std::uint32_t>(values.size()));
  if (values.empty()) return;
  Align(4);
  out_->append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(float));
}

void CdrWriter::ByteSequence(std::span<const std::uint8_t> bytes) {
  Uint32(static_cast<std::uint32_t>(bytes.size()));
  out_->append(reinterpret_cast<const char*>(bytes.data()), bytes.size());
}

void CdrWriter::Float64Sequence(std::span<const double> values) {
  Uint32(static_cast<std::uint32_t>(values.size()));
  Float64Array(values);
}

void CdrWriter::Float64Array(std::span<const double> values) {
  if (values.empty()) return;
  Align(8);
  out_->append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(double));
}

void CdrWriter::ZeroFloat64Array(std::size_t n) {
  if (n == 0) return;
  Align(8);
  out_->append(n * sizeof(double), '\0');
}

CdrReader::CdrReader(std::string_view data) : data_(data) {
  if (data_.size() < kHeaderBytes) {
    throw CdrError("payload of " + std::to_string(data_.size()) +
                   " bytes is shorter than the 4-byte CDR header");
  }
  if (data_[0] != 0x00 || data_[1] != 0x01) {
    throw CdrError("not little-endian CDR (encapsulation " + std::to_string(+data_[0]) + " " +
                   std::to_string(+data_[1]) + ", expected 0 1)");
  }
}

void CdrReader::Align(std::size_t n) {
  const std::size_t rem = (pos_ - kHeaderBytes) % n;
  if (rem != 0) pos_ += n - rem;
}

void CdrReader::Need(std::size_t n, const char* what) const {
  if (pos_ > data_.size() || data_.size() - pos_ < n) {
    throw CdrError("truncated at byte " + std::to_string(pos_) + " of " +
                   std::to_string(data_.size()) + ": " + what + " needs " + std::to_string(n) +
                   " bytes");
  }
}

std::string CdrReader::String() {
  const std::uint32_t length = Uint32();
  if (length == 0) return {};  // not legal CDR, but some writers send it for ""
  Need(length, "string");
  if (data_[pos_ + length - 1] != '\0') {
    throw CdrError("string at byte " + std::to_string(pos_) + " is not NUL-terminated");
  }
  std::string s(data_.substr(pos_, length - 1));
  pos_ += length;
  return s;
}

std::uint32_t CdrReader::SequenceLength(std::size_t min_element_bytes) {
  const std::uint32_t count = Uint32();
  const std::size_t left = pos_ <= data_.size() ? data_.size() - pos_ : 0;
  if (min_element_bytes > 0 && count > left / min_element_bytes) {
    throw CdrError("sequence at byte " + std::to_string(pos_) + " claims " + std::to_string(count) +
                   " elements but only " + std::to_string(left) + " bytes remain");
  }
  return count;
}

std::vector<float> CdrReader::Float32Sequence() {
  const std::uint32_t count = SequenceLength(sizeof(float));
  std::vector<float> values(count);
  if (count == 0) return values;
  Align(4);
  Need(count * sizeof(float), "float32 sequence");
  std::memcpy(values.data(), data_.data() + pos_, count * sizeof(float));
  pos_ += count * sizeof(float);
  return values;
}

std::string CdrReader::ByteSequence() {
  const std::uint32_t count = SequenceLength(1);
  Need(count, "byte sequence");
  std::string bytes(data_.substr(pos_, count));
  pos_ += count;
  return bytes;
}

std::vector<double> CdrReader::Float64Sequence() {
  const std::uint32_t count = SequenceLength(sizeof(double));
  return Float64Array(count);
}

std::vector<double> CdrReader::Float64Array(std::size_t n) {
  std::vector<double> values(n);
  if (n == 0) return values;
  Align(8);
  Need(n * sizeof(double), "float64 array");
  std::memcpy(values.data(), data_.data() + pos_, n * sizeof(double));
  pos_ += n * sizeof(double);
  return values;
}

void CdrReader::SkipFloat64Array(std::size_t n) {
  if (n == 0) return;
  Align(8);
  Need(n * sizeof(double), "float64 array");
  pos_ += n * sizeof(double);
}

}  // namespace slamrig::slam
