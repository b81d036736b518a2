#pragma once

// The scenario runner's side of an external estimator in `mode: stream`
// (slam/pipeline/external_estimator.h): the program started once, the records written to its
// stdin as an MCAP stream as they happen, and after each scan its pose read from its stdout, in
// lockstep (docs/external.md, "Streaming").

#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "scenarios/external_run.h"
#include "slam/io/bag/bag_sink.h"
#include "slam/io/bag/mcap_stream.h"
#include "slam/pipeline/external_estimator.h"

namespace slamrig::scenario {

/// Topics of the program's answer stream.
inline constexpr const char* kStreamEstimateTopic = "/estimate";  ///< PoseStamped, one per scan
inline constexpr const char* kStreamMapTopic = "/map";            ///< OccupancyGrid, optional
/// Name of the Metadata record that opens the bench's stream: the robot's wheel geometry.
inline constexpr const char* kStreamRobotMetadata = "slamrig.robot";

/// One running program fed in lockstep. Every pipe is non-blocking and every wait polls with a
/// deadline (answer_timeout_s for a scan's answer and for the program to take its input, and
/// timeout_s from the start for the whole run), so a program that stops reading or writing costs
/// at most its timeout; a write to a program that has gone fails with EPIPE (SIGPIPE is blocked
/// around the write and a pending one taken back).
/// The first failure kills the program and becomes `failure()`: "PROGRAM: what; stderr: <its
/// last 3 lines>". SIGINT/SIGTERM throw Interrupted from any wait; the destructor kills and
/// reaps a program still running.
class ExternalStreamSession final : public slam::ExternalStreamLink {
 public:
  /// Starts the program in `work_dir/external/<name>/` (made empty first), stderr to
  /// `work_dir/<name>_stderr.txt`, and encodes the head of the stream: the Metadata record
  /// kStreamRobotMetadata with the estimator context's wheel geometry and odometry.use_gyro.
  /// Throws OutputError when a folder cannot be made.
  ExternalStreamSession(const std::string& name, const slam::ExternalEstimator& estimator,
                        const std::string& work_dir);
  ~ExternalStreamSession() override;
  ExternalStreamSession(const ExternalStreamSession&) = delete;
  ExternalStreamSession& operator=(const ExternalStreamSession&) = delete;

  void Record(const slamrig::Record& record) override;
  std::optional<Pose2> Scan(const LaserScan& scan) override;
  void Finish() override;
  std::string failure() const override { return failure_; }
  const std::optional<slam::OccupancyGrid>& map() const override { return map_; }
  std::map<std::string, double> Statistics() const override;

 private:
  using Clock = std::chrono::steady_clock;
  enum class Wait { kDone, kEndOfFile, kTimeout };

  void Fail(const std::string& what);
  void Kill();
  // Writes what the stream holds, reading stdout meanwhile (a program may write while we do).
  Wait WriteOut(Clock::time_point deadline);
  // The next message of the answer stream.
  Wait NextMessage(Clock::time_point deadline, std::optional<slam::McapStreamMessage>* message);
  bool ReadSome();  // false at end of file
  void PollPeak();
  // Takes one message of the answer: a pose (into *pose when it is the one for `scan`), a map.
  void Take(const slam::McapStreamMessage& message, const LaserScan* scan,
            std::optional<Pose2>* pose);
  std::string Counts() const;
  // answer_timeout_s from now, or the run's deadline when sooner.
  Clock::time_point AnswerDeadline() const;
  std::string TimeoutText(Clock::time_point answer_deadline) const;
  // Waits for the program's exit (until the run's deadline); its end as a failure, or "".
  std::string Reap();

  std::string program_;
  slam::ExternalEstimatorOptions options_;
  std::string stderr_path_;
  pid_t pid_ = -1;
  int stdin_fd_ = -1;
  int stdout_fd_ = -1;
  bool stdout_eof_ = false;
  Clock::time_point start_;
  Clock::time_point run_deadline_;
  Clock::time_point next_peak_poll_;
  std::string stream_;  // encoded, not yet written
  std::size_t written_ = 0;
  slam::BagSink sink_;
  slam::McapStreamReader answers_;
  std::size_t scans_ = 0;
  std::size_t poses_ = 0;
  Time last_scan_time_;
  std::string failure_;
  std::optional<slam::OccupancyGrid> map_;
  double encode_s_ = 0.0;
  double child_wall_s_ = 0.0;
  long parent_kb_ = 0;
  long polled_peak_kb_ = 0;
  long peak_rss_kb_ = 0;
  bool finished_ = false;
};

}  // namespace slamrig::scenario
