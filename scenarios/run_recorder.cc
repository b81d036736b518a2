#include "scenarios/run_recorder.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <utility>

#include "slam/io/bag/ros_messages.h"
#include "slam/types/error.h"

namespace slamrig::scenario {
namespace {

using slam::RosColor;
using slam::RosMarker;
using slam::RosType;

constexpr const char* kMap = "map";
constexpr const char* kTruthBase = "truth/base_link";

// Colours of the markers: a colour-blind-safe set (Okabe-Ito).
constexpr RosColor kGrey{0.6f, 0.6f, 0.6f, 0.8f};
constexpr RosColor kOrange{0.9f, 0.6f, 0.0f, 1.0f};   // a loop closure not yet judged
constexpr RosColor kGreen{0.0f, 0.62f, 0.45f, 1.0f};  // one that agrees with the truth
constexpr RosColor kRed{0.84f, 0.37f, 0.0f, 1.0f};    // a false one
constexpr RosColor kBlue{0.0f, 0.45f, 0.7f, 0.5f};    // landmark ellipses

// The 95 % region of a 2-D Gaussian: the ellipse at sqrt(chi2_2(0.95)) standard deviations.
constexpr double kEllipseSigmas = 2.4477468306808166;

Time Stamp(double seconds) { return Time::FromSeconds(seconds); }

RosMarker Marker(Time time, const std::string& frame, const char* ns, int id, std::int32_t type) {
  RosMarker m;
  m.time = time;
  m.frame_id = frame;
  m.ns = ns;
  m.id = id;
  m.type = type;
  return m;
}

std::string Fixed(double v, int digits) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", digits, v);
  return text;
}

std::string PoseText(const Pose2& p) {
  return "(" + Fixed(p.x(), 2) + " m, " + Fixed(p.y(), 2) + " m, " + Fixed(p.theta(), 3) + " rad)";
}

// The graph as markers: odometry edges and their nodes, loop-closure edges in `loop_colour`.
std::vector<RosMarker> GraphMarkers(const std::vector<slam::ViewEdge>& edges, Time time,
                                    const std::string& frame, const Pose2& frame_from_estimator) {
  RosMarker odometry = Marker(time, frame, "odometry_edges", 0, RosMarker::kLineList);
  odometry.scale = {0.02, 0, 0};
  odometry.color = kGrey;
  RosMarker nodes = Marker(time, frame, "nodes", 1, RosMarker::kSphereList);
  nodes.scale = {0.08, 0.08, 0.08};
  nodes.color = kGrey;
  RosMarker loops = Marker(time, frame, "loop_closures", 2, RosMarker::kLineList);
  loops.scale = {0.04, 0, 0};
  loops.color = kOrange;
  for (const slam::ViewEdge& e : edges) {
    RosMarker& m = e.loop_closure ? loops : odometry;
    m.points.push_back(frame_from_estimator * e.from);
    m.points.push_back(frame_from_estimator * e.to);
    if (!e.loop_closure) nodes.points.push_back(frame_from_estimator * e.to);
  }
  return {odometry, nodes, loops};
}

// Landmarks: a flat cylinder over each one's 95 % position ellipse, and a sphere at its centre.
std::vector<RosMarker> LandmarkMarkers(const std::vector<slam::LandmarkEstimate>& landmarks,
                                       Time time, const std::string& frame,
                                       const Pose2& frame_from_estimator) {
  std::vector<RosMarker> markers;
  RosMarker centres = Marker(time, frame, "landmarks", 0, RosMarker::kSphereList);
  centres.scale = {0.1, 0.1, 0.1};
  centres.color = kBlue;
  centres.color.a = 1.0f;
  // DELETEALL first: an estimator may drop landmarks between two snapshots.
  RosMarker clear = Marker(time, frame, "", 0, RosMarker::kSphere);
  clear.action = 3;
  markers.push_back(clear);
  const Eigen::Matrix2d rotation = frame_from_estimator.Rotation();
  for (std::size_t i = 0; i < landmarks.size(); ++i) {
    const Eigen::Vector2d centre = frame_from_estimator * landmarks[i].position_m;
    centres.points.push_back(centre);
    const Eigen::Matrix2d cov = rotation * landmarks[i].covariance * rotation.transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
    const Eigen::Vector2d sd = eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
    const Eigen::Vector2d axis = eig.eigenvectors().col(1);
    RosMarker e = Marker(time, frame, "covariance", static_cast<int>(i), RosMarker::kCylinder);
    e.pose = Pose2(centre.x(), centre.y(), std::atan2(axis.y(), axis.x()));
    e.scale = {std::max(2.0 * kEllipseSigmas * sd[1], 1e-3),
               std::max(2.0 * kEllipseSigmas * sd[0], 1e-3), 0.01};
    e.color = kBlue;
    markers.push_back(std::move(e));
  }
  markers.push_back(std::move(centres));
  return markers;
}

}  // namespace

