#pragma once

// A certificate of global optimality for 2D pose-graph optimisation, after SE-Sync (Rosen,
// Carlone, Bandeira and Leonard, "SE-Sync: a certifiably correct algorithm for synchronization
// over the special Euclidean group", IJRR 2019) and Cartan-Sync (Briales and Gonzalez-Jimenez,
// "Cartan-Sync: fast and global SE(d)-synchronization", RA-L 2017).
//
// The certified problem is SE-Sync's, not g2o's chi2: each edge's information matrix Omega is
// reduced to two isotropic weights as SE-Sync's g2o reader does for EDGE_SE2,
//   kappa = Omega(2, 2),   tau = 2 / trace(inverse(Omega's translation block)),
// and the cost is
//   f(x) = sum_ij kappa ||R_j - R_i R_ij||_F^2 + tau ||t_j - t_i - R_i t_ij||^2   (no 1/2).
// For 2D, ||R_j - R_i R_ij||_F^2 = 4 (1 - cos(e_theta)), about 2 e_theta^2: on the rotations f
// weighs twice what chi2 does, on the translations it uses one isotropic weight per edge.
//
// Written with X = [t_1 R_1 ... t_n R_n] (2 x 3n; t_i a column, R_i 2x2) the cost is
// f = trace(X M X^T) with M (3n x 3n, sparse, one 3x3 block per pose) a sum over edges. With the
// rotations relaxed (Shor's semidefinite relaxation, the dual of SE-Sync's eq. 14 in the explicit
// form) a candidate X gives the Lagrange multiplier Lambda(X) = blkdiag(0, Lambda_1, ...), with
// Lambda_i = sym((M X^T)_{R_i} R_i) on each rotation block and 0 on the translations, and the
// certificate matrix S = M - Lambda(X). At a critical point S X^T = 0, so lambda_min(S) <= 0; if
// S is positive semidefinite the relaxation is tight and X is a global minimiser of f. Keeping
// the translations in the matrix (instead of SE-Sync's reduced Q, which is dense) leaves S
// sparse; its positive semidefiniteness is the same as that of SE-Sync's reduced Q - Lambda
// (Schur complement on the translation Laplacian, whose kernel M shares).

#include <Eigen/SparseCore>
#include <string>
#include <vector>

#include "slam/graph/pose_graph.h"
#include "slam/graph/pose_graph_optimizer_options.h"

