#include "scenarios/external_stream.h"

#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <thread>

#include "scenarios/child_process.h"
#include "slam/io/bag/cdr.h"
#include "slam/io/bag/ros_messages.h"
#include "slam/io/map_server.h"
#include "slam/types/error.h"
#include "slam/types/interrupt.h"

namespace slamrig::scenario {
namespace {

namespace fs = std::filesystem;

// Encoded bytes are written once this many wait (and at every scan).
constexpr std::size_t kFlushBytes = 1 << 20;
// Longest sleep of a wait, so that SIGINT/SIGTERM are seen soon.
constexpr int kPollSliceMs = 100;
// A pose is planar when its quaternion's x and y and its norm's distance to 1 are this small.
constexpr double kPlanarTolerance = 1e-6;
// A map the program sends may have at most this many cells.
constexpr std::uint64_t kMaxMapCells = 1ull << 28;

std::string Number(double v) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.17g", v);
  return text;
}

std::string Seconds(Time t) {
  char text[48];
  std::snprintf(text, sizeof(text), "%.9f s", t.seconds());
  return text;
}

// write(2) with SIGPIPE blocked: a program that closed its stdin gives EPIPE, not the death of
// this process. A SIGPIPE the write raised is taken back before the mask is restored (one that
// was pending before belongs to someone else and stays).
ssize_t WriteWithoutSigpipe(int fd, const char* data, std::size_t size) {
  sigset_t pipe_only, old_mask, pending;
  sigemptyset(&pipe_only);
  sigaddset(&pipe_only, SIGPIPE);
  sigpending(&pending);
  const bool was_pending = sigismember(&pending, SIGPIPE) == 1;
  pthread_sigmask(SIG_BLOCK, &pipe_only, &old_mask);
  const ssize_t n = ::write(fd, data, size);
  const int error = errno;
  if (n < 0 && error == EPIPE && !was_pending) {
    const timespec zero{0, 0};
    while (sigtimedwait(&pipe_only, nullptr, &zero) < 0 && errno == EINTR) {
    }
  }
  pthread_sigmask(SIG_SETMASK, &old_mask, nullptr);
  errno = error;
  return n;
}

int MillisecondsUntil(std::chrono::steady_clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
      deadline - std::chrono::steady_clock::now());
  return static_cast<int>(std::clamp<std::int64_t>(left.count() + 1, 0, kPollSliceMs));
}

slam::BagSinkOptions StreamSinkOptions(const slam::ExternalEstimator& estimator) {
  slam::BagSinkOptions options;
  options.writer.storage = slam::BagStorage::kMcap;
  options.writer.ticks_per_revolution = estimator.context().robot.ticks_per_revolution;
  options.odometry.robot = estimator.context().robot;
  options.odometry.use_gyro = estimator.context().use_gyro;
  return options;
}

// The program's map as the bench's grid; throws ParseError for one it cannot take.
slam::OccupancyGrid GridFromRos(const slam::RosOccupancyGrid& grid) {
  const std::uint64_t cells = std::uint64_t{grid.width} * grid.height;
  if (cells == 0 || cells > kMaxMapCells || cells != grid.data.size()) {
    throw ParseError("/map: " + std::to_string(grid.width) + " x " + std::to_string(grid.height) +
                     " cells with " + std::to_string(grid.data.size()) +
                     " values (at least one cell, one value per cell, at most 2^28)");
  }
  if (!(std::isfinite(grid.resolution_m) && grid.resolution_m > 0.0f))
    throw ParseError("/map: resolution " + Number(grid.resolution_m) + "; must be > 0");
  if (grid.origin.theta() != 0.0) {
    throw ParseError("/map: origin yaw " + Number(grid.origin.theta()) +
                     " rad; the bench reads maps with an unrotated origin");
  }
  slam::MapImage image;
  image.width = static_cast<int>(grid.width);
  image.height = static_cast<int>(grid.height);
  image.resolution_m = grid.resolution_m;
  image.origin = grid.origin;
  image.occupancy = grid.data;
  for (std::size_t i = 0; i < grid.data.size(); ++i) {
    if (grid.data[i] < -1 || grid.data[i] > 100) {
      throw ParseError("/map: cell " + std::to_string(i) + " is " + std::to_string(grid.data[i]) +
                       "; must be -1 (unknown) or 0..100");
    }
  }
  return slam::GridFromMapImage(image);
}

}  // namespace