slam::RosOccupancyGrid ToRosGrid(const slam::OccupancyGrid& grid, Time time,
                                 const std::string& frame_id, const Pose2& frame_from_grid) {
  // The smallest box of observed cells: a grid grows in margins it never observes.
  const Eigen::AlignedBox2i observed = grid.ObservedCells();
  int x0 = 0, x1 = 0, y0 = 0, y1 = 0;  // nothing observed yet: one unknown cell
  if (!observed.isEmpty()) {
    x0 = observed.min().x();
    y0 = observed.min().y();
    x1 = observed.max().x();
    y1 = observed.max().y();
  }
  slam::RosOccupancyGrid out;
  out.time = time;
  out.frame_id = frame_id;
  out.resolution_m = static_cast<float>(grid.resolution());
  out.width = static_cast<std::uint32_t>(x1 - x0 + 1);
  out.height = static_cast<std::uint32_t>(y1 - y0 + 1);
  const Eigen::Vector2d corner = grid.origin() + Eigen::Vector2d(x0, y0) * grid.resolution();
  out.origin = frame_from_grid * Pose2(corner.x(), corner.y(), 0.0);
  out.data.resize(static_cast<std::size_t>(out.width) * out.height);
  // Percent k where log-odds l lies in [b(k-1), b(k)), b(k) = logit((k + 0.5) / 100): the
  // rounded probability without an exp per cell (maps are written often), by a branchless
  // binary search over the bounds, padded to 128 with +infinity.
  static const std::array<float, 128> kBounds = [] {
    std::array<float, 128> b;
    b.fill(std::numeric_limits<float>::infinity());
    for (int k = 0; k < 100; ++k) {
      const double p = (k + 0.5) / 100.0;
      b[static_cast<std::size_t>(k)] = static_cast<float>(std::log(p / (1.0 - p)));
    }
    return b;
  }();
  // The number of bounds <= l.
  const auto percent = [](float l) {
    std::size_t n = 0;
    for (std::size_t step = 64; step > 0; step /= 2) n += kBounds[n + step - 1] <= l ? step : 0;
    return static_cast<std::int8_t>(n);
  };
  float last_l = 0.0f;
  std::int8_t last_value = -1;
  std::vector<float> log_odds(out.data.size());
  grid.CopyLogOdds({x0, y0}, {static_cast<int>(out.width), static_cast<int>(out.height)},
                   log_odds.data(), out.width);
  for (std::size_t i = 0; i < log_odds.size(); ++i) {
    const float l = log_odds[i];
    if (l != last_l) {
      last_l = l;
      last_value = l == 0.0f ? std::int8_t{-1} : percent(l);
    }
    out.data[i] = last_value;
  }
  return out;
}

RunRecorder::RunRecorder(std::string path, std::vector<std::string> config_names,
                         RecorderOptions options, slam::MessageSink* live)
    : path_(std::move(path)), options_(options) {
  slam::BagWriterOptions bag;
  bag.single_file = true;
  // base_link hangs under truth/base_link; the robot's own odom -> base_link stays in /odom.
  bag.write_tf = false;
  if (path_.empty()) {
    writer_ = std::make_unique<slam::BagWriter>(bag);
  } else {
    const std::string partial = path_ + ".partial";
    std::error_code ec;
    std::filesystem::remove(partial, ec);
    const std::filesystem::path parent = std::filesystem::path(partial).parent_path();
    if (!parent.empty() && !std::filesystem::exists(parent)) {
      std::filesystem::create_directories(parent, ec);
      if (!ec) created_dir_ = parent.string();
    }
    writer_ = std::make_unique<slam::BagWriter>(partial, bag);
  }
  if (live) writer_->AddSink(live);
  live_ = live;
  if (options_.odometry && options_.odometry->Validate().empty())
    odometry_.emplace(*options_.odometry);
  for (std::string& name : config_names) {
    configs_.emplace_back();
    configs_.back().name = std::move(name);
  }
}

RunRecorder::~RunRecorder() {
  const bool finished = finished_;
  writer_.reset();  // an unfinished writer removes its file
  // A run that failed leaves nothing behind: not even the folder made for the recording.
  if (!finished && !created_dir_.empty()) {
    std::error_code ec;
    std::filesystem::remove(created_dir_, ec);  // only if empty
  }
}

