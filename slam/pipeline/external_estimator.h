#pragma once

// The `external` algorithm: any program as an estimator. Offline, the pipeline only describes it
// (its options) and keeps the records it is given; the scenario runner (scenarios/external_run.h)
// writes them to a file, runs the program on it and reads its trajectory back. As a stream, the
// estimator talks to the running program through an ExternalStreamLink the scenario runner
// attaches (scenarios/external_stream.h): starting processes and writing report folders is the
// runner's business, not the pipeline's.

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
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

/// How the program gets the records.
enum class ExternalMode {
  kOffline,  ///< all at once in a file after the run, its trajectory read back from a file
  kStream,   ///< as they happen, an MCAP stream on its stdin, a pose per scan on its stdout
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
  ExternalMode mode = ExternalMode::kOffline;
  /// The file format offline (a stream is always MCAP).
  ExternalInput input = ExternalInput::kCarmen;
  /// Past this wall time the program is killed (SIGKILL) and the configuration fails: offline
  /// its whole run, as a stream from its start to its exit after the end of the stream.
  double timeout_s = 600.0;
  /// A stream's program must answer each scan within this wall time (it is waited for that
  /// long, then killed).
  double answer_timeout_s = 60.0;

  /// One message per broken rule.
  std::vector<std::string> Validate() const;
};

template <typename V>
void VisitFields(V& v, ExternalEstimatorOptions& o) {
  v("command", o.command);
  v.Enum("mode", o.mode, {{ExternalMode::kOffline, "offline"}, {ExternalMode::kStream, "stream"}});
  v.Enum("input", o.input,
         {{ExternalInput::kCarmen, "carmen"},
          {ExternalInput::kMcap, "mcap"},
          {ExternalInput::kSqlite3, "sqlite3"},
          {ExternalInput::kEce276a, "ece276a"}});
  v("timeout_s", o.timeout_s);
  v("answer_timeout_s", o.answer_timeout_s);
}

/// `command` with the placeholders replaced in every argument (each occurrence, anywhere in it).
std::vector<std::string> SubstituteExternalArguments(const std::vector<std::string>& command,
                                                     const std::string& input,
                                                     const std::string& output, std::uint64_t seed);

/// A stream-mode program as the estimator sees it; the scenario runner implements it. After a
/// failure (the program crashed, hung, wrote something else than the protocol) every call is a
/// no-op and Scan() answers nullopt: the configuration's result is then its failure alone.
class ExternalStreamLink {
 public:
  virtual ~ExternalStreamLink() = default;
  /// A record as it arrives, scans excepted (they go through Scan()).
  virtual void Record(const Record& record) = 0;
  /// A scan when the estimators take it: written, then the program's pose at its stamp waited
  /// for; nullopt once the program has failed.
  virtual std::optional<Pose2> Scan(const LaserScan& scan) = 0;
  /// The end of the records: the stream is closed and what the program writes last is read.
  virtual void Finish() = 0;
  /// Why the program failed (one line); empty while it has not.
  virtual std::string failure() const = 0;
  /// The map the program wrote at the end (in its frame), if it wrote one.
  virtual const std::optional<OccupancyGrid>& map() const = 0;
  /// ExternalEstimator::StatisticNames()' values.
  virtual std::map<std::string, double> Statistics() const = 0;
};

/// The in-process side of an external estimator. Offline it keeps every record it is given (the
/// same records every configuration gets, in the same order) for the runner to write out, and
/// reports the identity at each scan; the runner replaces its trajectory and map with the
/// program's. As a stream it passes the records to its link as they come and reports the
/// program's pose at each scan (the identity once the program has failed); its map is the
/// program's. Its map is empty until then.
class ExternalEstimator final : public Estimator {
 public:
  ExternalEstimator(const ExternalEstimatorOptions& options, const EstimatorContext& context);

  void AddRecord(const Record& record) override;
  ScanEstimate AddScan(const SyncedScan& scan) override;
  void Finish() override;
  const OccupancyGrid& map() const override;
  std::map<std::string, double> Statistics() const override;

  const ExternalEstimatorOptions& options() const { return options_; }
  const EstimatorContext& context() const { return context_; }
  const std::vector<Record>& records() const { return records_; }
  bool streams() const { return options_.mode == ExternalMode::kStream; }
  /// A stream's link, which the scenario runner attaches before the first record.
  void Attach(std::unique_ptr<ExternalStreamLink> link) { link_ = std::move(link); }
  const ExternalStreamLink* link() const { return link_.get(); }

  /// What the runner adds to an external configuration's metrics.
  static std::vector<std::string> StatisticNames() {
    return {"peak_rss_mib", "input_write_s", "child_wall_s"};
  }

 private:
  // Throws ConfigError when a stream has no link (a caller that starts no program).
  void RequireLink() const;

  ExternalEstimatorOptions options_;
  EstimatorContext context_;
  std::vector<Record> records_;
  std::unique_ptr<ExternalStreamLink> link_;
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
