#include "sim/camera/camera_rig.h"

#include <cmath>
#include <limits>
#include <utility>

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
    pending_.push_back({camera_.Render(truth.map_from_base, now), std::move(truth)});
    ++frames_;
    // One frame per step at most: a camera faster than the physics renders at the physics rate.
    while (next_frame_ * period_ns_ <= now.ns) ++next_frame_;
  }
  return Merge(std::move(step), simulator_.released_before());
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