void RunRecorder::Write(const std::string& topic, RosType type, Time time) {
  writer_->WriteMessage(topic, type, false, time, buffer_);
}

void RunRecorder::Record(const slamrig::Record& record) {
  const Time time = RecordTime(record);
  if (!first_time_) {
    first_time_ = time;
    writer_->AddStaticTransform({time, kTruthBase, "base_link", Pose2()}, time);
  }
  last_time_ = std::max(last_time_, time);
  writer_->Write(record);
  if (odometry_) {
    const std::optional<OdometryPose> pose = odometry_->Add(record);
    if (pose && std::holds_alternative<WheelTicks>(record)) writer_->Write(slamrig::Record{*pose});
  }
}

void RunRecorder::Truth(Time time, const Pose2& map_from_base) {
  if (!first_time_) {
    first_time_ = time;
    writer_->AddStaticTransform({time, kTruthBase, "base_link", Pose2()}, time);
  }
  writer_->Write(GroundTruthPose{time, map_from_base});
  if (!writer_->Wants("/tf", RosType::kTfMessage, false)) return;
  slam::EncodeTfMessage({{time, kMap, kTruthBase, map_from_base}}, &buffer_);
  Write("/tf", RosType::kTfMessage, time);
}

void RunRecorder::Scan(std::size_t index, Time time, const slam::ScanEstimate& estimate,
                       const slam::Estimator& estimator, const Pose2& map_from_estimator) {
  Config& c = configs_.at(index);
  c.last_time = time;
  const std::string frame = c.name + "/map";
  if (live_ && !c.announced) {
    c.announced = true;
    std::vector<slam::RosTransform> identities;
    for (const Config& other : configs_) {
      if (other.announced) identities.push_back({time, kMap, other.name + "/map", Pose2()});
    }
    slam::EncodeTfMessage(identities, &buffer_);
    live_->Message("/live/alignments", RosType::kTfMessage, true, time, buffer_);
  }
  const Pose2 pose = map_from_estimator * estimate.pose;
  if (writer_->Wants("/tf", RosType::kTfMessage, false)) {
    slam::EncodeTfMessage({{time, frame, c.name + "/base_link", pose}}, &buffer_);
    Write("/tf", RosType::kTfMessage, time);
  }
  if (!c.has_covariance) c.has_covariance = estimate.covariance.has_value();
  const RosType pose_type =
      *c.has_covariance ? RosType::kPoseWithCovarianceStamped : RosType::kPoseStamped;
  const std::string pose_topic = "/" + c.name + "/pose";
  if (writer_->Wants(pose_topic, pose_type, false)) {
    if (*c.has_covariance) {
      const Eigen::Matrix3d cov =
          estimate.covariance ? RotateCovariance(*estimate.covariance, map_from_estimator.theta())
                              : Eigen::Matrix3d::Zero();
      slam::EncodePoseWithCovarianceStamped(time, frame, pose, cov, &buffer_);
    } else {
      slam::EncodePoseStamped(time, frame, pose, &buffer_);
    }
    Write(pose_topic, pose_type, time);
  }
  const slam::EstimatorView view = estimator.View();
  if (!view.particles.empty() && time.seconds() >= c.next_particles_s &&
      writer_->Wants("/" + c.name + "/particles", RosType::kPoseArray, false)) {
    c.next_particles_s = time.seconds() + options_.particles_period_s;
    std::vector<Pose2> particles;
    particles.reserve(view.particles.size());
    for (const slam::WeightedPose& p : view.particles)
      particles.push_back(map_from_estimator * p.pose);
    slam::EncodePoseArray(time, frame, particles, &buffer_);
    Write("/" + c.name + "/particles", RosType::kPoseArray, time);
  }
  for (const slam::TraceValue& v : estimate.trace) {
    const std::string topic = "/" + c.name + "/health/" + v.name;
    if (!writer_->Wants(topic, RosType::kFloat64, false)) continue;
    slam::EncodeFloat64(v.value, &buffer_);
    Write(topic, RosType::kFloat64, time);
  }
  if (time.seconds() >= c.next_map_s) {
    c.next_map_s = time.seconds() + options_.map_period_s;
    WriteSnapshot(c, time, estimator, view, map_from_estimator);
  }
}

