#include "slam/graph/optimality_certificate.h"

#include <Spectra/SymEigsSolver.h>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <vector>

#include "slam/graph/edge_error.h"
#include "slam/graph/pose_graph_optimizer.h"
#include "slam/types/check.h"
#include "slam/types/format.h"

namespace slamrig::slam {
namespace {

using SparseMatrix = Eigen::SparseMatrix<double>;

// The largest absolute row sum: a bound on every eigenvalue's magnitude (Gershgorin).
double GershgorinBound(const SparseMatrix& s) {
  Eigen::VectorXd row_sums = Eigen::VectorXd::Zero(s.rows());
  for (int k = 0; k < s.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(s, k); it; ++it) row_sums(it.row()) += std::abs(it.value());
  }
  return row_sums.size() == 0 ? 0.0 : row_sums.maxCoeff();
}

// 1 - cos(e) without the cancellation of its two terms: near a solution e is ~1e-3, where
// 1 - cos(e) loses six of its sixteen digits, and kappa (~1e4) makes that rounding in f far
// larger than the decrease of a Newton step near the minimum, which then looked like a rise.
double OneMinusCos(double e) {
  const double s = std::sin(0.5 * e);
  return 2.0 * s * s;
}

// One edge of f, with what it needs precomputed.
struct IsotropicEdge {
  std::size_t a = 0, b = 0;  // vertex indices of from and to
  Eigen::Vector2d z;         // measured translation
  double theta = 0.0;        // measured rotation
  IsotropicWeights w;
};

std::vector<IsotropicEdge> IsotropicEdges(const PoseGraph& graph) {
  std::vector<IsotropicEdge> edges;
  edges.reserve(graph.edges().size());
  for (const PoseGraphEdge& e : graph.edges()) {
    edges.push_back({graph.IndexOf(e.from), graph.IndexOf(e.to), e.measurement.translation(),
                     e.measurement.theta(), SeSyncWeights(e.information)});
  }
  return edges;
}

// f and, when `h` is given, its gradient and Hessian in the poses' (x, y, theta), pose i at
// 3 * unknown[i] (unknown[i] < 0: held, left out). Per edge, with d = t_j - t_i - R_i t_ij,
// u = dR_i/dtheta_i t_ij, w = R_i t_ij and e = theta_j - theta_i - theta_ij:
//   f_e = 4 kappa (1 - cos e) + tau |d|^2,
//   df/dt_j = 2 tau d, df/dt_i = -2 tau d, df/dtheta_j = 4 kappa sin e,
//   df/dtheta_i = -2 tau d.u - 4 kappa sin e,
//   d2f/dtheta_i2 = 2 tau (|u|^2 + d.w) + 4 kappa cos e, d2f/dt_i dtheta_i = 2 tau u, ...
double IsotropicCostAndDerivatives(const std::vector<IsotropicEdge>& edges,
                                   const std::vector<Eigen::Index>& unknown,
                                   const std::vector<Eigen::Vector3d>& x, Eigen::VectorXd* g,
                                   std::vector<Eigen::Triplet<double>>* h) {
  double f = 0.0;
  for (const IsotropicEdge& e : edges) {
    const std::size_t a = e.a, b = e.b;
    const IsotropicWeights& wt = e.w;
    const Eigen::Vector2d w = RotationMatrix(x[a].z()) * e.z;
    const Eigen::Vector2d u(-w.y(), w.x());
    const Eigen::Vector2d d = x[b].head<2>() - x[a].head<2>() - w;
    const double angle = x[b].z() - x[a].z() - e.theta;
    const double k4 = 4.0 * wt.kappa, t2 = 2.0 * wt.tau;
    f += k4 * OneMinusCos(angle) + wt.tau * d.squaredNorm();
    if (h == nullptr) continue;
    // Gradient and Hessian of f_e over (t_i, theta_i, t_j, theta_j).
    Eigen::Matrix<double, 6, 1> ge;
    ge << -t2 * d, -t2 * d.dot(u) - k4 * std::sin(angle), t2 * d, k4 * std::sin(angle);
    Eigen::Matrix<double, 6, 6> he = Eigen::Matrix<double, 6, 6>::Zero();
    const Eigen::Matrix2d i2 = t2 * Eigen::Matrix2d::Identity();
    he.block<2, 2>(0, 0) = i2;
    he.block<2, 2>(3, 3) = i2;
    he.block<2, 2>(0, 3) = -i2;
    he.block<2, 2>(3, 0) = -i2;
    he.block<2, 1>(0, 2) = t2 * u;
    he.block<2, 1>(3, 2) = -t2 * u;
    he(2, 2) = t2 * (u.squaredNorm() + d.dot(w)) + k4 * std::cos(angle);
    he(5, 5) = k4 * std::cos(angle);
    he(2, 5) = -k4 * std::cos(angle);
    he.block<1, 2>(2, 0) = he.block<2, 1>(0, 2).transpose();
    he.block<1, 2>(2, 3) = he.block<2, 1>(3, 2).transpose();
    he(5, 2) = he(2, 5);
    const Eigen::Index blocks[2] = {unknown[a], unknown[b]};
    for (int r = 0; r < 2; ++r) {
      if (blocks[r] < 0) continue;
      g->segment<3>(3 * blocks[r]) += ge.segment<3>(3 * r);
      for (int c = 0; c < 2; ++c) {
        if (blocks[c] < 0) continue;
        for (int k = 0; k < 3; ++k) {
          for (int l = 0; l < 3; ++l) {
            h->emplace_back(3 * blocks[r] + k, 3 * blocks[c] + l, he(3 * r + k, 3 * c + l));
          }
        }
      }
    }
  }
  return f;
}

// Minimises f from the graph's poses by Newton's method with the exact Hessian (damped, with
// the damping raised until the step is a descent that lowers f), holding the first anchor: f is
// invariant under a global rigid motion, so one held pose changes neither its minima nor their
// stationarity. Newton rather than Gauss-Newton: the minima of f can be nearly flat along a
// direction (ais2klinik), where Gauss-Newton converges linearly at a rate near 1. Returns the
// iterations taken.
struct RefineResult {
  int iterations = 0;
  bool converged = false;
};
RefineResult RefineIsotropic(PoseGraph* graph, int max_iterations) {
  const std::size_t n = graph->vertices().size();
  std::vector<Eigen::Index> unknown(n, -1);
  const std::vector<std::size_t> anchors = graph->AnchorIndices();
  Eigen::Index num_unknowns = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (anchors.empty() || i != anchors.front()) unknown[i] = num_unknowns++;
  }
  std::vector<Eigen::Vector3d> x(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Pose2& p = graph->vertices()[i].pose;
    x[i] = {p.x(), p.y(), p.theta()};
  }
  const std::vector<IsotropicEdge> edges = IsotropicEdges(*graph);
  Eigen::SimplicialLLT<SparseMatrix> llt;
  SparseMatrix hessian(3 * num_unknowns, 3 * num_unknowns), identity = hessian;
  identity.setIdentity();
  std::vector<Eigen::Triplet<double>> triplets;
  int iteration = 0;
  bool converged = num_unknowns == 0;
  for (; iteration < max_iterations && !converged; ++iteration) {
    Eigen::VectorXd g = Eigen::VectorXd::Zero(3 * num_unknowns);
    triplets.clear();
    triplets.reserve(36 * edges.size());
    const double f = IsotropicCostAndDerivatives(edges, unknown, x, &g, &triplets);
    hessian.setFromTriplets(triplets.begin(), triplets.end());
    if (iteration == 0) llt.analyzePattern(hessian);
    // Beyond the Gershgorin bound the damped Hessian is positive definite and the step a
    // descent direction that is short enough to lower f.
    const double bound = GershgorinBound(hessian);
    bool improved = false;
    for (double damping = 0.0; damping < 1e6 * bound;
         damping = std::max(1e-12 * bound, 10 * damping)) {
      llt.factorize(hessian + damping * identity);
      if (llt.info() != Eigen::Success) continue;
      const Eigen::VectorXd step = -llt.solve(g);
      std::vector<Eigen::Vector3d> trial = x;
      for (std::size_t i = 0; i < n; ++i) {
        if (unknown[i] >= 0) trial[i] += step.segment<3>(3 * unknown[i]);
      }
      // Accepted when f does not rise beyond its rounding noise. An undamped step whose
      // predicted decrease is below 1e-16 f ends the iteration: Newton's convergence is
      // quadratic there, so the gradient left is at rounding level. (The duality gap weighs the
      // gradient by the poses' coordinates: a predicted decrease of 1e-12 f left gaps of 1e-4 f.)
      // A damped step converges nothing: a short step predicts a small decrease anywhere.
      const double noise = 1e-13 * std::abs(f);
      if (IsotropicCostAndDerivatives(edges, unknown, trial, nullptr, nullptr) <= f + noise) {
        x = std::move(trial);
        converged = damping == 0.0 && -0.5 * g.dot(step) <= 1e-16 * std::abs(f);
        improved = true;
        break;
      }
    }
    if (!improved) break;
  }
  for (std::size_t i = 0; i < n; ++i) {
    graph->SetPose(graph->vertices()[i].id, Pose2(x[i].x(), x[i].y(), x[i].z()));
  }
  return {.iterations = iteration, .converged = converged};
}

