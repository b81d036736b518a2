#include "slam/io/bag/bag_sink.h"

#include "slam/types/error.h"
#include "slam/types/validation.h"

namespace slamrig::slam {

std::vector<std::string> BagSinkOptions::Validate() const {
  Rules rules;
  rules.Nested("", writer.Validate()).Nested("", odometry.Validate());
  return rules.errors();
}

namespace {

const BagSinkOptions& Checked(const BagSinkOptions& options) {
  const std::vector<std::string> errors = options.Validate();
  if (!errors.empty()) throw ConfigError("bag sink: " + errors.front());
  return options;
}

}  // namespace

BagSink::BagSink(const std::string& folder, const BagSinkOptions& options)
    : writer_(folder, Checked(options).writer), odometry_(options.odometry) {}

BagSink::BagSink(McapWriter::Output output, const BagSinkOptions& options)
    : writer_(std::move(output), Checked(options).writer), odometry_(options.odometry) {}

void BagSink::Add(const Record& record, const GroundTruthPose* truth) {
  writer_.Write(record);
  const std::optional<OdometryPose> pose = odometry_.Add(record);
  // A logged OdometryPose went out with the record itself; ticks add the robot's own estimate.
  if (pose && std::holds_alternative<WheelTicks>(record)) writer_.Write(Record{*pose});
  if (std::holds_alternative<LaserScan>(record)) ++scans_;
  if (std::holds_alternative<RgbdFrame>(record)) ++frames_;
  if (truth != nullptr) writer_.Write(*truth);
}

void BagSink::Commit() { writer_.Commit(); }

}  // namespace slamrig::slam
