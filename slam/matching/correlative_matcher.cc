#include "slam/matching/correlative_matcher.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <queue>

#include "slam/types/check.h"
#include "slam/types/validation.h"

namespace slamrig::slam {
namespace {

// The search grids of matchers that are gone, for the next matcher built on the same thread.
// Graph SLAM and the ICP front end build a matcher for every scan they search, over megabytes of
// levels: fresh vectors cost a memset and the kernel's page faults each time (half of graph's time
// on acapulco; docs/studies/large-maps.md). Every cell of a taken raster is written before it is
// read, so the values are as before.
class RasterPool {
 public:
  ~RasterPool() { gone = true; }
  // A vector of `size` floats, contents unspecified: the smallest spare that holds them, else the
  // largest, grown.
  std::vector<float> Take(std::size_t size) {
    std::vector<float> v;
    if (!spare_.empty()) {
      std::size_t pick = 0;
      for (std::size_t k = 1; k < spare_.size(); ++k) {
        const std::size_t c = spare_[k].capacity(), best = spare_[pick].capacity();
        const bool fits = c >= size, best_fits = best >= size;
        if (fits != best_fits ? fits : (fits ? c < best : c > best)) pick = k;
      }
      v = std::move(spare_[pick]);
      spare_.erase(spare_.begin() + static_cast<std::ptrdiff_t>(pick));
      bytes_ -= v.capacity() * sizeof(float);
    }
    v.resize(size);
    return v;
  }
  void Give(std::vector<float>&& v) {
    const std::size_t bytes = v.capacity() * sizeof(float);
    if (bytes == 0 || bytes_ + bytes > kMaxBytes) return;
    bytes_ += bytes;
    spare_.push_back(std::move(v));
  }
  // Set when this thread's pool is destroyed (a matcher may outlive it at exit).
  static thread_local bool gone;