// X^T (3n x 2): pose i's translation at row 3i, its rotation's transpose at rows 3i+1, 3i+2.
Eigen::MatrixXd StackedPosesTransposed(const PoseGraph& graph) {
  const std::size_t n = graph.vertices().size();
  Eigen::MatrixXd xt(3 * n, 2);
  for (std::size_t i = 0; i < n; ++i) {
    const Pose2& p = graph.vertices()[i].pose;
    xt.row(3 * i) = p.translation().transpose();
    xt.block<2, 2>(3 * i + 1, 0) = RotationMatrix(p.theta()).transpose();
  }
  return xt;
}

// y = (S - sigma I)^-1 x with a factorisation made beforehand, for Spectra.
class InverseOperator {
 public:
  using Scalar = double;
  explicit InverseOperator(const Eigen::SimplicialLLT<SparseMatrix>& llt, Eigen::Index n)
      : llt_(llt), n_(n) {}
  Eigen::Index rows() const { return n_; }
  Eigen::Index cols() const { return n_; }
  void perform_op(const double* in, double* out) const {
    Eigen::Map<Eigen::VectorXd>(out, n_) = llt_.solve(Eigen::Map<const Eigen::VectorXd>(in, n_));
  }

 private:
  const Eigen::SimplicialLLT<SparseMatrix>& llt_;
  Eigen::Index n_;
};

}  // namespace

