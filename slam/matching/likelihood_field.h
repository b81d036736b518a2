#pragma once

#include <Eigen/Geometry>
#include <string>
#include <utility>
#include <vector>

#include "slam/grid/occupancy_grid.h"
#include "slam/matching/grid_view.h"

namespace slamrig::slam {

/// Parameters of the likelihood-field observation model.
struct LikelihoodFieldOptions {
  double sigma_m = 0.05;            ///< standard deviation of a hit around the nearest wall
  double z_hit = 0.9;               ///< weight of the Gaussian part
  double z_rand = 0.1;              ///< weight of the uniform part (outliers, unknown space)
  float occupied_threshold = 0.0f;  ///< log-odds above this is a wall
  double cutoff_sigmas = 3.0;       ///< walls further than this many sigmas count as "none near"

  /// One message per broken rule, keys relative to this struct (the container names it).
  std::vector<std::string> Validate() const;
};

/// The field table of LikelihoodFieldOptions (slam/config/fields.h).
template <typename V>
void VisitFields(V& v, LikelihoodFieldOptions& o) {
  v("sigma_m", o.sigma_m);
  v("z_hit", o.z_hit);
  v("z_rand", o.z_rand);
  v("occupied_threshold", o.occupied_threshold);
  v("cutoff_sigmas", o.cutoff_sigmas);
}

/// A likelihood field (Thrun, Burgard, Fox, "Probabilistic Robotics", Sec. 6.4, Table 6.3)
/// computed from the occupied cells of an OccupancyGrid over a window. Cell value:
/// log(z_hit * exp(-d^2 / (2 sigma^2)) + z_rand) - log(z_rand), with d the distance from the cell
/// centre to the nearest occupied cell centre; 0 when no wall is within the cutoff and outside the
/// window. Summed over a scan's end points it is the scan's log-likelihood up to a constant, so it
/// plugs into MapCorrelator (CorrelationValue::kRawValue) and gets its shift search for free.
class LikelihoodField {
 public:
  explicit LikelihoodField(const LikelihoodFieldOptions& options);

  /// Recomputes the field over the part of `grid` that overlaps `region` (world coordinates),
  /// on the grid's own cell lattice.
  void Update(const OccupancyGrid& grid, const Eigen::AlignedBox2d& region);

  /// Keeps the field up to date over at least the part of `grid` that overlaps `region`, at a cost
  /// that follows what changed and where the robot went, not the map's size: the field is a
  /// window of the grid (`region` with some slack), redone whole only when a region leaves it (or
  /// on the first call, after Update, with another grid, after SetSigma); between, only the cells
  /// within reach of a wall that appeared or went are redone, and a grid that grew re-bases the
  /// window. Every value is exactly what Update would compute. One follower per grid (it takes
  /// the grid's wall flips).
  void Follow(OccupancyGrid& grid, const Eigen::AlignedBox2d& region);
  /// Follow over the whole grid (tests, small maps).
  void Follow(OccupancyGrid& grid);

  /// The field as a raster (valid until the next Update or Follow): Update's window, or the
  /// followed window.
  GridView view() const;
  /// After Follow: the field over the part of the grid that overlaps `region`, 0 outside it, cell
  /// for cell the raster that Update(grid, region) would give (a window, no copy). `region` must
  /// lie in the followed window (a region given to the last Follow does).
  GridView view(const Eigen::AlignedBox2d& region) const;
  /// Value of a cell at distance `distance_m` from the nearest wall.
  double Score(double distance_m) const;
  /// The distance from the nearest wall that has value `score` (Score's inverse); +infinity for
  /// 0 and below (no wall within the cutoff).
  double Distance(double score) const;

  double sigma_m() const { return options_.sigma_m; }
  /// Takes another sigma (> 0): the next Follow recomputes the whole field, an Update its window.
  void SetSigma(double sigma_m);

 private:
  void EnsureKernel(double resolution);
  // Writes the field of the cells in [lo, hi] (inclusive, inside the grid) to `out`, the cell lo
  // at out[0] and rows `stride` floats apart.
  void Fill(const OccupancyGrid& grid, const Eigen::Array2i& lo, const Eigen::Array2i& hi,
            float* out, int stride) const;
  // Fill() on the followed window, for the cells of [lo, hi] (window cells) inside it.
  void Refill(const OccupancyGrid& grid, Eigen::Array2i lo, Eigen::Array2i hi);
  // Makes the followed window `region` (clipped to the grid) plus slack and computes it whole.
  void Recompute(const OccupancyGrid& grid, const Eigen::AlignedBox2d& region);
  // Brings the window's cells within reach of grid cell `cell` up to date after its wall flip.
  void ApplyFlip(const OccupancyGrid& grid, const Eigen::Array2i& cell);
  // The grid cells [lo, hi] that `region` overlaps on the followed grid (empty if hi < lo).
  std::pair<Eigen::Array2i, Eigen::Array2i> GridCells(const Eigen::AlignedBox2d& region) const;
  // Whether the followed window holds the grid cells [lo, hi].
  bool WindowHolds(const Eigen::Array2i& lo, const Eigen::Array2i& hi) const {
    return (lo >= window_lo_).all() && (hi < window_lo_ + Eigen::Array2i(width_, height_)).all();
  }

  LikelihoodFieldOptions options_;
  int radius_cells_ = 0;
  double kernel_resolution_ = 0.0;
  std::vector<float> kernel_;  // (2r+1)^2 scores by cell offset
  std::vector<float> values_;
  int width_ = 0;
  int height_ = 0;
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();  // world corner of values_'s cell (0, 0)
  double resolution_ = 1.0;
  // The grid Follow keeps up with (nullptr after Update), its lattice when last seen, and the
  // grid cell of the window's cell (0, 0).
  const OccupancyGrid* followed_ = nullptr;
  Eigen::Vector2d grid_origin_ = Eigen::Vector2d::Zero();
  Eigen::Array2i grid_size_ = Eigen::Array2i::Zero();
  Eigen::Array2i window_lo_ = Eigen::Array2i::Zero();
};

}  // namespace slamrig::slam
