#include "slam/io/dataset.h"

#include <algorithm>

namespace slamrig::slam {
namespace {

// A message of the log in file order.
struct Entry {
  int line;
  const CarmenScan* scan = nullptr;
  const CarmenOdometry* odometry = nullptr;
};

std::vector<Entry> InFileOrder(const CarmenLog& log) {
  std::vector<Entry> entries;
  entries.reserve(log.scans.size() + log.odometry.size());
  for (const auto& s : log.scans) entries.push_back({s.line, &s, nullptr});
  for (const auto& o : log.odometry) entries.push_back({o.line, nullptr, &o});
  std::sort(entries.begin(), entries.end(),
            [](const Entry& a, const Entry& b) { return a.line < b.line; });
  return entries;
}

}  // namespace

Dataset CarmenToDataset(const CarmenLog& log) {
  Dataset data;
  data.source = log.path;
  data.notes = log.notes;
  data.truncated = log.truncated;
  data.times_synthesised = !log.timestamps_usable;
  const std::vector<Entry> entries = InFileOrder(log);

  if (log.is_corrected) {
    data.reference_kind = "GMapping-corrected scan poses";
    // raw_from_corrected maps the corrected pose of the previous scan to the recovered odometry
    // pose there; motion after it comes from ODOM lines relative to that corrected pose.
    bool started = false;
    Pose2 previous_corrected;  // P_{k-1}
    Pose2 previous_odometry;   // recovered odometry at scan k-1
    int dropped = 0;
    int odometry_after_start = 0;
    int intervals = 0, intervals_without_odometry = 0;
    bool odometry_since_scan = false;
    for (const Entry& e : entries) {
      if (e.odometry != nullptr) {
        if (!started) {
          ++dropped;
          continue;
        }
        ++odometry_after_start;
        odometry_since_scan = true;
        const Pose2 recovered =
            previous_odometry * previous_corrected.Between(e.odometry->odometry.odom_from_base);
        data.records.push_back(OdometryPose{e.odometry->odometry.time, recovered});
        continue;
      }
      const CarmenScan& s = *e.scan;
      if (!started) {
        started = true;
        previous_odometry = s.logged_pose;
        data.records.push_back(OdometryPose{s.scan.time, previous_odometry});
      } else {
        ++intervals;
        if (!odometry_since_scan) ++intervals_without_odometry;
        // The odometry at this scan is the last ODOM before it (or no motion if there was none).
        const auto last =
            std::find_if(data.records.rbegin(), data.records.rend(),
                         [](const Record& r) { return std::holds_alternative<OdometryPose>(r); });
        previous_odometry = std::get<OdometryPose>(*last).odom_from_base;
      }
      previous_corrected = s.logged_pose;
      odometry_since_scan = false;
      data.records.push_back(s.scan);
      data.reference.push_back({s.scan.time, s.logged_pose});
    }
    if (dropped > 0) {
      data.notes.push_back(std::to_string(dropped) + " ODOM lines before the first scan dropped");
    }
    if (odometry_after_start == 0 && intervals > 0) {
      // Nothing but echoes: the first scan's pose held still is no odometry at all.
      std::erase_if(data.records,
                    [](const Record& r) { return std::holds_alternative<OdometryPose>(r); });
      data.notes.push_back(
          "no raw odometry: every ODOM line repeats its scan's pose; running without odometry "
          "(a scan-matched motion prior)");
    } else if (intervals_without_odometry > 0) {
      data.notes.push_back(GroupedCount(static_cast<std::uint64_t>(intervals_without_odometry)) +
                           " of " + GroupedCount(static_cast<std::uint64_t>(intervals)) +
                           " scan intervals have no raw ODOM line: the odometry holds still there");
    }
    return data;
  }

  data.reference_kind = log.true_poses.empty() ? "" : "TRUEPOS";
  for (const Entry& e : entries) {
    if (e.odometry != nullptr) {
      data.records.push_back(e.odometry->odometry);
      continue;
    }
    if (e.scan->has_pose)
      data.records.push_back(OdometryPose{e.scan->scan.time, e.scan->odom_pose});
    data.records.push_back(e.scan->scan);
  }
  data.reference = log.true_poses;
  return data;
}

}  // namespace slamrig::slam
