#include "slam/pipeline/revisits.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <unordered_set>
#include <utility>

namespace slamrig::slam {

namespace {

using CellKey = std::int64_t;

CellKey Key(std::int64_t ix, std::int64_t iy) { return (ix << 32) ^ (iy & 0xffffffffLL); }

CellKey KeyOf(const Eigen::Vector2d& p, double cell) {
  return Key(static_cast<std::int64_t>(std::floor(p.x() / cell)),
             static_cast<std::int64_t>(std::floor(p.y() / cell)));
}

// The share of `later`'s points, moved by `shift`, within reach of `earlier` that fall in or
// beside a cell of `earlier_cells`, or -1 when fewer than rules.min_points are within reach.
double Overlap(const std::vector<Eigen::Vector2d>& later, const Pose2& earlier,
               const std::unordered_set<CellKey>& earlier_cells, const RevisitRules& rules,
               const Eigen::Vector2d& shift = Eigen::Vector2d::Zero()) {
  int counted = 0;
  int agreeing = 0;
  const double reach_sq = rules.reach_m * rules.reach_m;
  for (const Eigen::Vector2d& point : later) {
    const Eigen::Vector2d p = point + shift;
    if ((p - earlier.translation()).squaredNorm() > reach_sq) continue;
    ++counted;
    const auto ix = static_cast<std::int64_t>(std::floor(p.x() / rules.cell_m));
    const auto iy = static_cast<std::int64_t>(std::floor(p.y() / rules.cell_m));
    bool found = false;
    for (std::int64_t dx = -1; dx <= 1 && !found; ++dx) {
      for (std::int64_t dy = -1; dy <= 1 && !found; ++dy) {
        found = earlier_cells.count(Key(ix + dx, iy + dy)) > 0;
      }
    }
    agreeing += found ? 1 : 0;
  }
  if (counted < rules.min_points) return -1.0;
  return static_cast<double>(agreeing) / counted;
}

// The best overlap of `later`'s points with `earlier`'s over the shifts of at most
// rules.max_shift_m (on a grid of cell_m), nearest shifts first; the first to reach
// rules.min_shifted_overlap ends the search.
double BestShiftedOverlap(const std::vector<Eigen::Vector2d>& later, const Pose2& earlier,
                          const std::unordered_set<CellKey>& earlier_cells,
                          const RevisitRules& rules) {
  const int steps = static_cast<int>(std::floor(rules.max_shift_m / rules.cell_m + 1e-9));
  std::vector<Eigen::Vector2d> shifts;
  for (int ix = -steps; ix <= steps; ++ix) {
    for (int iy = -steps; iy <= steps; ++iy) {
      const Eigen::Vector2d shift(ix * rules.cell_m, iy * rules.cell_m);
      if (shift.norm() <= rules.max_shift_m + 1e-9) shifts.push_back(shift);
    }
  }
  std::stable_sort(shifts.begin(), shifts.end(),
                   [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
                     return a.squaredNorm() < b.squaredNorm();
                   });
  double best = 0.0;
  for (const Eigen::Vector2d& shift : shifts) {
    best = std::max(best, Overlap(later, earlier, earlier_cells, rules, shift));
    if (best >= rules.min_shifted_overlap) break;
  }
  return best;
}

}  // namespace

RevisitAgreement CheckRevisits(const std::vector<Pose2>& poses,
                               const std::vector<std::vector<Eigen::Vector2d>>& points,
                               const RevisitRules& rules) {
  RevisitAgreement agreement;
  const std::size_t n = std::min(poses.size(), points.size());
  std::vector<double> path(n, 0.0);
  for (std::size_t k = 1; k < n; ++k) {
    path[k] = path[k - 1] + (poses[k].translation() - poses[k - 1].translation()).norm();
  }
  // Each view's points in the map's frame, and the cells they fall in.
  std::vector<std::vector<Eigen::Vector2d>> world(n);
  std::vector<std::unordered_set<CellKey>> cells(n);
  for (std::size_t k = 0; k < n; ++k) {
    world[k].reserve(points[k].size());
    for (const Eigen::Vector2d& p : points[k]) {
      world[k].push_back(poses[k] * p);
      cells[k].insert(KeyOf(world[k].back(), rules.cell_m));
    }
  }
  // The poses in cells of radius_m: a view's candidates are in its cell's 3x3 neighbourhood. A
  // view enters the grid once it is min_path_m behind the view being compared.
  std::unordered_map<CellKey, std::vector<int>> grid;
  std::unordered_set<CellKey> disagreeing_places;
  std::size_t entered = 0;
  for (std::size_t j = 0; j < n; ++j) {
    while (entered < j && path[j] - path[entered] >= rules.min_path_m) {
      grid[KeyOf(poses[entered].translation(), rules.radius_m)].push_back(
          static_cast<int>(entered));
      ++entered;
    }
    const Eigen::Vector2d here = poses[j].translation();
    const auto cx = static_cast<std::int64_t>(std::floor(here.x() / rules.radius_m));
    const auto cy = static_cast<std::int64_t>(std::floor(here.y() / rules.radius_m));
    std::vector<std::pair<double, int>> candidates;
    for (std::int64_t dx = -1; dx <= 1; ++dx) {
      for (std::int64_t dy = -1; dy <= 1; ++dy) {
        const auto it = grid.find(Key(cx + dx, cy + dy));
        if (it == grid.end()) continue;
        for (const int i : it->second) {
          const double d = (poses[i].translation() - here).norm();
          if (d > rules.radius_m) continue;
          if (std::abs(NormalizeAngle(poses[i].theta() - poses[j].theta())) > rules.max_turn_rad) {
            continue;
          }
          candidates.emplace_back(d, i);
        }
      }
    }
    std::sort(candidates.begin(), candidates.end());
    if (static_cast<int>(candidates.size()) > rules.max_candidates) {
      candidates.resize(static_cast<std::size_t>(rules.max_candidates));
    }
    double best = -1.0;
    int best_view = -1;
    for (const auto& [d, i] : candidates) {
      const double overlap = Overlap(world[j], poses[i], cells[i], rules);
      if (overlap > best) {
        best = overlap;
        best_view = i;
      }
    }
    if (best < 0.0) continue;
    ++agreement.revisits;
    if (best >= rules.min_overlap) continue;
    // Off by less than max_shift_m: a map a little out, not a second copy. The bar is higher than
    // min_overlap: the best of some 80 shifts of an unrelated view reaches 0.2-0.5 by chance.
    const double shifted = BestShiftedOverlap(world[j], poses[best_view], cells[best_view], rules);
    if (shifted >= rules.min_shifted_overlap) {
      ++agreement.shifted;
    } else {
      ++agreement.disagreeing;
      agreement.disagreeing_views.push_back(static_cast<int>(j));
      disagreeing_places.insert(Key(cx, cy));
    }
  }
  agreement.disagreeing_places = static_cast<int>(disagreeing_places.size());
  return agreement;
}

void RevisitAgreement::AppendStatistics(std::map<std::string, double>* statistics) const {
  (*statistics)["revisits"] = revisits;
  (*statistics)["revisits_disagreeing"] = disagreeing;
  (*statistics)["revisits_disagreeing_places"] = disagreeing_places;
}

std::vector<std::string> RevisitAgreement::WithStatisticNames(std::vector<std::string> names) {
  names.insert(names.end(), {"revisits", "revisits_disagreeing", "revisits_disagreeing_places"});
  return names;
}

bool RevisitViews::Offer(const Pose2& online) {
  const int scan = offered_++;
  if (last_) {
    const Pose2 moved = last_->Between(online);
    if (moved.translation().norm() < kDistanceM && std::abs(moved.theta()) < kTurnRad) return false;
  }
  last_ = online;
  scans_.push_back(scan);
  return true;
}

RevisitAgreement RevisitViews::Check(const std::vector<Pose2>& final_poses,
                                     const RevisitRules& rules) const {
  std::vector<Pose2> poses;
  std::vector<std::vector<Eigen::Vector2d>> points;
  for (std::size_t v = 0; v < scans_.size() && v < points_.size(); ++v) {
    const auto scan = static_cast<std::size_t>(scans_[v]);
    if (scan >= final_poses.size()) break;
    poses.push_back(final_poses[scan]);
    points.push_back(points_[v]);
  }
  return CheckRevisits(poses, points, rules);
}

}  // namespace slamrig::slam