ExternalStreamSession::ExternalStreamSession(const std::string& name,
                                             const slam::ExternalEstimator& estimator,
                                             const std::string& work_dir)
    : options_(estimator.options()),
      sink_([this](std::string_view bytes) { stream_.append(bytes); },
            StreamSinkOptions(estimator)),
      answers_("its stdout") {
  const fs::path dir = fs::absolute(fs::path(work_dir) / "external" / name);
  std::error_code ec;
  fs::remove_all(dir, ec);
  fs::create_directories(dir, ec);
  if (ec) throw OutputError(dir.string() + ": cannot create: " + ec.message());
  stderr_path_ = (fs::path(work_dir) / (name + "_stderr.txt")).string();
  const std::vector<std::string> args =
      slam::SubstituteExternalArguments(options_.command, "", "", estimator.context().seed);
  program_ = args.front();
  const slam::DiffDriveParams& robot = estimator.context().robot;
  sink_.writer().AddMetadata(kStreamRobotMetadata,
                             {{"wheel_radius_m", Number(robot.wheel_radius_m)},
                              {"track_width_m", Number(robot.track_width_m)},
                              {"ticks_per_revolution", std::to_string(robot.ticks_per_revolution)},
                              {"use_gyro", estimator.context().use_gyro ? "true" : "false"}});
  SpawnOptions spawn;
  spawn.stderr_path = stderr_path_;
  spawn.working_dir = dir.string();
  spawn.search_path = true;
  spawn.pipe_stdio = true;
  parent_kb_ = ProcessResidentKb();
  const Child child = SpawnChild(args, spawn, 0);
  pid_ = child.pid;
  stdin_fd_ = child.stdin_fd;
  stdout_fd_ = child.stdout_fd;
  start_ = child.start;
  next_peak_poll_ = start_;
  run_deadline_ = start_ + std::chrono::duration_cast<Clock::duration>(
                               std::chrono::duration<double>(options_.timeout_s));
}

ExternalStreamSession::~ExternalStreamSession() { Kill(); }

void ExternalStreamSession::Kill() {
  if (pid_ > 0) {
    ::kill(pid_, SIGKILL);
    int status = 0;
    while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    child_wall_s_ = std::chrono::duration<double>(Clock::now() - start_).count();
    pid_ = -1;
  }
  for (int* fd : {&stdin_fd_, &stdout_fd_}) {
    if (*fd >= 0) ::close(*fd);
    *fd = -1;
  }
}

void ExternalStreamSession::Fail(const std::string& what) {
  if (!failure_.empty()) return;
  Kill();
  const std::string tail = LastLines(stderr_path_, 3);
  failure_ = program_ + ": " + what + (tail.empty() ? "" : "; stderr: " + tail);
}

std::string ExternalStreamSession::Counts() const {
  return "wrote " + std::to_string(poses_) + " poses for " + std::to_string(scans_) + " scans";
}

ExternalStreamSession::Clock::time_point ExternalStreamSession::AnswerDeadline() const {
  return std::min(run_deadline_,
                  Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                     std::chrono::duration<double>(options_.answer_timeout_s)));
}

std::string ExternalStreamSession::TimeoutText(Clock::time_point deadline) const {
  char text[160];
  if (deadline >= run_deadline_) {
    std::snprintf(text, sizeof(text), "still running after timeout_s = %g s; killed",
                  options_.timeout_s);
    return std::string(text) + " (" + Counts() + ")";
  }
  std::snprintf(text, sizeof(text), "within answer_timeout_s = %g s", options_.answer_timeout_s);
  if (written_ < stream_.size()) {  // the wait was for it to read
    return "stopped reading its stdin (" + std::to_string(stream_.size() - written_) +
           " bytes not taken " + text + "); killed (" + Counts() + ")";
  }
  return "no pose for scan " + std::to_string(scans_) + " (" + Seconds(last_scan_time_) + ") " +
         text + "; killed (" + Counts() + ")";
}

std::string ExternalStreamSession::Reap() {
  bool timed_out = false;
  int status = 0;
  struct rusage usage {};
  auto sleep = std::chrono::microseconds(200);
  while (true) {
    const pid_t pid = ::wait4(pid_, &status, WNOHANG, &usage);
    if (pid == pid_) break;
    if (pid < 0 && errno != EINTR) {
      pid_ = -1;
      return "its exit status is lost (" + std::string(std::strerror(errno)) + ")";
    }
    ThrowIfInterrupted();
    PollPeak();
    if (Clock::now() > run_deadline_ && !timed_out) {
      ::kill(pid_, SIGKILL);
      timed_out = true;
    }
    std::this_thread::sleep_for(sleep);
    sleep = std::min(sleep * 2, std::chrono::microseconds(20000));
  }
  pid_ = -1;
  child_wall_s_ = std::chrono::duration<double>(Clock::now() - start_).count();
  // ru_maxrss is the program's own peak only when above the fork's copy of this process.
  peak_rss_kb_ = usage.ru_maxrss > parent_kb_ ? usage.ru_maxrss : polled_peak_kb_;
  return ExternalEndFailure(timed_out, status, options_.timeout_s);
}

