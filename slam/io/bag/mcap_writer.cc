#include "slam/io/bag/mcap_writer.h"

#include <lz4frame.h>
#include <zlib.h>
#include <zstd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "slam/io/bag/mcap_records.h"
#include "slam/types/error.h"
#include "slam/types/validation.h"

namespace slamrig::slam {

using mcap::Put;
using mcap::PutRecord;
using mcap::PutString;

std::uint32_t mcap::Crc32(std::string_view bytes) {
  return static_cast<std::uint32_t>(
      crc32_z(crc32_z(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(bytes.data()), bytes.size()));
}

std::string_view McapCompressionName(McapCompression compression) {
  switch (compression) {
    case McapCompression::kZstd:
      return "zstd";
    case McapCompression::kLz4:
      return "lz4";
    case McapCompression::kNone:
      break;
  }
  return "";
}

std::vector<std::string> McapWriterOptions::Validate() const {
  Rules rules;
  rules.AtLeast("chunk_size_bytes", chunk_size_bytes, decltype(chunk_size_bytes){1024})
      .InRange("zstd_level", zstd_level, 1, ZSTD_maxCLevel());
  return rules.errors();
}

McapWriter::McapWriter(std::string path, McapWriterOptions options)
    : path_(std::move(path)), options_(std::move(options)) {
  const std::vector<std::string> errors = options_.Validate();
  if (!errors.empty()) throw ConfigError("mcap writer: " + errors.front());
  file_ = std::fopen(path_.c_str(), "wb");
  if (file_ == nullptr) throw OutputError(path_ + ": cannot write: " + std::strerror(errno));
  std::setvbuf(file_, nullptr, _IOFBF, 1 << 20);
  Start();
}

McapWriter::McapWriter(Output output, McapWriterOptions options)
    : path_("MCAP stream"), output_(std::move(output)), options_(std::move(options)) {
  const std::vector<std::string> errors = options_.Validate();
  if (!errors.empty()) throw ConfigError("mcap writer: " + errors.front());
  Start();
}

void McapWriter::Start() {
  if (options_.compression == McapCompression::kZstd && !output_) {
    ZSTD_CCtx* ctx = ZSTD_createCCtx();
    ZSTD_CCtx_setParameter(ctx, ZSTD_c_compressionLevel, options_.zstd_level);
    zstd_ = ctx;
  }
  if (!output_) chunk_.reserve(options_.chunk_size_bytes + (1 << 16));
  crc_ = crc32_z(0L, Z_NULL, 0);
  Write(std::string_view(mcap::kMagic, sizeof(mcap::kMagic)));
  std::string header;
  PutString(&header, options_.profile);
  PutString(&header, "slamrig");
  std::string record;
  PutRecord(&record, mcap::kHeader, header);
  Write(record);
}

McapWriter::~McapWriter() {
  if (file_ != nullptr) std::fclose(file_);
  if (zstd_ != nullptr) ZSTD_freeCCtx(static_cast<ZSTD_CCtx*>(zstd_));
}

void McapWriter::Write(std::string_view bytes) {
  if (output_) {
    output_(bytes);
  } else if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size()) {
    throw OutputError(path_ + ": write failed: " + std::strerror(errno));
  }
  crc_ = crc32_z(crc_, reinterpret_cast<const Bytef*>(bytes.data()), bytes.size());
  offset_ += bytes.size();
}

std::uint16_t McapWriter::AddSchema(std::string_view name, std::string_view encoding,
                                    std::string_view data) {
  const auto id = static_cast<std::uint16_t>(schema_records_.size() + 1);
  std::string content;
  Put(&content, id);
  PutString(&content, name);
  PutString(&content, encoding);
  Put(&content, static_cast<std::uint32_t>(data.size()));
  content.append(data);
  std::string record;
  PutRecord(&record, mcap::kSchema, content);
  Write(record);
  schema_records_.push_back(std::move(record));
  return id;
}

std::uint16_t McapWriter::AddChannel(std::uint16_t schema_id, std::string_view topic,
                                     std::string_view message_encoding,
                                     const std::map<std::string, std::string>& metadata) {
  const auto id = static_cast<std::uint16_t>(channel_records_.size());
  std::string content;
  Put(&content, id);
  Put(&content, schema_id);
  PutString(&content, topic);
  PutString(&content, message_encoding);
  std::string map;
  for (const auto& [key, value] : metadata) {
    PutString(&map, key);
    PutString(&map, value);
  }
  Put(&content, static_cast<std::uint32_t>(map.size()));
  content += map;
  std::string record;
  PutRecord(&record, mcap::kChannel, content);
  Write(record);
  channel_records_.push_back(std::move(record));
  channel_counts_.push_back(0);
  return id;
}

void McapWriter::WriteMessage(std::uint16_t channel_id, std::uint32_t sequence,
                              std::uint64_t log_time_ns, std::uint64_t publish_time_ns,
                              std::string_view data) {
  if (channel_id >= channel_counts_.size()) {
    throw std::logic_error("McapWriter: unknown channel " + std::to_string(channel_id));
  }
  if (output_) {
    std::string record;
    record.reserve(9 + 2 + 4 + 8 + 8 + data.size());
    Put(&record, static_cast<std::uint8_t>(mcap::kMessage));
    Put(&record, static_cast<std::uint64_t>(2 + 4 + 8 + 8 + data.size()));
    Put(&record, channel_id);
    Put(&record, sequence);
    Put(&record, log_time_ns);
    Put(&record, publish_time_ns);
    record.append(data);
    Write(record);
    ++message_count_;
    ++channel_counts_[channel_id];
    return;
  }
  const bool first_in_chunk = chunk_.empty();
  std::string& index = chunk_message_index_[channel_id];
  Put(&index, log_time_ns);
  Put(&index, static_cast<std::uint64_t>(chunk_.size()));
  Put(&chunk_, static_cast<std::uint8_t>(mcap::kMessage));
  Put(&chunk_, static_cast<std::uint64_t>(2 + 4 + 8 + 8 + data.size()));
  Put(&chunk_, channel_id);
  Put(&chunk_, sequence);
  Put(&chunk_, log_time_ns);
  Put(&chunk_, publish_time_ns);
  chunk_.append(data);
  if (message_count_ == 0 || log_time_ns < start_time_) start_time_ = log_time_ns;
  if (message_count_ == 0 || log_time_ns > end_time_) end_time_ = log_time_ns;
  if (first_in_chunk) chunk_start_time_ = chunk_end_time_ = log_time_ns;
  chunk_start_time_ = std::min(chunk_start_time_, log_time_ns);
  chunk_end_time_ = std::max(chunk_end_time_, log_time_ns);
  ++message_count_;
  ++channel_counts_[channel_id];
  if (chunk_.size() >= options_.chunk_size_bytes) FlushChunk();
}

void McapWriter::FlushChunk() {
  if (chunk_.empty()) return;
  const std::uint32_t uncompressed_crc = mcap::Crc32(chunk_);
  std::string_view payload = chunk_;
  if (options_.compression == McapCompression::kZstd) {
    compressed_.resize(ZSTD_compressBound(chunk_.size()));
    const std::size_t n = ZSTD_compress2(static_cast<ZSTD_CCtx*>(zstd_), compressed_.data(),
                                         compressed_.size(), chunk_.data(), chunk_.size());
    if (ZSTD_isError(n)) throw std::runtime_error(path_ + ": zstd: " + ZSTD_getErrorName(n));
    payload = std::string_view(compressed_.data(), n);
  } else if (options_.compression == McapCompression::kLz4) {
    LZ4F_preferences_t prefs;
    std::memset(&prefs, 0, sizeof(prefs));
    prefs.frameInfo.contentSize = chunk_.size();
    compressed_.resize(LZ4F_compressFrameBound(chunk_.size(), &prefs));
    const std::size_t n = LZ4F_compressFrame(compressed_.data(), compressed_.size(), chunk_.data(),
                                             chunk_.size(), &prefs);
    if (LZ4F_isError(n)) throw std::runtime_error(path_ + ": lz4: " + LZ4F_getErrorName(n));
    payload = std::string_view(compressed_.data(), n);
  }
  const std::string_view compression = McapCompressionName(options_.compression);

  ChunkIndex ci{};
  ci.start_time = chunk_start_time_;
  ci.end_time = chunk_end_time_;
  ci.chunk_start = offset_;
  ci.compressed_size = payload.size();
  ci.uncompressed_size = chunk_.size();
  std::string head;
  Put(&head, static_cast<std::uint8_t>(mcap::kChunk));
  Put(&head,
      static_cast<std::uint64_t>(8 + 8 + 8 + 4 + 4 + compression.size() + 8 + payload.size()));
  Put(&head, chunk_start_time_);
  Put(&head, chunk_end_time_);
  Put(&head, static_cast<std::uint64_t>(chunk_.size()));
  Put(&head, uncompressed_crc);
  PutString(&head, compression);
  Put(&head, static_cast<std::uint64_t>(payload.size()));
  Write(head);
  Write(payload);
  ci.chunk_length = offset_ - ci.chunk_start;

  const std::uint64_t index_start = offset_;
  std::string record;
  for (const auto& [channel, entries] : chunk_message_index_) {
    ci.index_offsets[channel] = offset_;
    std::string content;
    Put(&content, channel);
    Put(&content, static_cast<std::uint32_t>(entries.size()));
    content += entries;
    record.clear();
    PutRecord(&record, mcap::kMessageIndex, content);
    Write(record);
  }
  ci.index_length = offset_ - index_start;
  chunk_indexes_.push_back(std::move(ci));
  chunk_.clear();
  chunk_message_index_.clear();
}

void McapWriter::AddMetadata(std::string_view name,
                             const std::map<std::string, std::string>& metadata) {
  std::string content;
  PutString(&content, name);
  std::string map;
  for (const auto& [key, value] : metadata) {
    PutString(&map, key);
    PutString(&map, value);
  }
  Put(&content, static_cast<std::uint32_t>(map.size()));
  content += map;
  std::string record;
  PutRecord(&record, mcap::kMetadata, content);
  Write(record);
  ++metadata_count_;
}

void McapWriter::CloseStream() {
  std::string record;
  std::string content;
  Put(&content, static_cast<std::uint32_t>(crc_));
  PutRecord(&record, mcap::kDataEnd, content);
  Write(record);
  record.clear();
  Put(&record, static_cast<std::uint8_t>(mcap::kFooter));
  Put(&record, std::uint64_t{8 + 8 + 4});
  Put(&record, std::uint64_t{0});  // no summary section
  Put(&record, std::uint64_t{0});  // no summary offsets
  Put(&record, std::uint32_t{0});  // so no summary CRC
  record.append(mcap::kMagic, sizeof(mcap::kMagic));
  Write(record);
  closed_ = true;
}

void McapWriter::Close() {
  if (closed_) return;
  if (output_) {
    CloseStream();
    return;
  }
  FlushChunk();
  const auto data_crc = static_cast<std::uint32_t>(crc_);
  std::string record;
  std::string content;
  Put(&content, data_crc);
  PutRecord(&record, mcap::kDataEnd, content);
  Write(record);

  // Summary section: its CRC runs from here to the footer's summary_offset_start field.
  crc_ = crc32_z(0L, Z_NULL, 0);
  const std::uint64_t summary_start = offset_;
  struct Group {
    mcap::Opcode op;
    std::uint64_t start, length;
  };
  std::vector<Group> groups;
  auto group = [&](mcap::Opcode op, const std::vector<std::string>& records) {
    if (records.empty()) return;
    const std::uint64_t start = offset_;
    for (const std::string& r : records) Write(r);
    groups.push_back({op, start, offset_ - start});
  };
  group(mcap::kSchema, schema_records_);
  group(mcap::kChannel, channel_records_);

  content.clear();
  Put(&content, message_count_);
  Put(&content, static_cast<std::uint16_t>(schema_records_.size()));
  Put(&content, static_cast<std::uint32_t>(channel_records_.size()));
  Put(&content, std::uint32_t{0});  // attachments
  Put(&content, metadata_count_);
  Put(&content, static_cast<std::uint32_t>(chunk_indexes_.size()));
  Put(&content, start_time_);
  Put(&content, end_time_);
  Put(&content, static_cast<std::uint32_t>(channel_counts_.size() * 10));
  for (std::size_t c = 0; c < channel_counts_.size(); ++c) {
    Put(&content, static_cast<std::uint16_t>(c));
    Put(&content, channel_counts_[c]);
  }
  record.clear();
  PutRecord(&record, mcap::kStatistics, content);
  group(mcap::kStatistics, {record});

  std::vector<std::string> chunk_index_records;
  for (const ChunkIndex& ci : chunk_indexes_) {
    content.clear();
    Put(&content, ci.start_time);
    Put(&content, ci.end_time);
    Put(&content, ci.chunk_start);
    Put(&content, ci.chunk_length);
    Put(&content, static_cast<std::uint32_t>(ci.index_offsets.size() * 10));
    for (const auto& [channel, offset] : ci.index_offsets) {
      Put(&content, channel);
      Put(&content, offset);
    }
    Put(&content, ci.index_length);
    PutString(&content, McapCompressionName(options_.compression));
    Put(&content, ci.compressed_size);
    Put(&content, ci.uncompressed_size);
    record.clear();
    PutRecord(&record, mcap::kChunkIndex, content);
    chunk_index_records.push_back(record);
  }
  group(mcap::kChunkIndex, chunk_index_records);

  const std::uint64_t summary_offset_start = offset_;
  for (const Group& g : groups) {
    content.clear();
    Put(&content, static_cast<std::uint8_t>(g.op));
    Put(&content, g.start);
    Put(&content, g.length);
    record.clear();
    PutRecord(&record, mcap::kSummaryOffset, content);
    Write(record);
  }

  record.clear();
  Put(&record, static_cast<std::uint8_t>(mcap::kFooter));
  Put(&record, std::uint64_t{8 + 8 + 4});
  Put(&record, summary_start);
  Put(&record, summary_offset_start);
  Write(record);
  record.clear();
  Put(&record, static_cast<std::uint32_t>(crc_));
  record.append(mcap::kMagic, sizeof(mcap::kMagic));
  Write(record);
  if (std::fflush(file_) != 0 || std::fclose(file_) != 0) {
    file_ = nullptr;
    throw OutputError(path_ + ": write failed: " + std::strerror(errno));
  }
  file_ = nullptr;
  closed_ = true;
}

}  // namespace slamrig::slam
