#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

namespace slamrig::slam {

/// A static 2D k-d tree over a point set (nanoflann, Blanco and Rai 2014, built once, queried many
/// times): the correspondence search of ICP. Queries are deterministic (same points, same query,
/// same answer) and thread-safe. Not copyable; movable.
class PointKdTree {
 public:
  /// Builds the tree over `points` (which it keeps).
  explicit PointKdTree(std::vector<Eigen::Vector2d> points);
  ~PointKdTree();
  PointKdTree(PointKdTree&&) noexcept;
  PointKdTree& operator=(PointKdTree&&) noexcept;
  PointKdTree(const PointKdTree&) = delete;
  PointKdTree& operator=(const PointKdTree&) = delete;

  const std::vector<Eigen::Vector2d>& points() const { return points_; }
  std::size_t size() const { return points_.size(); }

  /// Index of the point nearest to `query` and its squared distance, through `index` and
  /// `distance2`; false when no point lies within `max_distance2` (squared, inclusive) of it. The
  /// bound prunes the search; the point found within it is the unbounded search's.
  bool Nearest(const Eigen::Vector2d& query, std::uint32_t* index, double* distance2,
               double max_distance2 = std::numeric_limits<double>::infinity()) const;

  /// Up to `k` nearest points to `query`, nearest first, into `indices` and `distances2`
  /// (resized to the number found).
  void KNearest(const Eigen::Vector2d& query, int k, std::vector<std::uint32_t>* indices,
                std::vector<double>* distances2) const;

 private:
  struct Index;
  std::vector<Eigen::Vector2d> points_;
  std::unique_ptr<Index> index_;
};

}  // namespace slamrig::slam
