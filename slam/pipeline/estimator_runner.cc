#include "slam/pipeline/estimator_runner.h"

#include <algorithm>
#include <chrono>

#include "slam/pipeline/algorithm.h"
#include "slam/types/check.h"
#include "slam/types/interrupt.h"

namespace slamrig::slam {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// An estimator reports exactly the statistics its algorithm declares (Algorithm::statistics),
// which expectations accept by name: a name added on one side only is a bug found at once.
void CheckDeclaredStatistics(const std::string& algorithm,
                             const std::map<std::string, double>& statistics) {
  const Algorithm* a = FindAlgorithm(algorithm);
  if (a == nullptr || !a->statistics_declared) return;
  std::string differences;
  for (const auto& [name, value] : statistics) {
    if (std::find(a->statistics.begin(), a->statistics.end(), name) == a->statistics.end())
      differences += " reported but not declared: " + name + ";";
  }
  for (const std::string& name : a->statistics) {
    if (!statistics.count(name)) differences += " declared but not reported: " + name + ";";
  }
  SLAMRIG_CHECK(differences.empty(), (algorithm + " statistics:" + differences).c_str());
}

}  // namespace

EstimatorRunner::EstimatorRunner(const EstimatorConfig& config, OdometrySource source,
                                 std::uint64_t run_seed)
    : config_(config),
      sync_(config.odometry, source),
      estimator_(MakeEstimator(config, run_seed, source != OdometrySource::kNone)) {
  run_.name = config.name;
  run_.algorithm = config.algorithm;
  run_.odometry_source = source;
  if (source == OdometrySource::kNone) scan_odometry_.emplace();
}

void EstimatorRunner::Add(const Record& record) {
  SLAMRIG_CHECK(!finished_, "EstimatorRunner::Add after Finish");
  const auto start = Clock::now();
  estimator_->AddRecord(record);
  if (const std::optional<ScanEstimate> e = estimator_->RecordEstimate()) {
    const Time time = RecordTime(record);
    if (run_.record_rate.empty() || run_.record_rate.poses().back().time <= time) {
      run_.record_rate.Append(time, e->pose);
      if (e->covariance) run_.record_rate_covariances.push_back(*e->covariance);
    }
  }
  for (const SyncedScan& s : sync_.Add(record)) Process(s);
  run_.wall_s += SecondsSince(start);
}

void EstimatorRunner::Finish() {
  if (finished_) return;
  const auto start = Clock::now();
  for (const SyncedScan& s : sync_.Flush()) Process(s);
  estimator_->Finish();
  finished_ = true;
  run_.wall_s += SecondsSince(start);
}

void EstimatorRunner::Process(const SyncedScan& synced) {
  ThrowIfInterrupted();  // a scan is the unit of work; SIGINT/SIGTERM stop between two
  const SyncedScan scan = scan_odometry_ ? scan_odometry_->Apply(synced) : synced;
  const ScanEstimate estimate = estimator_->AddScan(scan);
  const Time time = scan.scan.time;
  pose_ = estimate.pose;
  run_.online.Append(time, estimate.pose);
  if (estimate.mean_pose) run_.mean.Append(time, *estimate.mean_pose);
  if (estimate.covariance) run_.covariances.push_back(*estimate.covariance);
  lost_.push_back(estimate.lost.value_or(false));
  judged_scans_ += estimate.lost.has_value();
  if (!estimate.trace.empty()) {
    run_.trace_time_s.push_back(time.seconds());
    for (const TraceValue& v : estimate.trace) run_.traces[v.name].push_back(v.value);
  }
  if (on_scan_) on_scan_(run_.online.size() - 1, scan, estimate);
}

EstimatorRun EstimatorRunner::TakeResult() {
  SLAMRIG_CHECK(finished_, "EstimatorRunner::TakeResult before Finish");
  run_.final = run_.online;
  if (const auto revised = estimator_->RevisedPoses()) {
    SLAMRIG_CHECK(revised->size() == run_.online.size(), "revised poses: one per scan");
    Trajectory final;
    for (std::size_t i = 0; i < revised->size(); ++i)
      final.Append(run_.online[i].time, (*revised)[i]);
    run_.final = std::move(final);
  }
  if (run_.covariances.size() != run_.online.size()) run_.covariances.clear();
  if (run_.record_rate_covariances.size() != run_.record_rate.size())
    run_.record_rate_covariances.clear();
  run_.judges_itself = judged_scans_ > 0;
  SLAMRIG_CHECK(!run_.judges_itself || judged_scans_ == static_cast<int>(lost_.size()),
                "an estimator that judges itself judges every scan");
  if (run_.judges_itself) run_.lost_intervals = LostIntervals(run_.online, lost_);
  run_.statistics = estimator_->Statistics();
  CheckDeclaredStatistics(config_.algorithm, run_.statistics);
  run_.loop_closures = estimator_->LoopClosures();
  run_.rejected_loop_closures = estimator_->RejectedLoopClosures();
  run_.landmarks = estimator_->Landmarks();
  run_.map = estimator_->map();
  run_.gyro_fallbacks = sync_.gyro_fallbacks();
  run_.scans_without_odometry = sync_.scans_without_odometry();
  if (scan_odometry_) run_.scan_matched_odometry = scan_odometry_->counts();
  return std::move(run_);
}

EstimatorRun RunEstimator(
    const EstimatorConfig& config, const std::vector<Record>& records, std::uint64_t run_seed,
    const RunLimits& limits,
    std::function<void(std::size_t, const SyncedScan&, const ScanEstimate&)> on_scan) {
  const OdometrySource source = ResolveOdometrySource(records, config.odometry.source);
  // A scan limit: the records up to the one that completes scan max_scans.
  std::size_t end = records.size();
  if (limits.max_scans > 0) {
    std::size_t scans = 0;
    for (std::size_t i = 0; i < records.size(); ++i) {
      if (std::holds_alternative<LaserScan>(records[i]) && ++scans > limits.max_scans) {
        end = i;
        break;
      }
    }
  }
  EstimatorRunner runner(config, source, run_seed);
  runner.SetScanCallback(std::move(on_scan));
  for (std::size_t i = 0; i < end; ++i) runner.Add(records[i]);
  runner.Finish();
  return runner.TakeResult();
}

}  // namespace slamrig::slam