namespace slamrig::slam {

/// SE-Sync's isotropic weights of one EDGE_SE2 information matrix.
struct IsotropicWeights {
  double kappa = 0.0;  // rotation: Omega(2, 2)
  double tau = 0.0;    // translation: 2 / trace(Omega_tt^-1)
};
IsotropicWeights SeSyncWeights(const Eigen::Matrix3d& information);

/// SE-Sync's objective f at the graph's current poses (the units of its published optima).
double SeSyncCost(const PoseGraph& graph);

/// The data matrix M of f, 3n x 3n, pose i (in PoseGraph::vertices() order) at rows 3i (its
/// translation coordinate) and 3i+1, 3i+2 (its rotation row), so that
/// f = sum_k x_k^T M x_k over the two rows x_k of X.
Eigen::SparseMatrix<double> SeSyncDataMatrix(const PoseGraph& graph);

/// The certificate matrix S = M - Lambda(X) at the graph's current poses, and the dual value
/// d = sum_i trace(Lambda_i). When S is positive semidefinite, d <= f* (weak duality: for any
/// feasible X', f(X') = trace(X' M X'^T) >= trace(X' Lambda X'^T) = d), so a candidate with
/// f(X) = d is a global minimiser; at a critical point f(X) = d exactly.
Eigen::SparseMatrix<double> CertificateMatrix(const PoseGraph& graph, double* dual_value = nullptr);

/// The smallest eigenvalue of a sparse symmetric matrix: sparse Cholesky factorisations of
/// S - sigma I at sigma = -start, -10 start, ... until one succeeds (then lambda_min > sigma),
/// then Lanczos (Spectra) on (S - sigma I)^-1, whose largest eigenvalue is
/// 1 / (lambda_min - sigma). `start` > 0. Returns NaN if no shift down to -(Gershgorin bound)
/// factorises or Lanczos does not converge.
double MinimumEigenvalue(const Eigen::SparseMatrix<double>& s, double start);

struct OptimalityCertificateOptions {
  /// lambda_min >= -relative_tolerance * scale counts as nonnegative, scale being the largest
  /// diagonal entry of M (the largest weight sum at one pose).
  double relative_tolerance = 1e-8;
  /// f(X) - d <= relative_gap_tolerance * max(f(X), tolerance) (d the dual value,
  /// CertificateMatrix(); the floor for a graph whose optimum costs 0).
  double relative_gap_tolerance = 1e-6;
  /// chi2 re-optimised from f's certified minimiser may be below the given solution's chi2 by
  /// this fraction (Ceres's stopping tolerances; of max(chi2, 1): chi2 is in whitened units, so
  /// below 1 the margin is absolute) and still count as the same minimum.
  double relative_chi2_tolerance = 1e-6;
  /// The chi2 optimiser of that re-optimisation (the caller's own, so both solve one problem).
  PoseGraphOptimizerOptions optimizer;
  /// Newton iterations of the refinement of f from the given poses.
  int max_iterations = 50;
};

/// What CertifyOptimality() found.
struct OptimalityCertificate {
  /// The verdict on the given solution: relaxation_tight, and chi2 optimised from f's certified
  /// minimiser does not reach a lower chi2 than the given solution's (so the given solution is
  /// the chi2 minimum in the basin of the certified global minimiser of f).
  bool certified = false;
  /// SE-Sync's certificate: the refinement of f converged, S >= -tolerance and f(X) = d
  /// (within relative_gap_tolerance): the refined poses are a global minimum of f.
  bool relaxation_tight = false;
  /// g2o's chi2 of the given poses, and after PoseGraphOptimizer from f's certified minimiser
  /// (equal to chi2 when the relaxation is not tight: nothing to start from).
  double chi2 = 0.0;
  double chi2_from_certified = 0.0;
  /// g2o's chi2 at the refined poses (f's minimiser, SE-Sync's solution): above the chi2
  /// minimum, since the two costs weigh the edges differently.
  double chi2_at_refined = 0.0;
  /// Smallest eigenvalue of S at the refined poses (NaN if it could not be computed).
  double lambda_min = 0.0;
  /// The threshold used: certified iff lambda_min >= -tolerance.
  double tolerance = 0.0;
  /// f at the given poses and at the refined (certified or not) poses.
  double cost_at_input = 0.0;
  double cost = 0.0;
  /// Largest change the refinement made to a pose (translation in m, rotation in rad): how far
  /// the certified minimiser of f is from the given solution of chi2.
  double max_translation_change_m = 0.0;
  double max_rotation_change_rad = 0.0;
  /// The dual value d at the refined poses (a lower bound on f's minimum when certified).
  double dual_value = 0.0;
  int refine_iterations = 0;
  /// False when the refinement stopped before a stationary point (then not certified).
  bool refine_converged = false;
  /// Wall time of the whole check in seconds (a measurement only; it never steers anything).
  double time_s = 0.0;
};

/// Refines f from the graph's current poses (Newton, on a copy: `graph` is not changed), builds
/// S at the refined poses and tests it (relaxation_tight: the refined poses are a global
/// minimum of SE-Sync's problem f for this graph), then re-optimises chi2 from there to tell
/// whether the given poses are the chi2 minimum of that basin (certified). The graph needs at
/// least one edge. SE-Sync's problem has one anchored pose: with several fixed vertices the
/// graph is a different (constrained) problem, which this does not certify (callers check).
OptimalityCertificate CertifyOptimality(const PoseGraph& graph,
                                        const OptimalityCertificateOptions& options = {});

/// The graph with each robust edge's information scaled by its robust loss's weight at the
/// graph's poses: rho'(s) at s = e^T Omega e for Huber and Cauchy (Ceres's losses), the switch
/// squared for switchable constraints (`switches` as PoseGraphSummary::switches gives them),
/// at least 1e-9 so that no edge vanishes. A robust solution is a stationary point of this
/// weighted least-squares problem (iteratively reweighted least squares at its fixed point),
/// which is the problem CertifyOptimality() can then check; without a robust loss, the graph.
PoseGraph WithRobustWeights(const PoseGraph& graph, const PoseGraphOptimizerOptions& options,
                            const std::vector<double>& switches);

/// "certified optimal (lambda_min = ...)" or "not certified (lambda_min = ...)", with the
/// tolerance.
std::string CertificateLine(const OptimalityCertificate& c);

}  // namespace slamrig::slam
