#include "slam/matching/point_kd_tree.h"

#include <algorithm>
#include <cmath>
#include <limits>
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

// nanoflann's result-set interface for the one nearest point closer than a bound: the search
// visits only branches that may hold a point closer than worstDist(), and a leaf offers a point
// only when it is closer than that (KNNResultSet of capacity 1, started at the bound).
class NearestWithin {
 public:
  explicit NearestWithin(double bound) : worst_(bound) {}
  double worstDist() const { return worst_; }
  bool addPoint(double distance2, std::uint32_t index) {
    if (distance2 < worst_) {
      worst_ = distance2;
      index_ = index;
      found_ = true;
    }
    return true;
  }
  bool full() const { return found_; }
  std::uint32_t index() const { return index_; }

 private:
  double worst_;
  std::uint32_t index_ = 0;
  bool found_ = false;
};

bool PointKdTree::Nearest(const Eigen::Vector2d& query, std::uint32_t* index, double* distance2,
                          double max_distance2) const {
  if (points_.empty() || !(max_distance2 >= 0.0)) return false;
  // A point at exactly the bound is within it: offered points must be strictly closer than the
  // next double up.
  NearestWithin result(std::nextafter(max_distance2, std::numeric_limits<double>::infinity()));
  const double q[2] = {query.x(), query.y()};
  index_->tree.findNeighbors(result, q, nanoflann::SearchParams());
  if (!result.full()) return false;
  *index = result.index();
  *distance2 = result.worstDist();
  return true;
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