void ExternalStreamSession::PollPeak() {
  const Clock::time_point now = Clock::now();
  if (pid_ <= 0 || now < next_peak_poll_) return;
  next_peak_poll_ = now + std::chrono::milliseconds(20);
  polled_peak_kb_ = std::max(polled_peak_kb_, ProcessPeakKb(pid_));
}

bool ExternalStreamSession::ReadSome() {
  char buffer[65536];
  while (stdout_fd_ >= 0) {
    const ssize_t n = ::read(stdout_fd_, buffer, sizeof(buffer));
    if (n > 0) {
      answers_.Feed(std::string_view(buffer, static_cast<std::size_t>(n)));
      continue;
    }
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) return true;
    ::close(stdout_fd_);  // end of file (or an error: nothing more will come)
    stdout_fd_ = -1;
    stdout_eof_ = true;
  }
  return false;
}

ExternalStreamSession::Wait ExternalStreamSession::WriteOut(Clock::time_point deadline) {
  while (written_ < stream_.size()) {
    if (Clock::now() >= deadline) return Wait::kTimeout;
    pollfd fds[2] = {{stdin_fd_, POLLOUT, 0}, {stdout_fd_, POLLIN, 0}};
    const int n = ::poll(fds, stdout_fd_ >= 0 ? 2 : 1, MillisecondsUntil(deadline));
    ThrowIfInterrupted();
    if (n < 0 && errno != EINTR) throw std::runtime_error("poll failed");
    PollPeak();
    // The program may be writing while it reads: its stdout is read meanwhile, or it could
    // block on a full pipe while we wait for it to read.
    if (stdout_fd_ >= 0 && fds[1].revents != 0) ReadSome();
    if (fds[0].revents == 0) continue;
    const ssize_t k =
        WriteWithoutSigpipe(stdin_fd_, stream_.data() + written_, stream_.size() - written_);
    if (k > 0) {
      written_ += static_cast<std::size_t>(k);
    } else if (k < 0 && errno != EAGAIN && errno != EINTR) {
      return Wait::kEndOfFile;  // EPIPE: it closed its stdin (or has exited)
    }
  }
  stream_.clear();
  written_ = 0;
  return Wait::kDone;
}

ExternalStreamSession::Wait ExternalStreamSession::NextMessage(
    Clock::time_point deadline, std::optional<slam::McapStreamMessage>* message) {
  while (true) {
    *message = answers_.Next();
    if (*message) return Wait::kDone;
    if (stdout_eof_) return Wait::kEndOfFile;
    if (Clock::now() >= deadline) return Wait::kTimeout;
    pollfd fd = {stdout_fd_, POLLIN, 0};
    const int n = ::poll(&fd, 1, MillisecondsUntil(deadline));
    ThrowIfInterrupted();
    if (n < 0 && errno != EINTR) throw std::runtime_error("poll failed");
    PollPeak();
    if (n > 0) ReadSome();
  }
}

void ExternalStreamSession::Take(const slam::McapStreamMessage& message, const LaserScan* scan,
                                 std::optional<Pose2>* pose) {
  const auto check_type = [&](const char* type) {
    if (message.schema == type && message.encoding == "cdr") return true;
    Fail(message.topic + " has schema '" + message.schema + "' in '" + message.encoding +
         "'; it must be " + type + " in cdr");
    return false;
  };
  if (message.topic == kStreamEstimateTopic) {
    if (!check_type("geometry_msgs/msg/PoseStamped")) return;
    ++poses_;
    if (scan == nullptr) return;  // after the last scan: counted, and the count fails
    slam::RosPoseStamped p;
    try {
      p = slam::DecodePoseStamped(message.data);
    } catch (const slam::CdrError& e) {
      Fail("pose " + std::to_string(poses_) +
           " is not a geometry_msgs/msg/PoseStamped: " + e.what());
      return;
    }
    if (p.time != scan->time) {
      Fail("pose " + std::to_string(poses_) + " is stamped " + Seconds(p.time) + ", scan " +
           std::to_string(scans_) + " at " + Seconds(scan->time) +
           ": one pose per scan, in scan order, with the scan's stamp (" + Counts() + ")");
      return;
    }
    const double norm = std::sqrt(p.qx * p.qx + p.qy * p.qy + p.qz * p.qz + p.qw * p.qw);
    if (!p.position.allFinite() || !(std::abs(p.qx) <= kPlanarTolerance) ||
        !(std::abs(p.qy) <= kPlanarTolerance) || !(std::abs(norm - 1.0) <= kPlanarTolerance)) {
      Fail("pose " + std::to_string(poses_) + " is not a planar pose (position " +
           Number(p.position.x()) + " " + Number(p.position.y()) + ", quaternion " + Number(p.qx) +
           " " + Number(p.qy) + " " + Number(p.qz) + " " + Number(p.qw) +
           "): a rotation about z with a unit quaternion");
      return;
    }
    *pose = p.Planar();
  } else if (message.topic == kStreamMapTopic) {
    if (!check_type("nav_msgs/msg/OccupancyGrid")) return;
    try {
      map_ = GridFromRos(slam::DecodeOccupancyGrid(message.data));
    } catch (const slam::CdrError& e) {
      Fail(std::string("/map is not a nav_msgs/msg/OccupancyGrid: ") + e.what());
    } catch (const ParseError& e) {
      Fail(e.what());
    }
  } else {
    Fail("a message on " + message.topic + ": the answer has /estimate and /map only");
  }
}

