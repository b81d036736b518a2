// GMapping's scan matcher (Grisetti, Stachniss, Burgard, IEEE T-RO 2007, Sec. IV; openslam
// gmapping `ScanMatcher::score`, `likelihoodAndScore` and `optimize`) on a TiledGrid.
#include "slam/pf/rbpf_matcher.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <utility>

#include "slam/types/validation.h"

namespace slamrig::slam {
namespace {

// floor() without the libm call (the matcher's hot loop); exact for |v| < 2^31.
int FloorToInt(double v) {
  const int i = static_cast<int>(v);
  return i - (v < i);
}

// The square cells of side `length_m` that the independence counts hash end points by.
class PointCells {
 public:
  explicit PointCells(double length_m) : inv_(1.0 / length_m) {}
  std::pair<std::int64_t, std::int64_t> Of(const Eigen::Vector2d& v) const {
    return {static_cast<std::int64_t>(std::floor(v.x() * inv_)),
            static_cast<std::int64_t>(std::floor(v.y() * inv_))};
  }
  // Both indices packed into one word, so that no two of a cell's nine neighbours share a key
  // (a multiplicative hash can map two of them to one bucket and count its points twice).
  static std::uint64_t Key(std::int64_t x, std::int64_t y) {
    return static_cast<std::uint64_t>(static_cast<std::uint32_t>(x)) << 32 |
           static_cast<std::uint32_t>(y);
  }

 private:
  double inv_;
};

}  // namespace

std::vector<std::string> RbpfMatcherOptions::Validate() const {
  Rules rules;
  rules.NonNegative("kernel_cells", kernel_cells)
      .Positive("score_sigma_m", score_sigma_m)
      .Positive("likelihood_sigma_m", likelihood_sigma_m)
      .Require(no_match_log_likelihood < 0.0, "no_match_log_likelihood", no_match_log_likelihood,
               "must be < 0")
      .Positive("linear_step_m", linear_step_m)
      .Positive("angular_step_rad", angular_step_rad)
      .NonNegative("yaw_search_rad", yaw_search_rad)
      .Positive("yaw_search_step_rad", yaw_search_step_rad)
      .NonNegative("refinements", refinements)
      .NonNegative("prior_weight", prior_weight)
      .AtLeast("max_iterations", max_iterations, 1)
      .Fraction("min_matched_fraction", min_matched_fraction);
  return rules.errors();
}

std::vector<MatchPoint> MakeMatchPoints(const LaserScan& scan, const ScanPointsOptions& points,
                                        double free_offset_m) {
  const Eigen::Vector2d laser = scan.base_from_laser.translation();
  std::vector<MatchPoint> out;
  for (const Eigen::Vector2d& hit : ScanToBasePoints(scan, points)) {
    const Eigen::Vector2d along = hit - laser;
    const double length = along.norm();
    if (!(length > free_offset_m)) continue;
    out.push_back({hit, hit - along * (free_offset_m / length)});
  }
  return out;
}

int CountIndependentPoints(std::span<const MatchPoint> points, double length_m) {
  if (!(length_m > 0.0)) return static_cast<int>(points.size());
  // The kept points hashed by their cell: a point within length_m of a kept one has it in its
  // own cell or one of the eight around it.
  const PointCells cells(length_m);
  const double l2 = length_m * length_m;
  std::unordered_map<std::uint64_t, std::vector<Eigen::Vector2d>> kept;
  int count = 0;
  for (const MatchPoint& p : points) {
    const auto [cx, cy] = cells.Of(p.hit);
    bool near = false;
    for (std::int64_t dy = -1; dy <= 1 && !near; ++dy) {
      for (std::int64_t dx = -1; dx <= 1 && !near; ++dx) {
        const auto it = kept.find(PointCells::Key(cx + dx, cy + dy));
        if (it == kept.end()) continue;
        for (const Eigen::Vector2d& q : it->second) {
          if ((q - p.hit).squaredNorm() < l2) {
            near = true;
            break;
          }
        }
      }
    }
    if (near) continue;
    kept[PointCells::Key(cx, cy)].push_back(p.hit);
    ++count;
  }
  return count;
}

void AssignIndependenceWeights(std::span<MatchPoint> points, double length_m) {
  for (MatchPoint& p : points) p.weight = 1.0;
  if (!(length_m > 0.0)) return;
  // The points hashed by their cell: a point within length_m of another has it in its own cell
  // or one of the eight around it.
  const PointCells cells(length_m);
  const double l2 = length_m * length_m;
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> buckets;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto [cx, cy] = cells.Of(points[i].hit);
    buckets[PointCells::Key(cx, cy)].push_back(i);
  }
  for (MatchPoint& p : points) {
    const auto [cx, cy] = cells.Of(p.hit);
    int neighbours = 0;
    for (std::int64_t dy = -1; dy <= 1; ++dy) {
      for (std::int64_t dx = -1; dx <= 1; ++dx) {
        const auto it = buckets.find(PointCells::Key(cx + dx, cy + dy));
        if (it == buckets.end()) continue;
        for (const std::size_t j : it->second) {
          neighbours += (points[j].hit - p.hit).squaredNorm() < l2;
        }
      }
    }
    p.weight = 1.0 / neighbours;  // >= 1: the point itself
  }
}