void RunRecorder::WriteSnapshot(Config& c, Time time, const slam::Estimator& estimator,
                                const slam::EstimatorView& view, const Pose2& map_from_estimator) {
  const std::string frame = c.name + "/map";
  const slam::OccupancyGrid& grid = estimator.map();
  if (grid.width() > 0 && grid.height() > 0 &&
      writer_->Wants("/" + c.name + "/map", RosType::kOccupancyGrid, false)) {
    slam::EncodeOccupancyGrid(ToRosGrid(grid, time, frame, map_from_estimator), &buffer_);
    Write("/" + c.name + "/map", RosType::kOccupancyGrid, time);
  }
  if (!view.edges.empty() &&
      writer_->Wants("/" + c.name + "/graph", RosType::kMarkerArray, false)) {
    slam::EncodeMarkerArray(GraphMarkers(view.edges, time, frame, map_from_estimator), &buffer_);
    Write("/" + c.name + "/graph", RosType::kMarkerArray, time);
  }
  if (!view.landmarks.empty() &&
      writer_->Wants("/" + c.name + "/landmarks", RosType::kMarkerArray, false)) {
    slam::EncodeMarkerArray(LandmarkMarkers(view.landmarks, time, frame, map_from_estimator),
                            &buffer_);
    Write("/" + c.name + "/landmarks", RosType::kMarkerArray, time);
  }
}

void RunRecorder::FinishConfig(const ScenarioResult& result, const ConfigResult& c, Time end,
                               std::vector<Late>* late) {
  const std::string frame = c.name + "/map";
  // The final map, path, graph and landmarks, at the end.
  if (c.run.map.width() > 0 && c.run.map.height() > 0) {
    slam::EncodeOccupancyGrid(ToRosGrid(c.run.map, end, frame, c.map_from_estimator), &buffer_);
    Write("/" + c.name + "/map", RosType::kOccupancyGrid, end);
  }
  if (!c.estimate.empty()) {
    slam::EncodePath(end, frame, c.estimate.poses(), &buffer_);
    Write("/" + c.name + "/path", RosType::kPath, end);
  }
  if ((!c.run.loop_closures.empty() || !c.run.rejected_loop_closures.empty()) &&
      c.estimate.size() > 0) {
    // Loop closures between the final poses, judged against the truth where there is one, and
    // the candidates the estimator rejected.
    RosMarker loops = Marker(end, frame, "loop_closures", 2, RosMarker::kLineList);
    loops.scale = {0.04, 0, 0};
    loops.color = kOrange;
    const auto& poses = c.estimate.poses();
    // A closure's two scans as indices into the final poses; nothing when either is outside them.
    auto ends =
        [&poses](const slam::LoopClosure& l) -> std::optional<std::pair<std::size_t, std::size_t>> {
      if (l.from_scan < 0 || l.to_scan < 0) return std::nullopt;
      const auto from = static_cast<std::size_t>(l.from_scan);
      const auto to = static_cast<std::size_t>(l.to_scan);
      if (from >= poses.size() || to >= poses.size()) return std::nullopt;
      return std::pair{from, to};
    };
    for (std::size_t i = 0; i < c.run.loop_closures.size(); ++i) {
      const slam::LoopClosure& l = c.run.loop_closures[i];
      const auto scans = ends(l);
      if (!scans) continue;
      const RosColor colour =
          i < c.loop_is_true.size() ? (c.loop_is_true[i] ? kGreen : kRed) : kOrange;
      loops.points.push_back(poses[scans->first].pose.translation());
      loops.points.push_back(poses[scans->second].pose.translation());
      loops.colors.push_back(colour);
      loops.colors.push_back(colour);
      const Time at = poses[scans->second].time;
      slam::EncodeString(c.name + ": loop closure scan " + std::to_string(l.from_scan) + " -> " +
                             std::to_string(l.to_scan) +
                             (i < c.loop_is_true.size()
                                  ? (c.loop_is_true[i] ? " (true)" : " (false against the truth)")
                                  : ""),
                         &buffer_);
      late->push_back({at, "/events", RosType::kString, false, buffer_});
    }
    RosMarker rejected = Marker(end, frame, "rejected_loop_closures", 3, RosMarker::kLineList);
    rejected.scale = {0.02, 0, 0};
    rejected.color = kGrey;
    for (const slam::LoopClosure& l : c.run.rejected_loop_closures) {
      const auto scans = ends(l);
      if (!scans) continue;
      rejected.points.push_back(poses[scans->first].pose.translation());
      rejected.points.push_back(poses[scans->second].pose.translation());
    }
    slam::EncodeMarkerArray(std::vector<RosMarker>{loops, rejected}, &buffer_);
    Write("/" + c.name + "/graph", RosType::kMarkerArray, end);
  }
  if (!c.run.landmarks.landmarks.empty()) {
    slam::EncodeMarkerArray(
        LandmarkMarkers(c.run.landmarks.landmarks, end, frame, c.map_from_estimator), &buffer_);
    Write("/" + c.name + "/landmarks", RosType::kMarkerArray, end);
  }
  // Errors of the online poses in the ATE alignment's frame (what the 3-D panel shows) against
  // the reference at the same time: x the position error (m), y the heading error (rad).
  std::map<std::int64_t, Pose2> truth;
  for (const StampedPose& p : result.truth.poses()) truth.emplace(p.time.ns, p.pose);
  for (const StampedPose& p : c.online.poses()) {
    const auto it = truth.find(p.time.ns);
    if (it == truth.end()) continue;
    const Pose2 aligned = c.reference_from_estimate * p.pose;
    const Pose2 error = it->second.Between(aligned);
    slam::EncodeVector3Stamped(
        p.time, kMap,
        Eigen::Vector3d((aligned.translation() - it->second.translation()).norm(), error.theta(),
                        0.0),
        &buffer_);
    late->push_back({p.time, "/" + c.name + "/error", RosType::kVector3Stamped, false, buffer_});
  }
}

