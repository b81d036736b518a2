#include <lz4frame.h>
#include <zstd.h>

#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "slam/io/bag/mcap_records.h"
#include "slam/io/bag/raw_bag.h"
#include "slam/io/dataset.h"
#include "slam/types/error.h"

namespace slamrig::slam {
namespace {

// A chunk may not claim to decompress to more than this (hostile sizes must not allocate).
constexpr std::uint64_t kMaxChunkBytes = std::uint64_t{1} << 31;

using mcap::Crc32;

class McapParser {
 public:
  explicit McapParser(std::string path) : path_(std::move(path)) {}

  RawBag Parse(bool recover_cut) {
    std::ifstream in(path_, std::ios::binary);
    if (!in) throw ParseError(path_ + ": cannot open");
    std::ostringstream s;
    s << in.rdbuf();
    file_ = std::move(s).str();
    const std::string_view file = file_;
    const std::string_view magic(mcap::kMagic, sizeof(mcap::kMagic));
    if (file.size() < magic.size() || file.substr(0, magic.size()) != magic) {
      throw ParseError(path_ + ": byte 0: not an MCAP file (bad magic)");
    }
    const bool whole = file.size() >= 2 * magic.size() + 9 + 20 &&
                       file.substr(file.size() - magic.size()) == magic;
    if (!whole && !recover_cut) {
      throw ParseError(path_ + ": truncated: no Footer and closing magic at the end");
    }
    if (whole) CheckSummaryCrc();
    std::size_t pos = magic.size();
    while (true) {
      const std::size_t start = pos;
      if (!whole && !RecordFits(file, pos)) {
        bag_.cut = RawBagCut{"truncated at byte " + GroupedCount(file.size()), false};
        break;
      }
      const auto [op, content] = NextRecord(file, &pos, 0);
      if (op == mcap::kFooter) {
        if (!whole) bag_.cut = RawBagCut{"truncated at byte " + GroupedCount(file.size()), true};
        break;
      }
      if (op == mcap::kDataEnd) {
        Cursor c{content, start + 9, this};
        const std::uint32_t crc = c.U32();
        if (crc != 0 && crc != Crc32(file.substr(0, start))) {
          throw ParseError(Where(start) + "data section CRC mismatch");
        }
        // A file cut in its summary section still holds every message.
        if (!whole) bag_.cut = RawBagCut{"truncated at byte " + GroupedCount(file.size()), true};
        break;
      }
      if (op == mcap::kChunk) {
        ReadChunk(content, start + 9);
      } else {
        Handle(op, content, start + 9);
      }
    }
    return std::move(bag_);
  }

 private:
  // Bounds-checked little-endian reader over one record's content; `base` is its file offset.
  struct Cursor {
    std::string_view data;
    std::size_t base;
    const McapParser* parser;
    std::size_t pos = 0;

    std::string_view Bytes(std::size_t n) {
      if (data.size() - pos < n) {
        throw ParseError(parser->Where(base + pos) + "record too short: needs " +
                         std::to_string(n) + " more bytes, has " +
                         std::to_string(data.size() - pos));
      }
      const std::string_view b = data.substr(pos, n);
      pos += n;
      return b;
    }
    template <typename T>
    T Get() {
      T v;
      std::memcpy(&v, Bytes(sizeof(T)).data(), sizeof(T));
      return v;
    }
    std::uint16_t U16() { return Get<std::uint16_t>(); }
    std::uint32_t U32() { return Get<std::uint32_t>(); }
    std::uint64_t U64() { return Get<std::uint64_t>(); }
    std::string String() { return std::string(Bytes(U32())); }
    std::string_view Rest() { return Bytes(data.size() - pos); }
  };

  std::string Where(std::size_t offset) const {
    return path_ + ": byte " + std::to_string(offset) + ": ";
  }

  // True if the whole record at `pos` of `data` (its 9-byte opcode and length, and the content)
  // is there.
  static bool RecordFits(std::string_view data, std::size_t pos) {
    if (data.size() - pos < 9) return false;
    std::uint64_t length;
    std::memcpy(&length, data.data() + pos + 1, 8);
    return length <= data.size() - pos - 9;
  }

  // Reads the record at *pos of `data` (whose first byte is at file offset `base`).
  std::pair<std::uint8_t, std::string_view> NextRecord(std::string_view data, std::size_t* pos,
                                                       std::size_t base) const {
    const std::size_t at = base + *pos;
    if (data.size() - *pos < 9) throw ParseError(Where(at) + "truncated record header");
    const auto op = static_cast<std::uint8_t>(data[*pos]);
    std::uint64_t length;
    std::memcpy(&length, data.data() + *pos + 1, 8);
    if (length > data.size() - *pos - 9) {
      throw ParseError(Where(at) + "record (opcode " + std::to_string(op) + ") of " +
                       std::to_string(length) + " bytes runs past the end");
    }
    const std::string_view content = data.substr(*pos + 9, static_cast<std::size_t>(length));
    *pos += 9 + static_cast<std::size_t>(length);
    return {op, content};
  }

  void CheckSummaryCrc() {
    const std::string_view file = file_;
    const std::size_t footer = file.size() - sizeof(mcap::kMagic) - 29;
    Cursor c{file.substr(footer, 29), footer, this};
    if (static_cast<std::uint8_t>(c.Bytes(1)[0]) != mcap::kFooter || c.U64() != 20) {
      throw ParseError(Where(footer) + "truncated: no Footer record before the closing magic");
    }
    const std::uint64_t summary_start = c.U64();
    c.U64();  // summary_offset_start
    const std::uint32_t crc = c.U32();
    if (summary_start == 0 || crc == 0) return;
    if (summary_start > footer) throw ParseError(Where(footer) + "summary_start past the footer");
    const std::size_t start = static_cast<std::size_t>(summary_start);
    if (Crc32(file.substr(start, footer + 25 - start)) != crc) {
      throw ParseError(Where(start) + "summary CRC mismatch");
    }
  }

