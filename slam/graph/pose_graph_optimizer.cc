#include "slam/graph/pose_graph_optimizer.h"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <array>
#include <memory>
#include <numbers>
#include <utility>
#include <vector>

#include "slam/graph/edge_error.h"
#include "slam/types/check.h"

namespace slamrig::slam {
namespace {

// One EDGE_SE2 as a Ceres residual r = S e with S = L^T, Omega = L L^T, so that
// r^T r = e^T Omega e; Ceres minimises 1/2 sum r^T r, i.e. half of g2o's chi2.
class EdgeCost final : public ceres::SizedCostFunction<3, 3, 3> {
 public:
  EdgeCost(const Pose2& measurement, const Eigen::Matrix3d& information)
      : measurement_(measurement),
        sqrt_information_(Eigen::LLT<Eigen::Matrix3d>(information).matrixU()) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Map<const Eigen::Vector3d> xi(parameters[0]);
    const Eigen::Map<const Eigen::Vector3d> xj(parameters[1]);
    const EdgeErrorResult e = EvaluateEdgeError(xi, xj, measurement_);
    Eigen::Map<Eigen::Vector3d> r(residuals);
    r = sqrt_information_ * e.error;
    if (jacobians != nullptr) {
      using RowMajor = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
      if (jacobians[0] != nullptr) {
        Eigen::Map<RowMajor> j(jacobians[0]);
        j = sqrt_information_ * e.d_error_d_xi;
      }
      if (jacobians[1] != nullptr) {
        Eigen::Map<RowMajor> j(jacobians[1]);
        j = sqrt_information_ * e.d_error_d_xj;
      }
    }
    return true;
  }

 private:
  Pose2 measurement_;
  Eigen::Matrix3d sqrt_information_;
};

// A switchable edge (Sünderhauf and Protzel 2012, eq. 4): the residual w S e, its switch w the
// third parameter block.
class SwitchedEdgeCost final : public ceres::SizedCostFunction<3, 3, 3, 1> {
 public:
  SwitchedEdgeCost(const Pose2& measurement, const Eigen::Matrix3d& information)
      : edge_(measurement, information) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double w = parameters[2][0];
    double* edge_jacobians[2] = {nullptr, nullptr};
    double storage[2][9];
    if (jacobians != nullptr) {
      for (int k = 0; k < 2; ++k)
        edge_jacobians[k] = jacobians[k] != nullptr ? storage[k] : nullptr;
    }
    Eigen::Vector3d r;
    if (!edge_.Evaluate(parameters, r.data(), jacobians != nullptr ? edge_jacobians : nullptr)) {
      return false;
    }
    for (int i = 0; i < 3; ++i) residuals[i] = w * r[i];
    if (jacobians != nullptr) {
      for (int k = 0; k < 2; ++k) {
        if (jacobians[k] != nullptr) {
          for (int i = 0; i < 9; ++i) jacobians[k][i] = w * storage[k][i];
        }
      }
      if (jacobians[2] != nullptr) {
        for (int i = 0; i < 3; ++i) jacobians[2][i] = r[i];
      }
    }
    return true;
  }

 private:
  EdgeCost edge_;
};

// The switch's prior: scale (1 - w), pulling every switch towards on.
class SwitchPriorCost final : public ceres::SizedCostFunction<1, 1> {
 public:
  explicit SwitchPriorCost(double scale) : scale_(scale) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    residuals[0] = scale_ * (1.0 - parameters[0][0]);
    if (jacobians != nullptr && jacobians[0] != nullptr) jacobians[0][0] = -scale_;
    return true;
  }

 private:
  double scale_;
};

// The same residual, templated for Ceres's automatic differentiation (the cross-check of the
// analytic Jacobians, and their benchmark baseline).
class EdgeResidual {
 public:
  EdgeResidual(const Pose2& measurement, const Eigen::Matrix3d& information)
      : measurement_(measurement),
        sqrt_information_(Eigen::LLT<Eigen::Matrix3d>(information).matrixU()) {}

