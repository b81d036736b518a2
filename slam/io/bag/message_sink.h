#pragma once

#include <string>
#include <string_view>

#include "slam/io/bag/ros_messages.h"
#include "slam/types/time.h"

namespace slamrig::slam {

/// Where encoded ROS 2 messages go besides (or instead of) a BagWriter's own file: the live
/// view of a run (scenario::LiveServer) takes the same messages as its recording. Each message
/// is one CDR payload of `type` (RosTypeName, RosMessageDefinition give its schema) on `topic`,
/// at `time` on the run's clock; `latched` topics (transient-local, as /tf_static and /truth/map)
/// hold their last message for late subscribers. Called from the thread that writes; an
/// implementation must not block it.
class MessageSink {
 public:
  virtual ~MessageSink() = default;
  virtual void Message(const std::string& topic, RosType type, bool latched, Time time,
                       std::string_view cdr) = 0;
  /// Whether a message on `topic` would be used now; it also makes the topic known (so that a
  /// client can ask for it). A producer may skip making a message no one wants; a latched
  /// topic's messages are always wanted.
  virtual bool Wants(const std::string& topic, RosType type, bool latched) {
    (void)topic, (void)type, (void)latched;
    return true;
  }
};

}  // namespace slamrig::slam