void ExternalStreamSession::Record(const slamrig::Record& record) {
  if (!failure_.empty() || finished_) return;
  const Clock::time_point start = Clock::now();
  try {
    sink_.Add(record, nullptr);
  } catch (const std::invalid_argument& e) {
    Fail(std::string("cannot write the record to the stream: ") + e.what());
    return;
  }
  encode_s_ += std::chrono::duration<double>(Clock::now() - start).count();
  if (stream_.size() - written_ < kFlushBytes) return;
  try {
    // A program must keep taking its input: stalled this long, it has stopped.
    const Clock::time_point deadline = AnswerDeadline();
    const Wait wait = WriteOut(deadline);
    if (wait == Wait::kTimeout) Fail(TimeoutText(deadline));
    if (wait == Wait::kEndOfFile) {
      const std::string end = Reap();
      Fail((end.empty() ? "exited" : end) + " before the end of the stream (" + Counts() + ")");
    }
  } catch (const ParseError& e) {
    Fail(e.what());
  }
}

std::optional<Pose2> ExternalStreamSession::Scan(const LaserScan& scan) {
  if (!failure_.empty() || finished_) return std::nullopt;
  const Clock::time_point start = Clock::now();
  try {
    sink_.Add(scan, nullptr);
  } catch (const std::invalid_argument& e) {
    Fail(std::string("cannot write the scan to the stream: ") + e.what());
    return std::nullopt;
  }
  encode_s_ += std::chrono::duration<double>(Clock::now() - start).count();
  ++scans_;
  last_scan_time_ = scan.time;
  const Clock::time_point deadline = AnswerDeadline();
  try {
    Wait wait = WriteOut(deadline);
    std::optional<Pose2> pose;
    while (wait == Wait::kDone && !pose && failure_.empty()) {
      std::optional<slam::McapStreamMessage> message;
      wait = NextMessage(deadline, &message);
      if (message) Take(*message, &scan, &pose);
    }
    if (pose) return pose;
    if (wait == Wait::kTimeout) Fail(TimeoutText(deadline));
    if (wait == Wait::kEndOfFile) {
      const std::string end = Reap();
      Fail((end.empty() ? "exited" : end) + " before answering scan " + std::to_string(scans_) +
           " (" + Counts() + ")");
    }
  } catch (const ParseError& e) {
    Fail(e.what());
  }
  return std::nullopt;
}

void ExternalStreamSession::Finish() {
  if (finished_) return;
  finished_ = true;
  if (!failure_.empty()) return;
  try {
    sink_.Commit();  // DataEnd, Footer and the closing magic
    if (WriteOut(run_deadline_) == Wait::kTimeout) return Fail(TimeoutText(run_deadline_));
    ::close(stdin_fd_);  // the end of its input
    stdin_fd_ = -1;
    // What it writes last (a map), its Footer, then the end of its stdout.
    Wait wait = Wait::kDone;
    while (wait == Wait::kDone && failure_.empty()) {
      std::optional<slam::McapStreamMessage> message;
      wait = NextMessage(run_deadline_, &message);
      if (message) Take(*message, nullptr, nullptr);
    }
    if (!failure_.empty()) return;
    if (wait == Wait::kTimeout) return Fail(TimeoutText(run_deadline_));
  } catch (const ParseError& e) {
    return Fail(e.what());
  }
  const std::string end = Reap();
  if (!end.empty()) return Fail(end);
  if (poses_ != scans_) return Fail(Counts() + " (one pose per scan, at its stamp)");
  if (!answers_.ended()) {
    Fail("its stdout ended without the MCAP Footer and closing magic (" +
         std::to_string(answers_.bytes()) + " bytes)");
  }
}

std::map<std::string, double> ExternalStreamSession::Statistics() const {
  return {{"peak_rss_mib", static_cast<double>(peak_rss_kb_) / 1024.0},
          {"input_write_s", encode_s_},
          {"child_wall_s", child_wall_s_}};
}

}  // namespace slamrig::scenario