RbpfMatcher::RbpfMatcher(const RbpfMatcherOptions& options)
    : options_(options),
      likelihood_scale_(-0.5 / (options.likelihood_sigma_m * options.likelihood_sigma_m)) {
  // exp(-d^2 / (2 sigma^2)) tabulated over d^2 up to 8 sigma^2 (exp(-4) = 0.018; beyond, 0).
  const double sigma2 = options.score_sigma_m * options.score_sigma_m;
  score_table_step_ = 8.0 * sigma2 / (kScoreTableSize - 1);
  score_table_.resize(kScoreTableSize + 1);
  for (int i = 0; i < kScoreTableSize; ++i) {
    score_table_[static_cast<std::size_t>(i)] = std::exp(-0.5 * i * score_table_step_ / sigma2);
  }
  score_table_[kScoreTableSize] = 0.0;
}

double RbpfMatcher::ScoreOf(double d2) const {
  // Linear interpolation in the table: cheaper than exp in the climb's inner loop, and as smooth.
  const double u = d2 / score_table_step_;
  if (!(u < kScoreTableSize - 1)) return 0.0;
  const int i = static_cast<int>(u);
  const double f = u - i;
  return (1.0 - f) * score_table_[static_cast<std::size_t>(i)] +
         f * score_table_[static_cast<std::size_t>(i) + 1];
}

template <bool kLikelihood>
MatchFit RbpfMatcher::Fit(const TiledGrid& map, std::span<const MatchPoint> points,
                          const Pose2& world_from_base) const {
  constexpr int kSize = TiledGrid::kTileSize;
  const int k = options_.kernel_cells;
  const bool free_test = options_.free_cell_test;
  const double c = std::cos(world_from_base.theta());
  const double s = std::sin(world_from_base.theta());
  const Eigen::Vector2d t = world_from_base.translation();
  const double res = map.resolution();
  const double inv_res = 1.0 / res;
  const Eigen::Vector2d origin = map.origin();
  const bool records_means = map.records_hit_means();
  MatchFit fit;
  for (const MatchPoint& p : points) {
    const Eigen::Vector2d hit(t.x() + c * p.hit.x() - s * p.hit.y(),
                              t.y() + s * p.hit.x() + c * p.hit.y());
    const Eigen::Vector2d free(t.x() + c * p.free.x() - s * p.free.y(),
                               t.y() + s * p.free.x() + c * p.free.y());
    const Eigen::Array2i ih(FloorToInt((hit.x() - origin.x()) * inv_res),
                            FloorToInt((hit.y() - origin.y()) * inv_res));
    const Eigen::Array2i back = Eigen::Array2i(FloorToInt((free.x() - origin.x()) * inv_res),
                                               FloorToInt((free.y() - origin.y()) * inv_res)) -
                                ih;
    double best = std::numeric_limits<double>::infinity();
    // The distance to the wall cell's hit mean where the map records one (TiledGrid::HitMean),
    // else to its centre.
    auto consider = [&](int x, int y, float cell, float behind, const TiledGrid::HitMean* mean) {
      if (!(cell > 0.0f) || (free_test && behind > 0.0f)) return;
      double ex = hit.x() - (origin.x() + (x + 0.5) * res);
      double ey = hit.y() - (origin.y() + (y + 0.5) * res);
      if (mean) {
        ex -= mean->dx;
        ey -= mean->dy;
      }
      best = std::min(best, ex * ex + ey * ey);
    };
    // Most kernels lie inside one tile: one tile lookup, then plain indexing.
    const int reach = k + std::max(std::abs(back.x()), std::abs(back.y()));
    const int lx = ih.x() & (kSize - 1);
    const int ly = ih.y() & (kSize - 1);
    if (lx >= reach && ly >= reach && lx + reach < kSize && ly + reach < kSize) {
      const TiledGrid::Tile* tile =
          map.FindTile(ih.x() >> TiledGrid::kTileBits, ih.y() >> TiledGrid::kTileBits);
      if (tile) {
        const float* centre = tile->data() + ly * kSize + lx;
        const int behind = back.y() * kSize + back.x();
        const TiledGrid::HitTile* means =
            records_means
                ? map.FindHitTile(ih.x() >> TiledGrid::kTileBits, ih.y() >> TiledGrid::kTileBits)
                : nullptr;
        const TiledGrid::HitMean* mean_centre = means ? means->data() + ly * kSize + lx : nullptr;
        for (int dy = -k; dy <= k; ++dy) {
          for (int dx = -k; dx <= k; ++dx) {
            const float* cell = centre + dy * kSize + dx;
            consider(ih.x() + dx, ih.y() + dy, cell[0], cell[behind],
                     mean_centre ? mean_centre + dy * kSize + dx : nullptr);
          }
        }
      }
    } else {
      for (int dy = -k; dy <= k; ++dy) {
        for (int dx = -k; dx <= k; ++dx) {
          const int x = ih.x() + dx;
          const int y = ih.y() + dy;
          const TiledGrid::HitMean mean =
              records_means ? map.HitMeanAt(x, y) : TiledGrid::HitMean{};
          consider(x, y, map.LogOdds(x, y), map.LogOdds(x + back.x(), y + back.y()),
                   records_means ? &mean : nullptr);
        }
      }
    }
    if (best < std::numeric_limits<double>::infinity()) {
      ++fit.matched;
      fit.score += ScoreOf(best);
      if constexpr (kLikelihood) {
        const double ll = std::max(likelihood_scale_ * best, options_.no_match_log_likelihood);
        fit.log_likelihood += ll;
        fit.weighted_log_likelihood += p.weight * ll;
      }
    } else if constexpr (kLikelihood) {
      fit.log_likelihood += options_.no_match_log_likelihood;
      fit.weighted_log_likelihood += p.weight * options_.no_match_log_likelihood;
    }
  }
  return fit;
}

