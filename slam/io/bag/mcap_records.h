#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

namespace slamrig::slam::mcap {

/// The 8 magic bytes that open and close an MCAP file (major version 0).
inline constexpr char kMagic[8] = {'\x89', 'M', 'C', 'A', 'P', '0', '\r', '\n'};

/// Record opcodes of the MCAP specification.
enum Opcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0A,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

/// Appends a little-endian integer.
template <typename T>
void Put(std::string* out, T v) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &v, sizeof(T));
  out->append(bytes, sizeof(T));
}

/// Appends an MCAP string: uint32 byte length, then the bytes.
inline void PutString(std::string* out, std::string_view s) {
  Put(out, static_cast<std::uint32_t>(s.size()));
  out->append(s);
}

/// Appends a record: opcode, uint64 content length, content.
inline void PutRecord(std::string* out, Opcode op, std::string_view content) {
  Put(out, static_cast<std::uint8_t>(op));
  Put(out, static_cast<std::uint64_t>(content.size()));
  out->append(content);
}

/// CRC-32 (ISO-HDLC, the zlib polynomial MCAP uses) of `bytes`.
std::uint32_t Crc32(std::string_view bytes);

}  // namespace slamrig::slam::mcap