 private:
  static constexpr std::size_t kMaxBytes = std::size_t{128} << 20;
  std::vector<std::vector<float>> spare_;
  std::size_t bytes_ = 0;
};

thread_local bool RasterPool::gone = false;
thread_local RasterPool raster_pool;

std::vector<float> TakeRaster(std::size_t size) {
  if (RasterPool::gone) return std::vector<float>(size);
  return raster_pool.Take(size);
}

// A block of 2^level x 2^level translations at one yaw, by its lowest corner (i, j).
struct Node {
  int k = 0;
  int i = 0;
  int j = 0;
  int level = 0;           // the block spans 2^level x 2^level cells
  float bound = 0.0f;      // the block's score at that level: no pose in it scores more
  std::int64_t index = 0;  // of its corner in the exhaustive search's (k, j, i) order
};

// Higher bound first; ties by the search order, so the visiting order is fixed.
bool BetterFirst(const Node& a, const Node& b) {
  return a.bound > b.bound || (a.bound == b.bound && a.index < b.index);
}

}  // namespace

std::vector<std::string> CorrelativeMatcherOptions::Validate() const {
  Rules rules;
  rules.NonNegative("linear_window_m", linear_window_m)
      .Require(angular_window_rad >= 0.0 && angular_window_rad <= 3.14159265358979 + 1e-9,
               "angular_window_rad", angular_window_rad, "must be in [0, pi]")
      .NonNegative("angular_step_rad", angular_step_rad)
      .InRange("branch_and_bound_depth", branch_and_bound_depth, 1, 12)
      .Require(std::isfinite(min_score), "min_score", min_score, "must be finite")
      .AtLeast("covariance_half_cells", covariance_half_cells, 1)
      .AtLeast("covariance_half_steps", covariance_half_steps, 1)
      .Positive("covariance_score_scale", covariance_score_scale);
  return rules.errors();
}

CorrelativeMatcher::CorrelativeMatcher(const CorrelativeMatcherOptions& options,
                                       const GridView& raster)
    : options_(options), origin_(raster.origin), resolution_(raster.resolution) {
  SLAMRIG_CHECK_VALID(options_, "CorrelativeMatcherOptions");
  std::vector<float> values = TakeRaster(static_cast<std::size_t>(raster.width) * raster.height);
  for (int y = 0; y < raster.height; ++y) {
    for (int x = 0; x < raster.width; ++x) {
      values[static_cast<std::size_t>(y) * raster.width + x] = raster.At(x, y);
    }
  }
  Precompute(std::move(values), raster.width, raster.height);
}

CorrelativeMatcher::CorrelativeMatcher(const CorrelativeMatcherOptions& options,
                                       const OccupancyGrid& grid, int decimation,
                                       const std::optional<Eigen::AlignedBox2d>& region)
    : options_(options), resolution_(grid.resolution() * decimation) {
  SLAMRIG_CHECK_VALID(options_, "CorrelativeMatcherOptions");
  SLAMRIG_CHECK(decimation >= 1, "CorrelativeMatcher: decimation must be >= 1");
  // The grid cells searched: all, or those of the region.
  Eigen::Array2i lo(0, 0), hi(grid.width() - 1, grid.height() - 1);
  if (region) std::tie(lo, hi) = grid.CellsIn(*region);
  const Eigen::Array2i cells = (hi - lo + 1).max(Eigen::Array2i(0, 0));
  origin_ = grid.origin() + lo.cast<double>().matrix() * grid.resolution();
  const int d = decimation;
  const int width = (cells.x() + d - 1) / d, height = (cells.y() + d - 1) / d;
  std::vector<float> values = TakeRaster(static_cast<std::size_t>(width) * height);
  std::fill(values.begin(), values.end(), 0.0f);
  std::vector<float> row(static_cast<std::size_t>(cells.x()));
  for (int y = 0; y < cells.y(); ++y) {
    grid.CopyLogOdds({lo.x(), lo.y() + y}, {cells.x(), 1}, row.data(), 0);
    for (int x = 0; x < cells.x(); ++x) {
      const double l = row[static_cast<std::size_t>(x)];
      if (!(l > 0.0)) continue;
      float& coarse = values[static_cast<std::size_t>(y / d) * width + x / d];
      coarse = std::max(coarse, static_cast<float>(1.0 - 1.0 / (1.0 + std::exp(l))));
    }
  }
  Precompute(std::move(values), width, height);
}

CorrelativeMatcher::~CorrelativeMatcher() {
  if (RasterPool::gone) return;
  for (Level& level : levels_) raster_pool.Give(std::move(level.values));
}

void CorrelativeMatcher::Precompute(std::vector<float> values, int width, int height) {
  levels_.resize(static_cast<std::size_t>(options_.branch_and_bound_depth));
  levels_[0] = Level{0, width, height, std::move(values)};
  // Level h from level h-1 by doubling (Hess 2016, Sec. V-C): the max of four blocks of 2^(h-1),
  // max(max(P(x, y), P(x + half, y)), max(P(x, y + half), P(x + half, y + half))) with cells
  // outside P reading 0. It is taken in two passes with the same operands in the same order (so
  // the same bits): R = the max along x of each of P's rows, padded to the level's width, then the
  // level = the max along y of R's rows, one row of zeros standing for the rows outside P.
  std::vector<float> rows, zeros;
  for (std::size_t h = 1; h < levels_.size(); ++h) {
    const Level& prev = levels_[h - 1];
    const int half = 1 << (h - 1);
    Level& level = levels_[h];
    level.offset = (1 << h) - 1;
    level.width = width + level.offset;    // = prev.width + half
    level.height = height + level.offset;  // = prev.height + half
    level.values = TakeRaster(static_cast<std::size_t>(level.width) * level.height);
    const int pw = prev.width, lw = level.width;
    // Column lx of the level is x = lx - level.offset: P(x, .) is prev's column lx - half and
    // P(x + half, .) its column lx.
    rows.resize(static_cast<std::size_t>(lw) * prev.height);
    for (int py = 0; py < prev.height; ++py) {
      const float* p = prev.values.data() + static_cast<std::size_t>(py) * pw;
      float* r = rows.data() + static_cast<std::size_t>(py) * lw;
      int lx = 0;
      for (; lx < std::min(half, pw); ++lx) r[lx] = std::max(0.0f, p[lx]);
      for (; lx < half; ++lx) r[lx] = 0.0f;  // only for a level narrower than half a block
      for (; lx < pw; ++lx) r[lx] = std::max(p[lx - half], p[lx]);
      for (; lx < lw; ++lx) r[lx] = std::max(p[lx - half], 0.0f);
    }
    // Row ly of the level is y = ly - level.offset: R(., y) is R's row ly - half and R(., y + half)
    // its row ly.
    zeros.assign(static_cast<std::size_t>(lw), 0.0f);
    for (int ly = 0; ly < level.height; ++ly) {
      const int a = ly - half, b = ly;
      const float* ra = a >= 0 ? rows.data() + static_cast<std::size_t>(a) * lw : zeros.data();
      const float* rb =
          b < prev.height ? rows.data() + static_cast<std::size_t>(b) * lw : zeros.data();
      float* out = level.values.data() + static_cast<std::size_t>(ly) * lw;
      for (int lx = 0; lx < lw; ++lx) out[lx] = std::max(ra[lx], rb[lx]);
    }
  }
}

float CorrelativeMatcher::LevelBound(int level, int x, int y) const {
  SLAMRIG_CHECK(level >= 0 && level < static_cast<int>(levels_.size()),
                "CorrelativeMatcher::LevelBound: no such level");
  const Level& l = levels_[static_cast<std::size_t>(level)];
  const int lx = x + l.offset, ly = y + l.offset;
  if (lx < 0 || ly < 0 || lx >= l.width || ly >= l.height) return 0.0f;
  return l.values[static_cast<std::size_t>(ly) * l.width + lx];
}

double CorrelativeMatcher::AngularStep(std::span<const Eigen::Vector2d> points_base) const {
  if (options_.angular_step_rad > 0.0) return options_.angular_step_rad;
  double d_max = 0.0;
  for (const Eigen::Vector2d& p : points_base) d_max = std::max(d_max, p.norm());
  if (d_max <= resolution_) return std::max(options_.angular_window_rad, 1e-3);
  return std::acos(1.0 - resolution_ * resolution_ / (2.0 * d_max * d_max));
}

std::optional<MatchResult> CorrelativeMatcher::Match(std::span<const Eigen::Vector2d> points_base,
                                                     const Pose2& initial) const {
  std::vector<MatchResult> best = MatchDistinct(points_base, initial, 1, 0.0, 0.0);
  if (best.empty()) return std::nullopt;
  return best.front();
}

struct CorrelativeMatcher::DiscreteScan {
  int n = 0;                          // points
  int half_steps = 0;                 // yaws k in [-half_steps, half_steps]
  std::vector<Eigen::Array2i> cells;  // per yaw, n cells relative to the raster's cell (0, 0)
  std::vector<Eigen::Array4i> boxes;  // per yaw: min x, y, max x, y of its cells
};

CorrelativeMatcher::DiscreteScan CorrelativeMatcher::Discretise(
    std::span<const Eigen::Vector2d> points_base, const Pose2& initial, double step,
    int half_steps) const {
  DiscreteScan scan;
  const int n = static_cast<int>(points_base.size());
  const int wk = half_steps;
  const int num_angles = 2 * wk + 1;
  scan.n = n;
  scan.half_steps = wk;
  scan.cells.resize(static_cast<std::size_t>(num_angles) * n);
  scan.boxes.resize(static_cast<std::size_t>(num_angles));
  for (int k = -wk; k <= wk; ++k) {
    const Pose2 pose(initial.x(), initial.y(), initial.theta() + k * step);
    Eigen::Array2i* out = &scan.cells[static_cast<std::size_t>(k + wk) * n];
    Eigen::Array4i box(INT_MAX, INT_MAX, INT_MIN, INT_MIN);
    for (int p = 0; p < n; ++p) {
      const Eigen::Vector2d w = pose * points_base[static_cast<std::size_t>(p)];
      out[p] = Eigen::Array2i(static_cast<int>(std::floor((w.x() - origin_.x()) / resolution_)),
                              static_cast<int>(std::floor((w.y() - origin_.y()) / resolution_)));
      box = Eigen::Array4i(std::min(box[0], out[p].x()), std::min(box[1], out[p].y()),
                           std::max(box[2], out[p].x()), std::max(box[3], out[p].y()));
    }
    scan.boxes[static_cast<std::size_t>(k + wk)] = box;
  }
  return scan;
}

float CorrelativeMatcher::ScoreAt(const DiscreteScan& scan, int level, int k, int i, int j) const {
  const int n = scan.n, wk = scan.half_steps;
  const Level& l = levels_[static_cast<std::size_t>(level)];
  const Eigen::Array2i* c = &scan.cells[static_cast<std::size_t>(k + wk) * n];
  const Eigen::Array4i& box = scan.boxes[static_cast<std::size_t>(k + wk)];
  const int dx = i + l.offset, dy = j + l.offset;
  float sum = 0.0f;
  // The bounds check is skipped when the whole shifted box lies inside the level (same sum
  // either way).
  if (box[0] + dx >= 0 && box[1] + dy >= 0 && box[2] + dx < l.width && box[3] + dy < l.height) {
    const std::ptrdiff_t shift = static_cast<std::ptrdiff_t>(dy) * l.width + dx;
    const float* values = l.values.data();
    for (int p = 0; p < n; ++p) {
      sum += values[shift + static_cast<std::ptrdiff_t>(c[p].y()) * l.width + c[p].x()];
    }
    return sum;
  }
  for (int p = 0; p < n; ++p) {
    const int x = c[p].x() + dx, y = c[p].y() + dy;
    if (static_cast<unsigned>(x) < static_cast<unsigned>(l.width) &&
        static_cast<unsigned>(y) < static_cast<unsigned>(l.height)) {
      sum += l.values[static_cast<std::size_t>(y) * l.width + x];
    }
  }
  return sum;
}

Eigen::Matrix3d CorrelativeMatcher::OlsonCovariance(const DiscreteScan& scan, int k, int i, int j,
                                                    double score, double step) const {
  // The offsets are relative to the best pose so that the sums stay well conditioned.
  const int n = scan.n, wk = scan.half_steps;
  const int cc = options_.covariance_half_cells, cs = options_.covariance_half_steps;
  Eigen::Matrix3d moment = Eigen::Matrix3d::Zero();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  double total = 0.0;
  for (int dk = -cs; dk <= cs; ++dk) {
    const int kk = k + dk;
    if (kk < -wk || kk > wk) continue;
    for (int dj = -cc; dj <= cc; ++dj) {
      for (int di = -cc; di <= cc; ++di) {
        const double s = static_cast<double>(ScoreAt(scan, 0, kk, i + di, j + dj)) / n;
        const double w = std::exp((s - score) / options_.covariance_score_scale);
        const Eigen::Vector3d x(di * resolution_, dj * resolution_, dk * step);
        total += w;
        mean += w * x;
        moment += w * x * x.transpose();
      }
    }
  }
  mean /= total;
  Eigen::Matrix3d covariance = moment / total - mean * mean.transpose();
  covariance(0, 0) += resolution_ * resolution_ / 12.0;
  covariance(1, 1) += resolution_ * resolution_ / 12.0;
  covariance(2, 2) += step * step / 12.0;
  return covariance;
}

std::vector<MatchResult> CorrelativeMatcher::MatchDistinct(
    std::span<const Eigen::Vector2d> points_base, const Pose2& initial, int count,
    double min_distance_m, double min_angle_rad) const {
  std::vector<MatchResult> results;
  if (points_base.empty() || count < 1) return results;
  const int n = static_cast<int>(points_base.size());
  const double step = AngularStep(points_base);
  const int wk = static_cast<int>(std::ceil(options_.angular_window_rad / step - 1e-9));
  const int wxy = static_cast<int>(std::ceil(options_.linear_window_m / resolution_ - 1e-9));
  const std::int64_t side = 2 * wxy + 1;

  const DiscreteScan scan = Discretise(points_base, initial, step, wk);
  auto score = [&](int level, int k, int i, int j) { return ScoreAt(scan, level, k, i, j); };
  auto index_of = [&](int k, int i, int j) {
    return (static_cast<std::int64_t>(k + wk) * side + (j + wxy)) * side + (i + wxy);
  };

  const int top = options_.branch_and_bound_depth - 1;
  const int block = 1 << top;
  std::vector<Node> roots;
  for (int k = -wk; k <= wk; ++k) {
    for (int j = -wxy; j <= wxy; j += block) {
      for (int i = -wxy; i <= wxy; i += block) {
        roots.push_back(Node{k, i, j, top, score(top, k, i, j), index_of(k, i, j)});
      }
    }
  }
  // Best-first branch and bound: the open blocks in a heap, the highest bound (then the earliest
  // in search order) on top. A leaf that comes to the top is the best pose not yet excluded: every
  // block still open bounds its poses no higher, and with an equal bound starts later in search
  // order (a block's poses come at or after its corner). So it is the exact search's answer, after
  // scoring only blocks whose bound reaches it; the depth-first order of Hess 2016, Sec. V-A,
  // scores every block above the best pose found so far, from min_score up. One heap serves the
  // greedy non-maximum suppression's searches: what the earlier ones left open is still a
  // partition of the poses neither taken nor excluded, and a block excluded once stays so.
  std::vector<Node> found;
  // A block of 2^level cells lies wholly within an earlier result's neighbourhood: its corners do
  // (the neighbourhood is a disc in x and y), at a yaw within min_angle_rad of the result's.
  auto excluded = [&](const Node& node) {
    const int last = (1 << node.level) - 1;
    const int i1 = std::min(node.i + last, wxy), j1 = std::min(node.j + last, wxy);
    for (const Node& e : found) {
      if (std::abs(NormalizeAngle((node.k - e.k) * step)) > min_angle_rad) continue;
      bool inside = true;
      for (const int i : {node.i, i1}) {
        for (const int j : {node.j, j1}) {
          inside = inside &&
                   std::hypot((i - e.i) * resolution_, (j - e.j) * resolution_) <= min_distance_m;
        }
      }
      if (inside) return true;
    }
    return false;
  };
  auto lower_priority = [](const Node& a, const Node& b) { return BetterFirst(b, a); };
  std::priority_queue<Node, std::vector<Node>, decltype(lower_priority)> open(lower_priority,
                                                                              std::move(roots));
  const float min_sum = static_cast<float>(options_.min_score * n);
  std::int64_t nodes_scored = static_cast<std::int64_t>(open.size());
  while (static_cast<int>(found.size()) < count && !open.empty()) {
    const Node node = open.top();
    open.pop();
    if (node.bound < min_sum) break;  // and so is every block still open
    if (!found.empty() && excluded(node)) continue;
    if (node.level == 0) {
      found.push_back(node);
      continue;
    }
    const int half = 1 << (node.level - 1);
    for (const int dj : {0, half}) {
      for (const int di : {0, half}) {
        const int i = node.i + di, j = node.j + dj;
        if (i > wxy || j > wxy) continue;
        open.push(Node{node.k, i, j, node.level - 1, score(node.level - 1, node.k, i, j),
                       index_of(node.k, i, j)});
        ++nodes_scored;
      }
    }
  }
  for (const Node& best : found) {
    MatchResult result;
    result.pose = Pose2(initial.x() + best.i * resolution_, initial.y() + best.j * resolution_,
                        initial.theta() + best.k * step);
    result.score = static_cast<double>(best.bound) / n;
    result.iterations = static_cast<int>(std::min<std::int64_t>(nodes_scored, 1 << 30));
    result.correspondences = n;
    result.converged = true;

    result.covariance = OlsonCovariance(scan, best.k, best.i, best.j, result.score, step);
    results.push_back(result);
  }
  return results;
}

}  // namespace slamrig::slam
