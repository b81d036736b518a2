#pragma once

#include <cstdint>
#include <cstdio>
#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace slamrig::slam {

/// How MCAP chunks are compressed.
enum class McapCompression { kNone, kZstd, kLz4 };

/// The name of a compression as MCAP's Chunk record spells it: "", "zstd" or "lz4".
std::string_view McapCompressionName(McapCompression compression);

/// Options of McapWriter.
struct McapWriterOptions {
  McapCompression compression = McapCompression::kZstd;
  /// A chunk is closed once its uncompressed records reach this size (the mcap CLI's default).
  std::size_t chunk_size_bytes = 768 * 1024;
  /// zstd level; 1 is fastest (rosbag2's "fast" preset).
  int zstd_level = 1;
  /// Header record's profile ("ros2" for rosbag2 files).
  std::string profile = "ros2";

  /// One RuleViolation() message per broken rule; empty when valid.
  std::vector<std::string> Validate() const;
};

/// Writes an MCAP file (https://mcap.dev/spec, major version 0): magic, Header, Schema and
/// Channel records in the data section when first used, messages in Chunks (zstd, LZ4 frame
/// or uncompressed) each followed by its MessageIndex records, DataEnd with the CRC-32 of the
/// whole data section (magic included, as the reference writers compute it), then the Summary
/// section (Schemas, Channels, Statistics, ChunkIndexes), SummaryOffset records, the Footer with
/// the summary CRC, and the closing magic. Every chunk carries the CRC-32 of its uncompressed
/// records. Throws ConfigError for invalid options, std::runtime_error naming the path if it
/// cannot write.
///
/// As a stream (the second constructor) it writes through a function instead of a file, in an
/// order a reader takes as it comes: magic, Header, then Schema, Channel, Metadata and Message
/// records as they are added (no chunks, no indexes), and at Close() DataEnd with the data
/// section's CRC, a Footer without a summary (all zeros) and the closing magic: a valid MCAP
/// file too.
class McapWriter {
 public:
  /// Where a stream's bytes go, in order; it may throw (the writer stops there).
  using Output = std::function<void(std::string_view)>;

  McapWriter(std::string path, McapWriterOptions options);
  /// A stream: every record goes to `output` as soon as it is complete.
  McapWriter(Output output, McapWriterOptions options);
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  /// Registers a schema; returns its id (1, 2, ...).
  std::uint16_t AddSchema(std::string_view name, std::string_view encoding, std::string_view data);
  /// Registers a channel on `schema_id`; returns its id (0, 1, ...).
  std::uint16_t AddChannel(std::uint16_t schema_id, std::string_view topic,
                           std::string_view message_encoding,
                           const std::map<std::string, std::string>& metadata);
  /// Writes one Metadata record (a name and text pairs) in the data section.
  void AddMetadata(std::string_view name, const std::map<std::string, std::string>& metadata);
  /// Appends one Message record to the open chunk (a stream: writes it).
  void WriteMessage(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time_ns,
                    std::uint64_t publish_time_ns, std::string_view data);
  /// Closes the open chunk (if any), so that the next message starts a new one.
  void FlushChunk();
  /// Flushes the last chunk, writes the summary and footer, and closes the file.
  void Close();

 private:
  struct ChunkIndex {
    std::uint64_t start_time, end_time, chunk_start, chunk_length, index_length, compressed_size,
        uncompressed_size;
    std::map<std::uint16_t, std::uint64_t> index_offsets;
  };

  void Start();
  void Write(std::string_view bytes);
  void CloseStream();

  std::string path_;
  Output output_;  // a stream's, else empty
  McapWriterOptions options_;
  std::FILE* file_ = nullptr;
  std::uint64_t offset_ = 0;
  unsigned long crc_ = 0;                    // running CRC-32 of the data section (zlib's type)
  std::vector<std::string> schema_records_;  // summary copies, without opcode and length
  std::vector<std::string> channel_records_;
  std::vector<std::uint64_t> channel_counts_;
  std::vector<ChunkIndex> chunk_indexes_;
  // Open chunk.
  std::string chunk_;
  std::map<std::uint16_t, std::string> chunk_message_index_;  // channel -> (time, offset) pairs
  std::uint64_t chunk_start_time_ = 0, chunk_end_time_ = 0;
  std::string compressed_;
  void* zstd_ = nullptr;  // ZSTD_CCtx*
  std::uint64_t message_count_ = 0, start_time_ = 0, end_time_ = 0;
  std::uint32_t metadata_count_ = 0;
  bool closed_ = false;
};

}  // namespace slamrig::slam
