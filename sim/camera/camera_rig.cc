#include "sim/camera/camera_rig.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>
#include <vector>

#include "slam/types/error.h"

namespace slamrig::sim {

CameraRig::CameraRig(Simulator* simulator, const CameraSpec& spec, std::uint64_t seed)
    : simulator_(*simulator),
      camera_(simulator->options().world, spec, seed),
      period_ns_(std::llround(1e9 / spec.rate_hz)) {}

StepResult CameraRig::Step() {
  StepResult step = simulator_.Step();
  const Time now = simulator_.time();
  if (next_frame_ * period_ns_ <= now.ns) {
    TruthSample truth = simulator_.Truth();
    const World& world = simulator_.world();
    std::vector<Eigen::Vector2d> obstacles;
    for (std::size_t i = 0; i < world.spec().obstacles.size(); ++i) {
      obstacles.push_back(world.ObstaclePositionAt(i, now));
    }
    RgbdFrame frame = camera_.Render(truth.map_from_base, now, obstacles);
    CheckDepth(frame, truth.map_from_base);
    pending_.push_back({std::move(frame), std::move(truth)});
    ++frames_;
    // One frame per step at most: a camera faster than the physics renders at the physics rate.
    while (next_frame_ * period_ns_ <= now.ns) ++next_frame_;
  }
  return Merge(std::move(step), simulator_.released_before());
}

void CameraRig::CheckDepth(const RgbdFrame& frame, const Pose2& map_from_base) {
  const bool any =
      std::any_of(frame.depth_m.begin(), frame.depth_m.end(), [](float z) { return z > 0.0f; });
  if (any) {
    blind_since_.reset();
    return;
  }
  if (!blind_since_) blind_since_ = frame.time;
  // A robot nosing a wall sees only nearer than min_depth_m for a moment; a first frame without
  // depth, or seconds of them, is a camera set up to see nothing.
  const double blind_s = static_cast<double>(frame.time.ns - blind_since_->ns) * 1e-9;
  const bool first = frames_ == 0;  // counted after this check
  if (!first && blind_s < kMaxBlindS) return;
  const CameraSpec& spec = camera_.spec();
  std::ostringstream msg;
  msg << "camera '" << spec.name << "': no depth reading in any pixel ";
  if (first) {
    msg << "of the first frame,";
  } else {
    msg << "for " << kMaxBlindS << " s up to";
  }
  msg << " t = " << frame.time.seconds() << " s (robot at " << map_from_base.x() << ", "
      << map_from_base.y() << ", " << map_from_base.theta() << "): everything it sees is nearer "
      << "than camera.min_depth_m = " << spec.min_depth_m
      << " or farther than camera.max_depth_m = " << spec.max_depth_m
      << "; check those and camera.mount";
  throw ConfigError(msg.str());
}

StepResult CameraRig::Flush() {
  return Merge(simulator_.Flush(), Time{std::numeric_limits<std::int64_t>::max()});
}

StepResult CameraRig::Merge(StepResult step, Time released_before) {
  if (pending_.empty() || !(pending_.front().frame.time < released_before)) return step;
  // Every record before the front frame's time is out: merge the frames that are due.
  StepResult out;
  out.time = step.time;
  out.records.reserve(step.records.size() + pending_.size());
  out.truth.reserve(out.records.capacity());
  std::size_t i = 0;
  while (!pending_.empty() && pending_.front().frame.time < released_before) {
    const Time t = pending_.front().frame.time;
    for (; i < step.records.size() && !(t < RecordTime(step.records[i])); ++i) {
      out.records.push_back(std::move(step.records[i]));
      out.truth.push_back(std::move(step.truth[i]));
    }
    out.records.emplace_back(std::move(pending_.front().frame));
    out.truth.push_back(std::move(pending_.front().truth));
    pending_.pop_front();
  }
  for (; i < step.records.size(); ++i) {
    out.records.push_back(std::move(step.records[i]));
    out.truth.push_back(std::move(step.truth[i]));
  }
  return out;
}

}  // namespace slamrig::sim