MatchFit RbpfMatcher::Evaluate(const TiledGrid& map, std::span<const MatchPoint> points,
                               const Pose2& world_from_base) const {
  return Fit<true>(map, points, world_from_base);
}

ClimbResult RbpfMatcher::Climb(const TiledGrid& map, std::span<const MatchPoint> points,
                               const Pose2& initial, const PosePrior& prior) const {
  const double wx = options_.prior_weight * 0.5 / (prior.sigma_xy_m * prior.sigma_xy_m);
  const double wt = options_.prior_weight * 0.5 / (prior.sigma_yaw_rad * prior.sigma_yaw_rad);
  auto objective = [&](const Pose2& pose, const MatchFit& fit) {
    const double dx = pose.x() - prior.mean.x();
    const double dy = pose.y() - prior.mean.y();
    const double dt = NormalizeAngle(pose.theta() - prior.mean.theta());
    return fit.score - wx * (dx * dx + dy * dy) - wt * dt * dt;
  };
  ClimbResult best{initial, Fit<false>(map, points, initial), 1};
  double best_value = objective(best.pose, best.fit);
  int evaluations = 1;
  if (options_.yaw_search_rad > 0.0) {
    const int steps = static_cast<int>(options_.yaw_search_rad / options_.yaw_search_step_rad);
    for (int i = -steps; i <= steps; ++i) {
      if (i == 0) continue;
      const Pose2 pose(initial.x(), initial.y(),
                       initial.theta() + i * options_.yaw_search_step_rad);
      const MatchFit fit = Fit<false>(map, points, pose);
      ++evaluations;
      const double value = objective(pose, fit);
      if (value > best_value) {
        best = {pose, fit, 0};
        best_value = value;
      }
    }
  }
  double linear = options_.linear_step_m;
  double angular = options_.angular_step_rad;
  int refinements = 0;
  for (int iteration = 0; iteration < options_.max_iterations; ++iteration) {
    // The six moves of GMapping's optimize, in the world frame; the best neighbour wins.
    const std::array<Pose2, 6> moves = {
        Pose2(best.pose.x() + linear, best.pose.y(), best.pose.theta()),
        Pose2(best.pose.x() - linear, best.pose.y(), best.pose.theta()),
        Pose2(best.pose.x(), best.pose.y() + linear, best.pose.theta()),
        Pose2(best.pose.x(), best.pose.y() - linear, best.pose.theta()),
        Pose2(best.pose.x(), best.pose.y(), best.pose.theta() + angular),
        Pose2(best.pose.x(), best.pose.y(), best.pose.theta() - angular)};
    ClimbResult next = best;
    double next_value = best_value;
    for (const Pose2& move : moves) {
      const MatchFit fit = Fit<false>(map, points, move);
      ++evaluations;
      const double value = objective(move, fit);
      if (value > next_value) {
        next = {move, fit, 0};
        next_value = value;
      }
    }
    if (next_value > best_value) {
      best = next;
      best_value = next_value;
      continue;
    }
    if (++refinements > options_.refinements) break;
    linear *= 0.5;
    angular *= 0.5;
  }
  best.evaluations = evaluations;
  return best;
}

}  // namespace slamrig::slam