  template <typename T>
  bool operator()(const T* xi, const T* xj, T* residuals) const {
    using std::cos, std::sin;
    const T ci = cos(xi[2]), si = sin(xi[2]);
    const T dx = xj[0] - xi[0], dy = xj[1] - xi[1];
    const T ux = ci * dx + si * dy - measurement_.x();
    const T uy = -si * dx + ci * dy - measurement_.y();
    const double cz = std::cos(measurement_.theta()), sz = std::sin(measurement_.theta());
    // Wrapped into [-pi, pi); the derivative of the wrap is 1 wherever it is defined.
    const T angle = xj[2] - xi[2] - measurement_.theta();
    const double two_pi = 2.0 * std::numbers::pi;
    const T wrapped = angle - two_pi * ceres::floor((angle + std::numbers::pi) / two_pi);
    const Eigen::Matrix<T, 3, 1> e(cz * ux + sz * uy, -sz * ux + cz * uy, wrapped);
    Eigen::Map<Eigen::Matrix<T, 3, 1>> r(residuals);
    r = sqrt_information_.cast<T>() * e;
    return true;
  }

 private:
  Pose2 measurement_;
  Eigen::Matrix3d sqrt_information_;
};

// (x, y, theta) with a plain additive step whose angle is wrapped into (-pi, pi].
class PoseManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 3; }
  int TangentSize() const override { return 3; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override {
    x_plus_delta[0] = x[0] + delta[0];
    x_plus_delta[1] = x[1] + delta[1];
    x_plus_delta[2] = NormalizeAngle(x[2] + delta[2]);
    return true;
  }
  bool PlusJacobian(const double* /*x*/, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> j(jacobian);
    j.setIdentity();
    return true;
  }
  bool Minus(const double* y, const double* x, double* y_minus_x) const override {
    y_minus_x[0] = y[0] - x[0];
    y_minus_x[1] = y[1] - x[1];
    y_minus_x[2] = NormalizeAngle(y[2] - x[2]);
    return true;
  }
  bool MinusJacobian(const double* /*x*/, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> j(jacobian);
    j.setIdentity();
    return true;
  }
};

std::unique_ptr<ceres::LossFunction> MakeLoss(RobustLoss loss, double scale) {
  switch (loss) {
    case RobustLoss::kNone:
      return nullptr;
    case RobustLoss::kHuber:
      return std::make_unique<ceres::HuberLoss>(scale);
    case RobustLoss::kCauchy:
      return std::make_unique<ceres::CauchyLoss>(scale);
    case RobustLoss::kSwitchable:
      return nullptr;  // a switch variable per edge instead (SwitchedEdgeCost)
  }
  return nullptr;
}

ceres::Solver::Options SolverOptions(const PoseGraphOptimizerOptions& o) {
  ceres::Solver::Options s;
  s.max_num_iterations = o.max_iterations;
  s.num_threads = o.num_threads;
  s.function_tolerance = o.function_tolerance;
  s.gradient_tolerance = o.gradient_tolerance;
  s.parameter_tolerance = o.parameter_tolerance;
  s.trust_region_strategy_type =
      o.trust_region == TrustRegion::kDogleg ? ceres::DOGLEG : ceres::LEVENBERG_MARQUARDT;
  s.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  s.initial_trust_region_radius = o.initial_trust_region_radius;
  // Eigen's simplicial Cholesky beat CHOLMOD here on the benchmark graphs (city10000: 183 vs
  // 257 ms CPU, bench/graph_benchmark.cc); CHOLMOD when Ceres was built without Eigen sparse.
  s.sparse_linear_algebra_library_type =
      ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::EIGEN_SPARSE) ? ceres::EIGEN_SPARSE
                                                                            : ceres::SUITE_SPARSE;
  s.logging_type = ceres::SILENT;
  s.minimizer_progress_to_stdout = false;
  return s;
}

}  // namespace

