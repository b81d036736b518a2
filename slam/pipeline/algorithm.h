#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "slam/config/fields.h"
#include "slam/eval/json_fields.h"
#include "slam/odometry/wheel_odometry.h"
#include "slam/pipeline/estimator.h"

namespace slamrig::slam {

/// A gyro's white noise in the continuous-time parameters of the robot file (Kalibr's), for an
/// estimator to model the gyro it reads instead of guessing.
struct GyroNoiseModel {
  double noise_density_rad_s_sqrt_hz = 0.0;  ///< white rate noise
  double random_walk_rad_s2_sqrt_hz = 0.0;   ///< bias random walk
  double rate_hz = 0.0;                      ///< samples per second
};

/// What every estimator is built with besides its own options.
struct EstimatorContext {
  std::uint64_t seed = 1;  ///< the estimator's own random seed (a named stream of the run's)
  DiffDriveParams robot;   ///< the wheel geometry of the source (for estimators that read ticks)
  bool use_gyro = true;    ///< odometry.use_gyro: estimators that read the IMU themselves honour it
  /// The source's gyro noise as its robot file states it, where there is one (a simulated
  /// robot); nullopt for logs, whose gyro is not characterised.
  std::optional<GyroNoiseModel> gyro;
  /// Whether the scans' increments are the robot's own odometry (wheels, a gyro, a platform's
  /// poses); false when the source has none and they come from scan matching
  /// (ScanMatchedOdometry), which is no independent yardstick for a scan match.
  bool own_odometry = true;
};

/// One algorithm's options behind one interface: a plain options struct with a VisitFields
/// table, read strictly from YAML and written to YAML and JSON by that same table, validated,
/// and turned into an Estimator. Made by AlgorithmOptionsFor<Options, EstimatorType>.
class AlgorithmOptions {
 public:
  virtual ~AlgorithmOptions() = default;
  virtual std::unique_ptr<AlgorithmOptions> Clone() const = 0;
  /// Reads the table's keys present in `reader`'s map (nested maps are validated as read).
  virtual void Visit(FieldReader& reader) = 0;
  /// Writes every field.
  virtual void Visit(FieldWriter& writer) = 0;
  virtual void Visit(JsonFieldWriter& writer) = 0;
  /// One message per broken rule, named by the table's keys ("particles = 0; must be > 0").
  virtual std::vector<std::string> Validate() const = 0;
  /// A new estimator; the options must be valid.
  virtual std::unique_ptr<Estimator> MakeEstimator(const EstimatorContext& context) const = 0;
};

/// AlgorithmOptions for an options struct `Options` (with VisitFields and Validate()) and an
/// estimator `E` constructed as E(const Options&, const EstimatorContext&).
template <typename Options, typename E>
class AlgorithmOptionsFor final : public AlgorithmOptions {
 public:
  explicit AlgorithmOptionsFor(Options options) : options_(std::move(options)) {}
  std::unique_ptr<AlgorithmOptions> Clone() const override {
    return std::make_unique<AlgorithmOptionsFor>(options_);
  }
  void Visit(FieldReader& reader) override { VisitFields(reader, options_); }
  void Visit(FieldWriter& writer) override { VisitFields(writer, options_); }
  void Visit(JsonFieldWriter& writer) override { VisitFields(writer, options_); }
  std::vector<std::string> Validate() const override { return options_.Validate(); }
  std::unique_ptr<Estimator> MakeEstimator(const EstimatorContext& context) const override {
    return std::make_unique<E>(options_, context);
  }
  const Options& options() const { return options_; }

 private:
  Options options_;
};

/// One entry of the algorithm table: the only place that knows which algorithms exist.
struct Algorithm {
  std::string name;                  ///< `algorithm:` in a scenario, `--algorithm` on the CLI
  std::string summary;               ///< one line for --help
  std::vector<std::string> presets;  ///< named starting points; the first is the default
  /// The names Estimator::Statistics() reports: the estimator's own StatisticNames(), the one
  /// declaration that expectations and metrics.json both follow (EstimatorRunner checks each run).
  std::vector<std::string> statistics;
  /// The options of `preset` (one of `presets`).
  std::function<std::unique_ptr<AlgorithmOptions>(const std::string& preset)> make_options;
  /// It reports a landmark map (Estimator::Landmarks()), which simulated runs score against the
  /// world's pillars (the landmark metrics of metrics.json).
  bool maps_landmarks = false;
  /// It reports loop closures (Estimator::LoopClosures()), scored against the reference.
  bool closes_loops = false;
  /// `statistics` is all it reports; false for an algorithm whose statistics are only known
  /// once it runs (a Python class's).
  bool statistics_declared = true;
  /// It may run on a thread of its own beside the run's other estimators: false for a Python
  /// class (one interpreter) and a program of the user's (a stream's program ends before an
  /// offline one starts).
  bool runs_beside_others = true;
};

/// Every algorithm, in the order --help lists them.
const std::vector<Algorithm>& Algorithms();
/// The algorithm called `name`, or nullptr.
const Algorithm* FindAlgorithm(const std::string& name);
/// "dead-reckoning, pf, ..." for messages.
std::string AlgorithmNames();

}  // namespace slamrig::slam
