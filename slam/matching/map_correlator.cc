// Map correlation over a shift grid: Wang, "Simultaneous Localization and Mapping with Texture"
// (UCSD ECE276A), Sec. II-D and Eq. 7 (corr(y, m), softmax weights); the 9x9 grid of Zafari and
// Kansal (ECE276A reports); yaw shifts as in Wang Sec. III-C.
#include "slam/matching/map_correlator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <sstream>

#include "slam/types/check.h"
#include "slam/types/validation.h"

namespace slamrig::slam {
namespace {

// Four floats in one SIMD register (GCC/Clang vector extension: SSE2 on x86-64, NEON on ARM).
typedef float V4 __attribute__((vector_size(16)));
typedef std::int32_t V4i __attribute__((vector_size(16)));

inline V4 Load4(const float* p) {
  V4 v;
  std::memcpy(&v, p, sizeof(v));
  return v;
}

// Per-cell contribution: the raw value, or 1 for cells above the threshold.
struct RawOp {
  V4 operator()(V4 v) const { return v; }
  float operator()(float v) const { return v; }
};
struct IndicatorOp {
  float threshold;
  V4 operator()(V4 v) const {
    const V4 t = {threshold, threshold, threshold, threshold};
    const V4 one = {1.0f, 1.0f, 1.0f, 1.0f};
    V4i ones;
    std::memcpy(&ones, &one, sizeof(ones));
    const V4i mask = (v > t) & ones;
    V4 out;
    std::memcpy(&out, &mask, sizeof(out));
    return out;
  }
  float operator()(float v) const { return v > threshold ? 1.0f : 0.0f; }
};

// Adds, for every patch row r and column c < 4*K, the contribution of cell
// values[offset + r*stride + c] over all `offsets` into sums[r*4K + c].
template <int K, typename Op>
void AccumulateRows(const float* values, int stride, int side,
                    const std::vector<std::int64_t>& offsets, const Op& op, float* sums) {
  for (int r = 0; r < side; ++r) {
    V4 acc[K] = {};
    const float* row_base = values + static_cast<std::ptrdiff_t>(r) * stride;
    for (const std::int64_t offset : offsets) {
      const float* p = row_base + offset;
      for (int k = 0; k < K; ++k) acc[k] += op(Load4(p + 4 * k));
    }
    std::memcpy(sums + static_cast<std::ptrdiff_t>(r) * 4 * K, acc, sizeof(acc));
  }
}

template <typename Op>
void AccumulateDispatch(int chunks, const float* values, int stride, int side,
                        const std::vector<std::int64_t>& offsets, const Op& op, float* sums) {
  switch (chunks) {
    case 1:
      return AccumulateRows<1>(values, stride, side, offsets, op, sums);
    case 2:
      return AccumulateRows<2>(values, stride, side, offsets, op, sums);
    case 3:
      return AccumulateRows<3>(values, stride, side, offsets, op, sums);
    case 4:
      return AccumulateRows<4>(values, stride, side, offsets, op, sums);
    case 5:
      return AccumulateRows<5>(values, stride, side, offsets, op, sums);
    case 6:
      return AccumulateRows<6>(values, stride, side, offsets, op, sums);
    case 7:
      return AccumulateRows<7>(values, stride, side, offsets, op, sums);
    case 8:
      return AccumulateRows<8>(values, stride, side, offsets, op, sums);
    default:
      SLAMRIG_CHECK(false, "shift grid too wide");
  }
}

// Sixteen byte counters in one SIMD register.
typedef std::uint8_t V16u8 __attribute__((vector_size(16)));

// Counts, for every patch row r and column c < side, the walls at mask cell offset + r*stride + c
// over all `offsets` into sums[r*padded + c]. Counts below 2^24 are exact floats, so the sums are
// those of adding 1.0f per wall in any order.
template <int K>
void CountWalls(const std::uint8_t* mask, int stride, int side, int padded,
                const std::vector<std::int64_t>& offsets, float* sums) {
  std::array<std::uint32_t, 16 * K> counts;
  for (int r = 0; r < side; ++r) {
    counts.fill(0);
    const std::uint8_t* row_base = mask + static_cast<std::ptrdiff_t>(r) * stride;
    // Blocks of 255 points: a byte counter holds 255.
    for (std::size_t begin = 0; begin < offsets.size(); begin += 255) {
      const std::size_t end = std::min(offsets.size(), begin + 255);
      V16u8 acc[K] = {};
      for (std::size_t i = begin; i < end; ++i) {
        const std::uint8_t* p = row_base + offsets[i];
        for (int k = 0; k < K; ++k) {
          V16u8 v;
          std::memcpy(&v, p + 16 * k, sizeof(v));
          acc[k] += v;
        }
      }
      for (int k = 0; k < K; ++k) {
        for (int j = 0; j < 16; ++j) counts[static_cast<std::size_t>(16 * k + j)] += acc[k][j];
      }
    }
    for (int c = 0; c < side; ++c) {
      sums[r * padded + c] = static_cast<float>(counts[static_cast<std::size_t>(c)]);
    }
  }
}

// floor() for values well inside the int range, without the libm call.
inline int FastFloor(double v) {
  const int i = static_cast<int>(v);
  return i - (v < static_cast<double>(i) ? 1 : 0);
}

// Scratch reused across calls on the same thread.
struct Scratch {
  std::vector<std::int64_t> offsets;       // patch corner offsets of points fully inside
  std::vector<std::int64_t> mask_offsets;  // the same corners in an OccupiedMask
  std::vector<Eigen::Array2i> border;      // patch corner cells of points near or over the edge
  std::vector<float> sums;
};

}  // namespace

std::vector<std::string> MapCorrelatorOptions::Validate() const {
  Rules rules;
  rules.InRange("xy_half_width_cells", xy_half_width_cells, 0, 15)
      .NonNegative("yaw_half_steps", yaw_half_steps)
      .Require(yaw_half_steps <= 0 || yaw_step_rad > 0.0, "yaw_step_rad", yaw_step_rad,
               "must be > 0 when yaw_half_steps > 0")
      .NonNegative("prior_sigma_xy_m", prior_sigma_xy_m)
      .NonNegative("prior_sigma_yaw_rad", prior_sigma_yaw_rad)
      .NonNegative("min_shift_gain", min_shift_gain);
  return rules.errors();
}

MapCorrelator::MapCorrelator(const MapCorrelatorOptions& options) : options_(options) {
  SLAMRIG_CHECK_VALID(options_, "MapCorrelatorOptions");
}

CorrelationResult MapCorrelator::Correlate(const GridView& grid,
                                           std::span<const Eigen::Vector2d> points_base,
                                           const Pose2& world_from_base,
                                           std::vector<float>* table) const {
  return CorrelateImpl(grid, nullptr, points_base, world_from_base, table);
}

CorrelationResult MapCorrelator::Correlate(const GridView& grid, const OccupiedMask& mask,
                                           std::span<const Eigen::Vector2d> points_base,
                                           const Pose2& world_from_base,
                                           std::vector<float>* table) const {
  SLAMRIG_CHECK(options_.value == CorrelationValue::kOccupiedIndicator &&
                    mask.threshold() == options_.occupied_threshold,
                "OccupiedMask need the occupied-indicator model at their threshold");
  SLAMRIG_CHECK(mask.width() == grid.width && mask.height() == grid.height,
                "OccupiedMask must follow the viewed grid");
  return CorrelateImpl(grid, &mask, points_base, world_from_base, table);
}

// function-length: exception (the SIMD hot kernel of every particle's scan match: its scratch is
// hoisted and its loops fused on purpose; splitting it costs measured time)
CorrelationResult MapCorrelator::CorrelateImpl(const GridView& grid, const OccupiedMask* mask,
                                               std::span<const Eigen::Vector2d> points_base,
                                               const Pose2& world_from_base,
                                               std::vector<float>* table) const {
  thread_local Scratch scratch;
  const int n = options_.xy_half_width_cells;
  const int side = options_.side();
  const int chunks = (side + 3) / 4;
  const int padded = 4 * chunks;  // columns actually read per patch row
  const double inv_res = 1.0 / grid.resolution;
  const int stride = grid.row_stride();
  const IndicatorOp indicator{options_.occupied_threshold};
  const RawOp raw;
  if (table != nullptr)
    table->assign(static_cast<std::size_t>(options_.num_yaws() * side * side), 0.0f);

  // The prior's cost per cell and per yaw step squared (0: no prior on that part).
  const double xy_sigma_cells = options_.prior_sigma_xy_m / grid.resolution;
  const float xy_cost =
      xy_sigma_cells > 0.0 ? static_cast<float>(0.5 / (xy_sigma_cells * xy_sigma_cells)) : 0.0f;
  float yaw_cost = 0.0f;
  if (options_.yaw_half_steps > 0 && options_.prior_sigma_yaw_rad > 0.0) {
    const double yaw_sigma_steps = options_.prior_sigma_yaw_rad / options_.yaw_step_rad;
    yaw_cost = static_cast<float>(0.5 / (yaw_sigma_steps * yaw_sigma_steps));
  }

  CorrelationResult best;
  best.score = -std::numeric_limits<float>::infinity();
  float best_value = -std::numeric_limits<float>::infinity();
  float centre_score = -std::numeric_limits<float>::infinity();
  long best_rank = std::numeric_limits<long>::max();
  for (int yaw_index = -options_.yaw_half_steps; yaw_index <= options_.yaw_half_steps;
       ++yaw_index) {
    const double yaw = world_from_base.theta() + yaw_index * options_.yaw_step_rad;
    const double c = std::cos(yaw) * inv_res;
    const double s = std::sin(yaw) * inv_res;
    const double tx = (world_from_base.x() - grid.origin.x()) * inv_res;
    const double ty = (world_from_base.y() - grid.origin.y()) * inv_res;

    // Points to patch-corner cells, consecutive duplicates dropped.
    scratch.offsets.clear();
    scratch.mask_offsets.clear();
    scratch.border.clear();
    int last_x = std::numeric_limits<int>::min(), last_y = 0;
    int distinct = 0;
    for (const Eigen::Vector2d& p : points_base) {
      const int ix = FastFloor(tx + c * p.x() - s * p.y());
      const int iy = FastFloor(ty + s * p.x() + c * p.y());
      if (ix == last_x && iy == last_y) continue;
      last_x = ix;
      last_y = iy;
      ++distinct;
      const int x0 = ix - n, y0 = iy - n;
      if (x0 >= 0 && y0 >= 0 && x0 + padded <= grid.width && y0 + side <= grid.height) {
        if (mask != nullptr) {
          scratch.mask_offsets.push_back(static_cast<std::int64_t>(y0) * mask->stride() + x0);
        } else {
          scratch.offsets.push_back(static_cast<std::int64_t>(y0) * stride + x0);
        }
      } else {
        scratch.border.push_back({x0, y0});
      }
    }

    scratch.sums.assign(static_cast<std::size_t>(side * padded), 0.0f);
    if (mask != nullptr) {
      if (side <= 16) {
        CountWalls<1>(mask->data(), mask->stride(), side, padded, scratch.mask_offsets,
                      scratch.sums.data());
      } else {
        CountWalls<2>(mask->data(), mask->stride(), side, padded, scratch.mask_offsets,
                      scratch.sums.data());
      }
    } else if (!scratch.offsets.empty()) {
      if (options_.value == CorrelationValue::kOccupiedIndicator) {
        AccumulateDispatch(chunks, grid.values, stride, side, scratch.offsets, indicator,
                           scratch.sums.data());
      } else {
        AccumulateDispatch(chunks, grid.values, stride, side, scratch.offsets, raw,
                           scratch.sums.data());
      }
    }
    // Points near the edge: cell by cell, outside reads as 0 (with a mask, the grid's values
    // may be absent: the mask holds their indicator).
    for (const Eigen::Array2i& corner : scratch.border) {
      for (int r = 0; r < side; ++r) {
        for (int col = 0; col < side; ++col) {
          const int x = corner.x() + col, y = corner.y() + r;
          float contribution = 0.0f;
          if (mask != nullptr) {
            const bool inside = x >= 0 && y >= 0 && x < mask->width() && y < mask->height();
            contribution = inside && mask->Get(x, y) ? 1.0f : 0.0f;
          } else {
            const float v = grid.At(x, y);
            contribution =
                options_.value == CorrelationValue::kOccupiedIndicator ? indicator(v) : v;
          }
          scratch.sums[static_cast<std::size_t>(r * padded + col)] += contribution;
        }
      }
    }

    for (int r = 0; r < side; ++r) {
      for (int col = 0; col < side; ++col) {
        const float score = scratch.sums[static_cast<std::size_t>(r * padded + col)];
        const int dx = col - n, dy = r - n;
        if (table != nullptr) {
          (*table)[static_cast<std::size_t>(
              ((yaw_index + options_.yaw_half_steps) * side + r) * side + col)] = score;
        }
        const long rank = static_cast<long>(dx) * dx + static_cast<long>(dy) * dy +
                          static_cast<long>(yaw_index) * yaw_index;
        if (rank == 0) centre_score = score;
        const float cost = xy_cost * static_cast<float>(dx * dx + dy * dy) +
                           yaw_cost * static_cast<float>(yaw_index * yaw_index);
        const float value = score - cost;
        if (value > best_value || (value == best_value && rank < best_rank)) {
          best_value = value;
          best.score = score;
          best.prior_cost = cost;
          best_rank = rank;
          best.dx_cells = dx;
          best.dy_cells = dy;
          best.dyaw_steps = yaw_index;
        }
      }
    }
    if (yaw_index == 0) best.points_used = distinct;
  }
  // A near-tie with the centre is noise, not evidence: stay put.
  if (options_.min_shift_gain > 0.0f && !(best_value - centre_score > options_.min_shift_gain)) {
    best.score = centre_score;
    best.prior_cost = 0.0f;
    best.dx_cells = best.dy_cells = best.dyaw_steps = 0;
  }
  best.pose = Pose2(world_from_base.x() + best.dx_cells * grid.resolution,
                    world_from_base.y() + best.dy_cells * grid.resolution,
                    world_from_base.theta() + best.dyaw_steps * options_.yaw_step_rad);
  return best;
}

}  // namespace slamrig::slam
