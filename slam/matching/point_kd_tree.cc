#include "slam/matching/point_kd_tree.h"

#include <algorithm>
#include <nanoflann.hpp>

namespace slamrig::slam {
namespace {

// nanoflann's dataset interface over a vector of points (it reads them in place).
struct PointsAdaptor {
  const std::vector<Eigen::Vector2d>* points;
  std::size_t kdtree_get_point_count() const { return points->size(); }
  double kdtree_get_pt(std::size_t i, std::size_t dim) const { return (*points)[i][dim]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};

using Tree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointsAdaptor>,
                                        PointsAdaptor, 2, std::uint32_t>;

}  // namespace

struct PointKdTree::Index {
  explicit Index(const std::vector<Eigen::Vector2d>* points)
      : adaptor{points}, tree(2, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10)) {}
  PointsAdaptor adaptor;
  Tree tree;
};

PointKdTree::PointKdTree(std::vector<Eigen::Vector2d> points) : points_(std::move(points)) {
  index_ = std::make_unique<Index>(&points_);
}

PointKdTree::~PointKdTree() = default;

// The adaptor points at points_, whose heap buffer moves with the vector; re-aim it after a move.
PointKdTree::PointKdTree(PointKdTree&& other) noexcept
    : points_(std::move(other.points_)), index_(std::move(other.index_)) {
  if (index_) index_->adaptor.points = &points_;
}

PointKdTree& PointKdTree::operator=(PointKdTree&& other) noexcept {
  points_ = std::move(other.points_);
  index_ = std::move(other.index_);
  if (index_) index_->adaptor.points = &points_;
  return *this;
}

bool PointKdTree::Nearest(const Eigen::Vector2d& query, std::uint32_t* index,
                          double* distance2) const {
  if (points_.empty()) return false;
  nanoflann::KNNResultSet<double, std::uint32_t> result(1);
  result.init(index, distance2);
  const double q[2] = {query.x(), query.y()};
  index_->tree.findNeighbors(result, q, nanoflann::SearchParams());
  return result.size() == 1;
}

void PointKdTree::KNearest(const Eigen::Vector2d& query, int k, std::vector<std::uint32_t>* indices,
                           std::vector<double>* distances2) const {
  const auto capacity = static_cast<std::size_t>(std::max(k, 0));
  indices->resize(capacity);
  distances2->resize(capacity);
  if (points_.empty() || capacity == 0) {
    indices->clear();
    distances2->clear();
    return;
  }
  nanoflann::KNNResultSet<double, std::uint32_t> result(capacity);
  result.init(indices->data(), distances2->data());
  const double q[2] = {query.x(), query.y()};
  index_->tree.findNeighbors(result, q, nanoflann::SearchParams());
  indices->resize(result.size());
  distances2->resize(result.size());
}

}  // namespace slamrig::slam
