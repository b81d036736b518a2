#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "slam/io/bag/message_sink.h"
#include "slam/types/time.h"

namespace slamrig::scenario {

/// Options of a LiveServer.
struct LiveOptions {
  /// The address to listen on: the local machine only unless asked otherwise.
  std::string address = "127.0.0.1";
  /// The TCP port; 0 picks a free one (LiveServer::port() says which).
  std::uint16_t port = 8765;
  /// The run's speed while a client is subscribed, as a factor of real time (1 real time, 2
  /// twice as fast, 0 as fast as it goes); a client changes it with the `slamrig.pace` parameter.
  double pace = 1.0;
  /// Holds the run at the first Pace() after a topic was declared until a client subscribes to
  /// something, so that a viewer opened after the start sees the run from its beginning.
  bool wait_for_watcher = false;
  /// Bytes of messages queued for one client before further messages to it are dropped.
  std::size_t queue_bytes = 16u << 20;
};

/// What a LiveServer did so far.
struct LiveStats {
  std::uint64_t sent = 0;     ///< message frames written to clients
  std::uint64_t dropped = 0;  ///< messages not queued because a client's queue was full
  std::uint64_t clients = 0;  ///< clients that connected
};

/// Serves a run's messages over the Foxglove WebSocket protocol (subprotocol
/// `foxglove.websocket.v1`), so that Foxglove shows the run as it happens: each topic is a
/// channel (encoding `cdr`, its ROS 2 type as schemaName and its `ros2msg` definition as schema,
/// as in run.mcap), advertised to every client when its first message arrives; a subscribed
/// client gets binary message frames stamped with the run's clock (ns), and `time` frames as the
/// clock advances; a latched topic's last message is sent again to a client when it subscribes.
/// The `parameters` capability holds `slamrig.pace` (see LiveOptions::pace).
///
/// The network lives on the server's own thread. Message() only copies into bounded per-client
/// queues (a full queue drops the message and counts it), so a slow, stuck or vanished client
/// never blocks the run; Pace() sleeps, and only while a client is subscribed and the pace is
/// above 0. Nothing a client does changes what the run computes.
class LiveServer final : public slam::MessageSink {
 public:
  /// Listens and starts the server's thread. Throws OutputError naming the address and port when
  /// it cannot listen (a port in use, an address not of this machine).
  explicit LiveServer(LiveOptions options);
  /// Stops the thread and closes every connection (Close(0) unless Close() was called).
  ~LiveServer() override;
  LiveServer(const LiveServer&) = delete;
  LiveServer& operator=(const LiveServer&) = delete;

  /// The port it listens on.
  std::uint16_t port() const;
  /// ws://ADDRESS:PORT.
  std::string url() const;

  void Message(const std::string& topic, slam::RosType type, bool latched, Time time,
               std::string_view cdr) override;
  /// True for a latched topic and for one a client is subscribed to; declares the topic.
  bool Wants(const std::string& topic, slam::RosType type, bool latched) override;
  /// The run has reached `time` on its own clock: sleeps until the wall clock catches up with
  /// it at the current pace while a client is subscribed; returns at once otherwise. With
  /// LiveOptions::wait_for_watcher, the first call after a topic was declared first waits for a
  /// subscription (or an interrupt signal).
  void Pace(Time time);
  /// Lets the clients receive what is queued for them, for at most `drain_s` seconds of wall
  /// time (less when none of them takes anything for half a second), then closes their
  /// connections and stops listening.
  void Close(double drain_s);

  LiveStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace slamrig::scenario