IsotropicWeights SeSyncWeights(const Eigen::Matrix3d& information) {
  const Eigen::Matrix2d translation = information.topLeftCorner<2, 2>();
  return {.kappa = information(2, 2), .tau = 2.0 / translation.inverse().trace()};
}

double SeSyncCost(const PoseGraph& graph) {
  double f = 0.0;
  for (const PoseGraphEdge& e : graph.edges()) {
    const IsotropicWeights w = SeSyncWeights(e.information);
    const Pose2& a = graph.pose(e.from);
    const Pose2& b = graph.pose(e.to);
    const double angle = b.theta() - a.theta() - e.measurement.theta();
    const Eigen::Vector2d dt =
        b.translation() - a.translation() - RotationMatrix(a.theta()) * e.measurement.translation();
    f += w.kappa * 4.0 * OneMinusCos(angle) + w.tau * dt.squaredNorm();
  }
  return f;
}

SparseMatrix SeSyncDataMatrix(const PoseGraph& graph) {
  const Eigen::Index n = static_cast<Eigen::Index>(graph.vertices().size());
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(graph.edges().size() * 25);
  for (const PoseGraphEdge& e : graph.edges()) {
    const IsotropicWeights w = SeSyncWeights(e.information);
    const Eigen::Index i = 3 * static_cast<Eigen::Index>(graph.IndexOf(e.from));
    const Eigen::Index j = 3 * static_cast<Eigen::Index>(graph.IndexOf(e.to));
    // Translation: tau (a^T x_k)^2 with a = +1 at t_j, -1 at t_i, -t_ij at R_i's row.
    const Eigen::Vector2d t = e.measurement.translation();
    const std::array<std::pair<Eigen::Index, double>, 4> a = {
        {{j, 1.0}, {i, -1.0}, {i + 1, -t.x()}, {i + 2, -t.y()}}};
    for (const auto& [r, ar] : a) {
      for (const auto& [c, ac] : a) triplets.emplace_back(r, c, w.tau * ar * ac);
    }
    // Rotation: kappa |R_j row - R_ij^T R_i row|^2: kappa I on both diagonal blocks,
    // -kappa R_ij at (i, j) and its transpose at (j, i).
    const Eigen::Matrix2d rij = RotationMatrix(e.measurement.theta());
    for (int r = 0; r < 2; ++r) {
      triplets.emplace_back(i + 1 + r, i + 1 + r, w.kappa);
      triplets.emplace_back(j + 1 + r, j + 1 + r, w.kappa);
      for (int c = 0; c < 2; ++c) {
        triplets.emplace_back(i + 1 + r, j + 1 + c, -w.kappa * rij(r, c));
        triplets.emplace_back(j + 1 + c, i + 1 + r, -w.kappa * rij(r, c));
      }
    }
  }
  SparseMatrix m(3 * n, 3 * n);
  m.setFromTriplets(triplets.begin(), triplets.end());
  return m;
}

