#pragma once

// The `external` algorithm: any program as an estimator. The pipeline only describes it (its
// options) and keeps the records it is given; the scenario runner (scenarios/external_run.h)
// writes them to a file, runs the program on it and reads its trajectory back, since starting
// processes and writing report folders is the runner's business, not the pipeline's.

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "slam/grid/occupancy_grid.h"
#include "slam/pipeline/algorithm.h"
#include "slam/pipeline/estimator.h"

namespace slamrig::slam {

/// The file format an external estimator reads its records in.
enum class ExternalInput {
  kCarmen,   ///< input.log: PARAM, ODOM, ROBOTLASER1 (slam::CarmenSink)
  kMcap,     ///< input/: a ROS 2 bag with MCAP storage (slam::BagSink)
  kSqlite3,  ///< input/: a ROS 2 bag with sqlite3 storage
  kEce276a,  ///< input/: Encoders<N>.npz, Imu<N>.npz, Hokuyo<N>.npz (slam::Ece276aSink)
};

/// The placeholders an argument of `command` may hold.
inline constexpr const char* kExternalInputPlaceholder = "{input}";
inline constexpr const char* kExternalOutputPlaceholder = "{output}";
inline constexpr const char* kExternalSeedPlaceholder = "{seed}";

struct ExternalEstimatorOptions {
  /// The program and its arguments, run without a shell. The first names the program: a path,
  /// or a name looked up on PATH. An argument starting with ./ or ../ is a path relative to the
  /// scenario file, made absolute when read. `{input}`, `{output}` and `{seed}` are replaced in
  /// every argument.
  std::vector<std::string> command;
  ExternalInput input = ExternalInput::kCarmen;
  /// Past this wall time the program is killed (SIGKILL) and the configuration fails.
  double timeout_s = 600.0;

  /// One message per broken rule.
  std::vector<std::string> Validate() const;
};

template <typename V>
void VisitFields(V& v, ExternalEstimatorOptions& o) {
  v("command", o.command);
  v.Enum("input", o.input,
         {{ExternalInput::kCarmen, "carmen"},
          {ExternalInput::kMcap, "mcap"},
          {ExternalInput::kSqlite3, "sqlite3"},
          {ExternalInput::kEce276a, "ece276a"}});
  v("timeout_s", o.timeout_s);
}

/// `command` with the placeholders replaced in every argument (each occurrence, anywhere in it).
std::vector<std::string> SubstituteExternalArguments(const std::vector<std::string>& command,
                                                     const std::string& input,
                                                     const std::string& output, std::uint64_t seed);

/// The in-process side of an external estimator: it keeps every record it is given (the same
/// records every configuration gets, in the same order) for the runner to write out, and
/// reports the identity at each scan; the runner replaces its trajectory and map with the
/// program's. Its map is empty.
class ExternalEstimator final : public Estimator {
 public:
  ExternalEstimator(const ExternalEstimatorOptions& options, const EstimatorContext& context);

  void AddRecord(const Record& record) override { records_.push_back(record); }
  ScanEstimate AddScan(const SyncedScan& /*scan*/) override { return {}; }
  const OccupancyGrid& map() const override { return map_; }

  const ExternalEstimatorOptions& options() const { return options_; }
  const EstimatorContext& context() const { return context_; }
  const std::vector<Record>& records() const { return records_; }

  /// What the runner adds to an external configuration's metrics.
  static std::vector<std::string> StatisticNames() {
    return {"peak_rss_mib", "input_write_s", "child_wall_s"};
  }

 private:
  ExternalEstimatorOptions options_;
  EstimatorContext context_;
  std::vector<Record> records_;
  OccupancyGrid map_{OccupancyGridOptions{}};
};

/// The AlgorithmOptions of `external`: the field table of ExternalEstimatorOptions, with the
/// relative paths of `command` resolved against the scenario file's folder as they are read.
class ExternalAlgorithmOptions final : public AlgorithmOptions {
 public:
  explicit ExternalAlgorithmOptions(ExternalEstimatorOptions options = {})
      : options_(std::move(options)) {}
  std::unique_ptr<AlgorithmOptions> Clone() const override {
    return std::make_unique<ExternalAlgorithmOptions>(options_);
  }
  void Visit(FieldReader& reader) override;
  void Visit(FieldWriter& writer) override { VisitFields(writer, options_); }
  void Visit(JsonFieldWriter& writer) override { VisitFields(writer, options_); }
  std::vector<std::string> Validate() const override { return options_.Validate(); }
  std::unique_ptr<Estimator> MakeEstimator(const EstimatorContext& context) const override {
    return std::make_unique<ExternalEstimator>(options_, context);
  }
  const ExternalEstimatorOptions& options() const { return options_; }

 private:
  ExternalEstimatorOptions options_;
};

}  // namespace slamrig::slam
