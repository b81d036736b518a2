#pragma once

#include "slam/types/records.h"

namespace slamrig::slam {

/// Where a recorded run goes (a CARMEN log, a ROS 2 bag, ...): the sensor records in time
/// order, each with the reference pose at its time when the source knows one (the simulator's
/// truth), and nothing visible until Commit(). Sources and sinks are symmetric: what a sink
/// writes, a log reader (log_reader.h) reads back as the same records.
class RecordSink {
 public:
  virtual ~RecordSink() = default;
  /// One record; `truth` is the reference pose at its time, or nullptr.
  virtual void Add(const Record& record, const GroundTruthPose* truth) = 0;
  /// Writes what is still held back and moves the output into place; a sink destroyed without
  /// Commit() leaves nothing that looks complete.
  virtual void Commit() = 0;
};

}  // namespace slamrig::slam
