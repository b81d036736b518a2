#pragma once

// Reading an MCAP stream as its bytes arrive (a program's stdout): the counterpart of
// McapWriter's stream form (slam/io/bag/mcap_writer.h).

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>

namespace slamrig::slam {

/// One message of an MCAP stream, with what its channel and schema say.
struct McapStreamMessage {
  std::string topic;
  std::string schema;    ///< the schema's name ("geometry_msgs/msg/PoseStamped"); "" for none
  std::string encoding;  ///< the channel's message encoding ("cdr")
  std::uint64_t log_time_ns = 0;
  std::string data;
};

/// Reads an MCAP stream incrementally: bytes go in with Feed() as they come, whole messages come
/// out of Next(). The stream is the magic, a Header, then Schema, Channel and Message records
/// (Metadata, DataEnd and any other record not needed to read messages are skipped), and ends
/// with a Footer and the closing magic. Chunks are refused (a stream has its messages unchunked):
/// reading one would need all of it first. Every record length is checked against
/// `max_record_bytes` before anything waits for it or allocates. Throws ParseError naming
/// `name` and the byte offset: bad magic, a record too long, a Chunk, a channel on an unknown
/// schema, a message on an unknown channel, bytes after the closing magic.
class McapStreamReader {
 public:
  explicit McapStreamReader(std::string name, std::uint64_t max_record_bytes = 1ull << 30);

  /// Appends bytes read from the stream.
  void Feed(std::string_view bytes);
  /// The next whole message, or nullopt when the bytes fed so far hold none (more are needed,
  /// or the stream has ended).
  std::optional<McapStreamMessage> Next();
  /// The Footer and the closing magic have been read.
  bool ended() const { return ended_; }
  /// Bytes fed so far.
  std::uint64_t bytes() const { return consumed_ + (buffer_.size() - pos_); }
  /// A short printable excerpt of the bytes at the reading position (for messages about what a
  /// program wrote instead of a stream).
  std::string Excerpt() const;

 private:
  struct Channel {
    std::string topic;
    std::string schema;
    std::string encoding;
  };

  [[noreturn]] void Fail(std::uint64_t offset, const std::string& what) const;
  void Handle(std::uint8_t op, std::string_view content, std::uint64_t offset,
              std::optional<McapStreamMessage>* message);

  std::string name_;
  std::uint64_t max_record_bytes_;
  std::string buffer_;
  std::size_t pos_ = 0;
  std::uint64_t consumed_ = 0;  // bytes dropped from the front of buffer_
  bool magic_read_ = false;
  bool footer_read_ = false;
  bool ended_ = false;
  std::map<std::uint16_t, std::string> schemas_;
  std::map<std::uint16_t, Channel> channels_;
};

}  // namespace slamrig::slam
