#include "slam/pipeline/external_estimator.h"

#include <cmath>
#include <filesystem>

#include "slam/types/error.h"
#include "slam/types/validation.h"

namespace slamrig::slam {

std::vector<std::string> ExternalEstimatorOptions::Validate() const {
  Rules rules;
  rules.Required(!command.empty(), "command",
                 "a non-empty list: the program, then its arguments, e.g. [python3, "
                 "./my_slam.py, \"{input}\", \"{output}\"]");
  if (!command.empty() && command.front().empty()) {
    rules.Add("command[0]: the program is an empty text");
  }
  rules.Require(std::isfinite(timeout_s) && timeout_s > 0.0, "timeout_s", timeout_s, "must be > 0")
      .Require(std::isfinite(answer_timeout_s) && answer_timeout_s > 0.0, "answer_timeout_s",
               answer_timeout_s, "must be > 0");
  if (mode == ExternalMode::kStream && input != ExternalInput::kCarmen) {
    rules.Add(
        "input: set with mode stream, which always streams MCAP on stdin (input is for mode "
        "offline)");
  }
  if (mode == ExternalMode::kStream) {
    for (std::size_t i = 0; i < command.size(); ++i) {
      for (const char* placeholder : {kExternalInputPlaceholder, kExternalOutputPlaceholder}) {
        if (command[i].find(placeholder) != std::string::npos) {
          rules.Add("command[" + std::to_string(i) + "] = '" + command[i] + "'; " + placeholder +
                    " has no meaning with mode stream (the records come on stdin, the poses go to "
                    "stdout)");
        }
      }
    }
  }
  return rules.errors();
}

std::vector<std::string> SubstituteExternalArguments(const std::vector<std::string>& command,
                                                     const std::string& input,
                                                     const std::string& output,
                                                     std::uint64_t seed) {
  const std::pair<std::string, std::string> replacements[] = {
      {kExternalInputPlaceholder, input},
      {kExternalOutputPlaceholder, output},
      {kExternalSeedPlaceholder, std::to_string(seed)}};
  std::vector<std::string> args;
  for (const std::string& argument : command) {
    // One pass from left to right: text that a replacement brings in is never replaced again.
    std::string out;
    std::size_t i = 0;
    while (i < argument.size()) {
      bool replaced = false;
      for (const auto& [placeholder, value] : replacements) {
        if (argument.compare(i, placeholder.size(), placeholder) == 0) {
          out += value;
          i += placeholder.size();
          replaced = true;
          break;
        }
      }
      if (!replaced) out += argument[i++];
    }
    args.push_back(std::move(out));
  }
  return args;
}

ExternalEstimator::ExternalEstimator(const ExternalEstimatorOptions& options,
                                     const EstimatorContext& context)
    : options_(options), context_(context) {}

void ExternalEstimator::RequireLink() const {
  if (link_ == nullptr) {
    throw ConfigError(
        "algorithm external with mode stream runs its program from the scenario runner (slamrig "
        "run, slamrig slam --out); this caller started none");
  }
}

void ExternalEstimator::AddRecord(const Record& record) {
  if (!streams()) {
    records_.push_back(record);
    return;
  }
  RequireLink();
  // A scan goes when the estimators take it (AddScan): after the odometry it waits for.
  if (!std::holds_alternative<LaserScan>(record)) link_->Record(record);
}

ScanEstimate ExternalEstimator::AddScan(const SyncedScan& scan) {
  ScanEstimate estimate;
  if (!streams()) return estimate;
  RequireLink();
  if (const std::optional<Pose2> pose = link_->Scan(scan.scan)) estimate.pose = *pose;
  return estimate;
}

void ExternalEstimator::Finish() {
  if (link_) link_->Finish();
}

const OccupancyGrid& ExternalEstimator::map() const {
  if (link_ && link_->map()) return *link_->map();
  return map_;
}

std::map<std::string, double> ExternalEstimator::Statistics() const {
  return link_ ? link_->Statistics() : std::map<std::string, double>{};
}

void ExternalAlgorithmOptions::Visit(FieldReader& reader) {
  namespace fs = std::filesystem;
  const std::vector<std::string> before = options_.command;
  VisitFields(reader, options_);
  if (options_.command == before) return;  // not set here: already resolved
  // Relative to the scenario file, like a python estimator's module; written resolved, so that
  // config.yaml runs from anywhere.
  std::error_code error;
  const fs::path file(reader.node().file());
  const fs::path folder = fs::is_regular_file(file, error) ? fs::absolute(file, error).parent_path()
                                                           : fs::current_path();
  for (std::string& argument : options_.command) {
    if (argument.rfind("./", 0) == 0 || argument.rfind("../", 0) == 0)
      argument = (folder / argument).lexically_normal().string();
  }
}

}  // namespace slamrig::slam