void RunRecorder::Events(const ScenarioResult& result, std::vector<Late>* late) {
  auto event = [&](Time t, const std::string& text) {
    slam::EncodeString(text, &buffer_);
    late->push_back({t, "/events", RosType::kString, false, buffer_});
  };
  if (const auto& sim = result.spec->simulated) {
    for (std::size_t i = 0; i < result.kidnap_times.size() && i < sim->kidnaps.size(); ++i) {
      event(result.kidnap_times[i],
            "kidnapped: the robot is moved to " + PoseText(sim->kidnaps[i].to));
    }
    for (const BlackoutFault& b : sim->blackouts) {
      if (b.from_s > result.sim_time_s) continue;
      event(Stamp(b.from_s), "lidar blackout starts (until " + Fixed(b.to_s, 1) + " s)");
      if (b.to_s <= result.sim_time_s) event(Stamp(b.to_s), "lidar blackout ends");
    }
  }
  // Relocalisations: recovery_time_s is the worst over the kidnappings (slam::WorstRecoveryTime),
  // so its moment is known only when there was one kidnapping.
  for (const ConfigResult& c : result.configs) {
    const auto it = c.metrics.find("recovery_time_s");
    if (it == c.metrics.end() || !std::isfinite(it->second) || result.kidnap_times.size() != 1) {
      continue;
    }
    event(Time{result.kidnap_times.front().ns + Time::FromSeconds(it->second).ns},
          c.name + ": relocalised (back within 0.5 m of the truth for good) " +
              Fixed(it->second, 2) + " s after the kidnapping");
  }
}

void RunRecorder::Finish(const ScenarioResult& result) {
  Time end = last_time_;
  for (const Config& c : configs_) end = std::max(end, c.last_time);
  const Time start = first_time_.value_or(end);
  std::vector<Late> late;
  for (std::size_t i = 0; i < result.configs.size() && i < configs_.size(); ++i) {
    FinishConfig(result, result.configs[i], end, &late);
  }
  Events(result, &late);
  // Known only now, valid from the start: the alignments (static) and the true map (latched).
  writer_->FlushChunk();
  // Stamped at the start, or with the last mount a camera's first frame added, so that /tf_static
  // stays in time order in the file too.
  const Time static_time = std::max(start, writer_->static_time().value_or(start));
  for (const ConfigResult& c : result.configs) {
    writer_->AddStaticTransform({static_time, kMap, c.name + "/map", c.reference_from_estimate},
                                static_time);
  }
  if (result.truth_map && result.truth_map->width() > 0) {
    slam::EncodeOccupancyGrid(ToRosGrid(*result.truth_map, start, kMap, Pose2()), &buffer_);
    writer_->WriteMessage("/truth/map", RosType::kOccupancyGrid, true, start, buffer_);
  }
  std::stable_sort(late.begin(), late.end(),
                   [](const Late& a, const Late& b) { return a.time < b.time; });
  for (const Late& m : late) writer_->WriteMessage(m.topic, m.type, m.latched, m.time, m.payload);
  writer_->Commit();
  finished_ = true;
}

void RunRecorder::Commit(const std::string& path) {
  std::error_code ec;
  std::filesystem::rename(path + ".partial", path, ec);
  if (ec) throw OutputError(path + ": cannot rename into place: " + ec.message());
}

}  // namespace slamrig::scenario