  void ReadChunk(std::string_view content, std::size_t base) {
    Cursor c{content, base, this};
    c.U64();  // message_start_time
    c.U64();  // message_end_time
    const std::uint64_t size = c.U64();
    const std::uint32_t crc = c.U32();
    const std::string compression = c.String();
    const std::uint64_t compressed_size = c.U64();
    const std::size_t records_at = base + c.pos;
    const std::string_view compressed =
        c.Bytes(static_cast<std::size_t>(std::min<std::uint64_t>(compressed_size, content.size())));
    if (compressed.size() != compressed_size) {
      throw ParseError(Where(records_at) + "chunk records run past the record");
    }
    if (size > kMaxChunkBytes) throw ParseError(Where(base) + "chunk too large");
    // A damaged size field must not make us allocate: check it against the frame's own.
    if (compression == "zstd") {
      const unsigned long long declared =
          ZSTD_getFrameContentSize(compressed.data(), compressed.size());
      if (declared != ZSTD_CONTENTSIZE_UNKNOWN && declared != size) {
        throw ParseError(Where(records_at) + "zstd chunk does not decompress: frame holds " +
                         std::to_string(declared) + " bytes, chunk says " + std::to_string(size));
      }
    }
    std::string_view records;
    if (compression.empty()) {
      if (compressed.size() != size) throw ParseError(Where(base) + "chunk size mismatch");
      records = compressed;
    } else if (compression == "zstd") {
      buffer_.resize(static_cast<std::size_t>(size));
      const std::size_t n =
          ZSTD_decompress(buffer_.data(), buffer_.size(), compressed.data(), compressed.size());
      if (ZSTD_isError(n) || n != size) {
        throw ParseError(Where(records_at) + "zstd chunk does not decompress" +
                         (ZSTD_isError(n) ? std::string(": ") + ZSTD_getErrorName(n) : ""));
      }
      records = buffer_;
    } else if (compression == "lz4") {
      buffer_.resize(static_cast<std::size_t>(size));
      records = buffer_;
      LZ4F_dctx* ctx = nullptr;
      LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION);
      std::size_t out_size = buffer_.size(), in_size = compressed.size();
      const std::size_t rc =
          LZ4F_decompress(ctx, buffer_.data(), &out_size, compressed.data(), &in_size, nullptr);
      LZ4F_freeDecompressionContext(ctx);
      if (LZ4F_isError(rc) || rc != 0 || out_size != size) {
        throw ParseError(Where(records_at) + "lz4 chunk does not decompress" +
                         (LZ4F_isError(rc) ? std::string(": ") + LZ4F_getErrorName(rc) : ""));
      }
    } else {
      throw ParseError(Where(base) + "unknown chunk compression '" + compression + "'");
    }
    if (crc != 0 && Crc32(records) != crc) {
      throw ParseError(Where(records_at) + "chunk CRC mismatch");
    }
    std::size_t pos = 0;
    while (pos < records.size()) {
      const std::size_t at = pos;
      const auto [op, inner] = NextRecord(records, &pos, records_at);
      Handle(op, inner, records_at + at + 9);
    }
  }

  void Handle(std::uint8_t op, std::string_view content, std::size_t base) {
    Cursor c{content, base, this};
    if (op == mcap::kSchema) {
      const std::uint16_t id = c.U16();
      schemas_[id] = c.String();  // name; encoding and data are not needed
    } else if (op == mcap::kChannel) {
      const std::uint16_t id = c.U16();
      const std::uint16_t schema = c.U16();
      RawBagTopic topic;
      topic.name = c.String();
      topic.encoding = c.String();
      Cursor map{c.Bytes(c.U32()), base + c.pos, this};
      while (map.pos < map.data.size()) {
        std::string key = map.String();
        std::string value = map.String();
        if (key.starts_with("slamrig.")) bag_.custom_data[std::move(key)] = std::move(value);
      }
      if (schema != 0) {
        const auto it = schemas_.find(schema);
        if (it == schemas_.end()) {
          throw ParseError(Where(base) + "channel " + topic.name + " uses unknown schema " +
                           std::to_string(schema));
        }
        topic.type = it->second;
      }
      if (channels_.count(id) == 0) {
        channels_[id] = bag_.topics.size();
        bag_.topics.push_back(std::move(topic));
      }
    } else if (op == mcap::kMessage) {
      const std::uint16_t channel = c.U16();
      c.U32();  // sequence
      const std::uint64_t log_time = c.U64();
      c.U64();  // publish_time
      const auto it = channels_.find(channel);
      if (it == channels_.end()) {
        throw ParseError(Where(base) + "message on unknown channel " + std::to_string(channel));
      }
      if (log_time > static_cast<std::uint64_t>(INT64_MAX)) {
        throw ParseError(Where(base) + "log time out of range");
      }
      bag_.messages.push_back(
          {it->second, static_cast<std::int64_t>(log_time), std::string(c.Rest())});
    }
    // Other records (indexes, statistics, attachments, metadata) are not needed for reading.
  }

  std::string path_;
  std::string file_;
  std::string buffer_;
  std::map<std::uint16_t, std::string> schemas_;
  std::map<std::uint16_t, std::size_t> channels_;
  RawBag bag_;
};

}  // namespace

RawBag ReadMcapFile(const std::string& path, bool recover_cut) {
  return McapParser(path).Parse(recover_cut);
}

}  // namespace slamrig::slam