SparseMatrix CertificateMatrix(const PoseGraph& graph, double* dual_value) {
  const SparseMatrix m = SeSyncDataMatrix(graph);
  const Eigen::MatrixXd xt = StackedPosesTransposed(graph);
  const Eigen::MatrixXd g = m * xt;
  std::vector<Eigen::Triplet<double>> triplets;
  const std::size_t n = graph.vertices().size();
  triplets.reserve(4 * n);
  double dual = 0.0;
  for (std::size_t p = 0; p < n; ++p) {
    const Eigen::Index r0 = 3 * static_cast<Eigen::Index>(p) + 1;
    const Eigen::Matrix2d rp = xt.block<2, 2>(r0, 0).transpose();
    const Eigen::Matrix2d prod = g.block<2, 2>(r0, 0) * rp;
    const Eigen::Matrix2d lambda = 0.5 * (prod + prod.transpose());
    dual += lambda.trace();
    for (int r = 0; r < 2; ++r) {
      for (int c = 0; c < 2; ++c) triplets.emplace_back(r0 + r, r0 + c, lambda(r, c));
    }
  }
  SparseMatrix lambda(m.rows(), m.cols());
  lambda.setFromTriplets(triplets.begin(), triplets.end());
  if (dual_value != nullptr) *dual_value = dual;
  return m - lambda;
}

