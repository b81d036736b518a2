#include "slam/io/bag/mcap_stream.h"

#include <cstring>

#include "slam/io/bag/mcap_records.h"
#include "slam/types/error.h"

namespace slamrig::slam {
namespace {

constexpr std::size_t kRecordHead = 9;  // opcode and uint64 length

// Bounds-checked little-endian reads over one record's content.
struct Cursor {
  std::string_view data;
  std::size_t pos = 0;

  bool Has(std::size_t n) const { return data.size() - pos >= n; }
  template <typename T>
  std::optional<T> Get() {
    if (!Has(sizeof(T))) return std::nullopt;
    T v;
    std::memcpy(&v, data.data() + pos, sizeof(T));
    pos += sizeof(T);
    return v;
  }
  std::optional<std::string> String() {
    const std::optional<std::uint32_t> n = Get<std::uint32_t>();
    if (!n || !Has(*n)) return std::nullopt;
    std::string s(data.substr(pos, *n));
    pos += *n;
    return s;
  }
};

}  // namespace

McapStreamReader::McapStreamReader(std::string name, std::uint64_t max_record_bytes)
    : name_(std::move(name)), max_record_bytes_(max_record_bytes) {}

void McapStreamReader::Fail(std::uint64_t offset, const std::string& what) const {
  throw ParseError(name_ + ": byte " + std::to_string(offset) + ": " + what);
}

std::string McapStreamReader::Excerpt() const {
  std::string text;
  for (std::size_t i = pos_; i < buffer_.size() && i < pos_ + 24; ++i) {
    const auto c = static_cast<unsigned char>(buffer_[i]);
    if (c >= 0x20 && c < 0x7f && c != '\\') {
      text += static_cast<char>(c);
    } else {
      char escaped[8];
      std::snprintf(escaped, sizeof(escaped), "\\x%02x", c);
      text += escaped;
    }
  }
  return text;
}

void McapStreamReader::Feed(std::string_view bytes) {
  if (ended_ && !bytes.empty()) Fail(this->bytes(), "bytes after the closing magic");
  // Drop what has been read once it is most of the buffer: appends stay amortised O(1).
  if (pos_ > 0 && pos_ >= buffer_.size() / 2) {
    buffer_.erase(0, pos_);
    consumed_ += pos_;
    pos_ = 0;
  }
  buffer_.append(bytes);
}

std::optional<McapStreamMessage> McapStreamReader::Next() {
  const std::string_view magic(mcap::kMagic, sizeof(mcap::kMagic));
  while (!ended_) {
    const std::uint64_t offset = consumed_ + pos_;
    const std::string_view rest = std::string_view(buffer_).substr(pos_);
    if (!magic_read_ || footer_read_) {
      // The opening magic, or the closing one after the Footer: compared as far as it came.
      const std::size_t n = std::min(rest.size(), magic.size());
      if (rest.substr(0, n) != magic.substr(0, n)) {
        Fail(offset, footer_read_ ? "no closing magic after the Footer"
                                  : "not an MCAP stream (it starts with '" + Excerpt() + "')");
      }
      if (n < magic.size()) return std::nullopt;
      pos_ += magic.size();
      ended_ = footer_read_;
      magic_read_ = true;
      if (ended_ && pos_ < buffer_.size())
        Fail(offset + magic.size(), "bytes after the closing magic");
      continue;
    }
    if (rest.size() < kRecordHead) return std::nullopt;
    const auto op = static_cast<std::uint8_t>(rest[0]);
    std::uint64_t length;
    std::memcpy(&length, rest.data() + 1, sizeof(length));
    if (length > max_record_bytes_) {
      Fail(offset, "record (opcode " + std::to_string(op) + ") of " + std::to_string(length) +
                       " bytes: longer than the " + std::to_string(max_record_bytes_) +
                       " a record may have");
    }
    if (rest.size() - kRecordHead < length) return std::nullopt;
    const std::string_view content = rest.substr(kRecordHead, static_cast<std::size_t>(length));
    pos_ += kRecordHead + static_cast<std::size_t>(length);
    std::optional<McapStreamMessage> message;
    Handle(op, content, offset, &message);
    if (message) return message;
  }
  return std::nullopt;
}

void McapStreamReader::Handle(std::uint8_t op, std::string_view content, std::uint64_t offset,
                              std::optional<McapStreamMessage>* message) {
  Cursor c{content};
  const std::string too_short = " record too short for its fields";
  if (op == mcap::kSchema) {
    const auto id = c.Get<std::uint16_t>();
    const auto name = c.String();
    if (!id || !name) Fail(offset, "Schema" + too_short);
    schemas_[*id] = *name;  // its encoding and text are not needed to read messages
  } else if (op == mcap::kChannel) {
    const auto id = c.Get<std::uint16_t>();
    const auto schema = c.Get<std::uint16_t>();
    const auto topic = c.String();
    const auto encoding = c.String();
    if (!id || !schema || !topic || !encoding) Fail(offset, "Channel" + too_short);
    Channel channel{*topic, "", *encoding};
    if (*schema != 0) {
      const auto it = schemas_.find(*schema);
      if (it == schemas_.end()) {
        Fail(offset, "channel " + *topic + " uses schema " + std::to_string(*schema) +
                         ", which no Schema record before it defines");
      }
      channel.schema = it->second;
    }
    channels_[*id] = std::move(channel);
  } else if (op == mcap::kMessage) {
    const auto channel = c.Get<std::uint16_t>();
    const auto sequence = c.Get<std::uint32_t>();
    const auto log_time = c.Get<std::uint64_t>();
    const auto publish_time = c.Get<std::uint64_t>();
    if (!channel || !sequence || !log_time || !publish_time) Fail(offset, "Message" + too_short);
    const auto it = channels_.find(*channel);
    if (it == channels_.end()) {
      Fail(offset, "message on channel " + std::to_string(*channel) +
                       ", which no Channel record before it defines");
    }
    *message = McapStreamMessage{it->second.topic, it->second.schema, it->second.encoding,
                                 *log_time, std::string(content.substr(c.pos))};
  } else if (op == mcap::kChunk) {
    Fail(offset, "a Chunk record: a stream has its messages unchunked");
  } else if (op == mcap::kFooter) {
    footer_read_ = true;
  }
  // Header, Metadata, DataEnd, indexes, attachments: nothing a reader of messages needs.
}

}  // namespace slamrig::slam