PoseGraphOptimizer::PoseGraphOptimizer(const PoseGraphOptimizerOptions& options)
    : options_(options) {
  SLAMRIG_CHECK_VALID(options_, "PoseGraphOptimizerOptions");
}

PoseGraphSummary PoseGraphOptimizer::Optimize(PoseGraph* graph) const {
  PoseGraphSummary summary;
  summary.num_vertices = static_cast<int>(graph->vertices().size());
  summary.num_edges = static_cast<int>(graph->edges().size());
  summary.initial_chi2 = Chi2(*graph);

  std::vector<std::array<double, 3>> x(graph->vertices().size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    const Pose2& p = graph->vertices()[i].pose;
    x[i] = {p.x(), p.y(), p.theta()};
  }

  // The problem borrows the shared loss and manifold; it owns the cost functions.
  const std::unique_ptr<ceres::LossFunction> loss =
      MakeLoss(options_.robust_loss, options_.robust_loss_scale);
  PoseManifold manifold;
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  const bool switchable = options_.robust_loss == RobustLoss::kSwitchable;
  // Every switch starts on: the solve turns off the edges the others contradict.
  std::vector<double> switches(switchable ? graph->edges().size() : 0, 1.0);
  for (std::size_t k = 0; k < graph->edges().size(); ++k) {
    const PoseGraphEdge& e = graph->edges()[k];
    const bool robust = options_.robust_loss_on_all_edges || e.kind == EdgeKind::kLoopClosure;
    if (switchable && robust) {
      double* w = &switches[k];
      problem.AddResidualBlock(new SwitchedEdgeCost(e.measurement, e.information), nullptr,
                               x[graph->IndexOf(e.from)].data(), x[graph->IndexOf(e.to)].data(), w);
      problem.AddResidualBlock(new SwitchPriorCost(options_.robust_loss_scale), nullptr, w);
      problem.SetParameterLowerBound(w, 0, 0.0);
      problem.SetParameterUpperBound(w, 0, 1.0);
      continue;
    }
    ceres::CostFunction* cost = options_.autodiff_jacobians
                                    ? static_cast<ceres::CostFunction*>(
                                          new ceres::AutoDiffCostFunction<EdgeResidual, 3, 3, 3>(
                                              new EdgeResidual(e.measurement, e.information)))
                                    : new EdgeCost(e.measurement, e.information);
    problem.AddResidualBlock(cost, robust ? loss.get() : nullptr, x[graph->IndexOf(e.from)].data(),
                             x[graph->IndexOf(e.to)].data());
  }
  if (problem.NumResidualBlocks() == 0) {
    summary.final_chi2 = summary.initial_chi2;
    summary.converged = true;
    summary.message = "no edges: nothing to optimise";
    return summary;
  }
  for (auto& block : x) {
    if (problem.HasParameterBlock(block.data())) problem.SetManifold(block.data(), &manifold);
  }
  for (const std::size_t i : graph->AnchorIndices()) {
    if (problem.HasParameterBlock(x[i].data())) problem.SetParameterBlockConstant(x[i].data());
  }

  ceres::Solver::Summary ceres_summary;
  ceres::Solve(SolverOptions(options_), &problem, &ceres_summary);

  for (std::size_t i = 0; i < x.size(); ++i) {
    graph->SetPose(graph->vertices()[i].id, Pose2(x[i][0], x[i][1], x[i][2]));
  }
  summary.final_chi2 = Chi2(*graph);
  // Ceres lists iteration 0 (the initial evaluation) too.
  summary.iterations = static_cast<int>(ceres_summary.iterations.size()) - 1;
  summary.time_s = ceres_summary.total_time_in_seconds;
  summary.converged = ceres_summary.termination_type == ceres::CONVERGENCE;
  summary.message = ceres_summary.message;
  summary.switches = std::move(switches);
  return summary;
}

}  // namespace slamrig::slam