double MinimumEigenvalue(const SparseMatrix& s, double start) {
  SLAMRIG_CHECK(start > 0.0 && s.rows() == s.cols() && s.rows() >= 2,
                "MinimumEigenvalue: needs start > 0 and a square matrix of size >= 2");
  const double bound = GershgorinBound(s);
  SparseMatrix identity(s.rows(), s.cols());
  identity.setIdentity();
  Eigen::SimplicialLLT<SparseMatrix> llt;
  llt.analyzePattern(s + identity);
  for (double shift = start;; shift *= 10.0) {
    // S + shift I is positive definite exactly when lambda_min > -shift.
    llt.factorize(s + shift * identity);
    if (llt.info() == Eigen::Success) {
      InverseOperator op(llt, s.rows());
      const Eigen::Index ncv = std::min<Eigen::Index>(20, s.rows());
      Spectra::SymEigsSolver<InverseOperator> eigs(op, 1, ncv);
      eigs.init();
      eigs.compute(Spectra::SortRule::LargestAlge, 1000, 1e-3);
      if (eigs.info() != Spectra::CompInfo::Successful) break;
      return 1.0 / eigs.eigenvalues()(0) - shift;
    }
    if (shift > 2.0 * bound) break;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

OptimalityCertificate CertifyOptimality(const PoseGraph& graph,
                                        const OptimalityCertificateOptions& options) {
  SLAMRIG_CHECK(!graph.edges().empty(), "CertifyOptimality: the graph has no edges");
  const auto start = std::chrono::steady_clock::now();
  OptimalityCertificate c;
  c.cost_at_input = SeSyncCost(graph);
  PoseGraph refined = graph;
  const RefineResult refine = RefineIsotropic(&refined, options.max_iterations);
  c.refine_iterations = refine.iterations;
  c.refine_converged = refine.converged;
  c.cost = SeSyncCost(refined);
  for (std::size_t i = 0; i < graph.vertices().size(); ++i) {
    const Pose2& a = graph.vertices()[i].pose;
    const Pose2& b = refined.vertices()[i].pose;
    c.max_translation_change_m =
        std::max(c.max_translation_change_m, (a.translation() - b.translation()).norm());
    c.max_rotation_change_rad =
        std::max(c.max_rotation_change_rad, std::abs(NormalizeAngle(a.theta() - b.theta())));
  }
  const SparseMatrix m = SeSyncDataMatrix(refined);
  double scale = 0.0;
  for (Eigen::Index k = 0; k < m.rows(); ++k) scale = std::max(scale, m.coeff(k, k));
  c.tolerance = options.relative_tolerance * scale;
  c.lambda_min = MinimumEigenvalue(CertificateMatrix(refined, &c.dual_value), c.tolerance);
  c.relaxation_tight =
      c.refine_converged && std::isfinite(c.lambda_min) && c.lambda_min >= -c.tolerance &&
      c.cost - c.dual_value <= options.relative_gap_tolerance * std::max(c.cost, c.tolerance);
  // Whether the given solution is the chi2 minimum in the basin of f's certified minimiser.
  c.chi2 = Chi2(graph);
  c.chi2_from_certified = c.chi2;
  c.chi2_at_refined = Chi2(refined);
  if (c.relaxation_tight) {
    c.chi2_from_certified = PoseGraphOptimizer(options.optimizer).Optimize(&refined).final_chi2;
  }
  c.certified =
      c.relaxation_tight &&
      c.chi2_from_certified >= c.chi2 - options.relative_chi2_tolerance * std::max(c.chi2, 1.0);
  c.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return c;
}

PoseGraph WithRobustWeights(const PoseGraph& graph, const PoseGraphOptimizerOptions& options,
                            const std::vector<double>& switches) {
  PoseGraph out;
  for (const PoseGraphVertex& v : graph.vertices()) out.AddVertex(v.id, v.pose, v.fixed);
  const double a2 = options.robust_loss_scale * options.robust_loss_scale;
  for (std::size_t k = 0; k < graph.edges().size(); ++k) {
    PoseGraphEdge e = graph.edges()[k];
    const bool robust = options.robust_loss_on_all_edges || e.kind == EdgeKind::kLoopClosure;
    double weight = 1.0;
    if (robust && options.robust_loss != RobustLoss::kNone) {
      const Eigen::Vector3d error = EdgeError(graph, e);
      const double s = error.dot(e.information * error);
      switch (options.robust_loss) {
        case RobustLoss::kHuber:
          weight = s <= a2 ? 1.0 : std::sqrt(a2 / s);
          break;
        case RobustLoss::kCauchy:
          weight = 1.0 / (1.0 + s / a2);
          break;
        case RobustLoss::kSwitchable:
          weight = k < switches.size() ? switches[k] * switches[k] : 1.0;
          break;
        case RobustLoss::kNone:
          break;
      }
    }
    e.information *= std::max(weight, 1e-9);
    out.AddEdge(e);
  }
  return out;
}

std::string CertificateLine(const OptimalityCertificate& c) {
  std::string line = std::string(c.certified ? "certified optimal" : "not certified") +
                     " (lambda_min = " + Number("%.3g", c.lambda_min) + ", tolerance " +
                     Number("%.2g", c.tolerance) + "): ";
  if (c.certified) {
    return line + "chi2 " + Number("%.6g", c.chi2) +
           " is the minimum in the basin of SE-Sync's certified global optimum, cost " +
           Number("%.6g", c.cost);
  }
  if (!c.refine_converged) {
    return line + "the refinement of SE-Sync's cost did not converge (cost " +
           Number("%.6g", c.cost) + ")";
  }
  if (!c.relaxation_tight) {
    return line + "SE-Sync's relaxation is not tight at the refined poses (cost " +
           Number("%.6g", c.cost) + ", dual bound " + Number("%.6g", c.dual_value) + ")";
  }
  return line + "from SE-Sync's certified global optimum (cost " + Number("%.6g", c.cost) +
         ") chi2 reaches " + Number("%.6g", c.chi2_from_certified) + ", below this solution's " +
         Number("%.6g", c.chi2);
}

}  // namespace slamrig::slam
