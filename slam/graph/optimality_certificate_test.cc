#include "slam/graph/optimality_certificate.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <vector>

#include "slam/graph/edge_error.h"
#include "slam/graph/graph_initialization.h"
#include "slam/graph/pose_graph_optimizer.h"
#include "slam/graph/testing/random_graph.h"

namespace slamrig::slam {
namespace {

Eigen::Matrix2d Rot(double theta) { return Eigen::Rotation2Dd(theta).toRotationMatrix(); }

// Three draws, the last first (gcc's order of the arguments this replaced), sequenced so that
// every compiler draws the same pose.
template <typename D>
Pose2 DrawPose(D& d, std::mt19937_64& rng, double yaw_scale = 1.0) {
  const double theta = yaw_scale * d(rng);
  const double y = d(rng);
  const double x = d(rng);
  return Pose2(x, y, theta);
}

// A 4-pose graph with a loop and a chord, random poses and random anisotropic information.
PoseGraph SmallGraph(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  PoseGraph g;
  for (int i = 0; i < 4; ++i) g.AddVertex(10 + 3 * i, DrawPose(u, rng, 1.5));
  const int edges[5][2] = {{10, 13}, {13, 16}, {16, 19}, {19, 10}, {13, 19}};
  for (const auto& [a, b] : edges) {
    Eigen::Matrix3d l = Eigen::Matrix3d::Random();
    const Eigen::Matrix3d information = l * l.transpose() + 0.5 * Eigen::Matrix3d::Identity();
    g.AddEdge({.from = a,
               .to = b,
               .measurement = DrawPose(u, rng),
               .information = information,
               .kind = EdgeKind::kOther});
  }
  return g;
}

// SE-Sync's explicit data matrix from the paper's block definitions (Rosen et al. 2019, eq. 13
// and the definitions of L(W^tau), V, L(G^rho) and Sigma there), translations first
// (n x n), then the rotations (2n x 2n); then permuted to the interleaved order of
// SeSyncDataMatrix (pose i at 3i, 3i+1, 3i+2).
Eigen::MatrixXd DenseDataMatrix(const PoseGraph& g) {
  const int n = static_cast<int>(g.vertices().size());
  Eigen::MatrixXd lw = Eigen::MatrixXd::Zero(n, n), v = Eigen::MatrixXd::Zero(n, 2 * n);
  Eigen::MatrixXd lg = Eigen::MatrixXd::Zero(2 * n, 2 * n), sigma = lg;
  for (const PoseGraphEdge& e : g.edges()) {
    const int i = static_cast<int>(g.IndexOf(e.from)), j = static_cast<int>(g.IndexOf(e.to));
    const Eigen::Matrix2d tt = e.information.topLeftCorner<2, 2>().inverse();
    const double tau = 2.0 / tt.trace(), kappa = e.information(2, 2);
    const Eigen::Vector2d t = e.measurement.translation();
    lw(i, i) += tau;
    lw(j, j) += tau;
    lw(i, j) -= tau;
    lw(j, i) -= tau;
    v.block<1, 2>(i, 2 * i) += tau * t.transpose();
    v.block<1, 2>(j, 2 * i) -= tau * t.transpose();
    lg.block<2, 2>(2 * i, 2 * i) += kappa * Eigen::Matrix2d::Identity();
    lg.block<2, 2>(2 * j, 2 * j) += kappa * Eigen::Matrix2d::Identity();
    lg.block<2, 2>(2 * i, 2 * j) -= kappa * Rot(e.measurement.theta());
    lg.block<2, 2>(2 * j, 2 * i) -= kappa * Rot(e.measurement.theta()).transpose();
    sigma.block<2, 2>(2 * i, 2 * i) += tau * t * t.transpose();
  }
  Eigen::MatrixXd full(3 * n, 3 * n);
  full << lw, v, v.transpose(), lg + sigma;
  std::vector<int> to_interleaved(3 * n);
  for (int i = 0; i < n; ++i) {
    to_interleaved[i] = 3 * i;
    to_interleaved[n + 2 * i] = 3 * i + 1;
    to_interleaved[n + 2 * i + 1] = 3 * i + 2;
  }
  Eigen::MatrixXd out(3 * n, 3 * n);
  for (int r = 0; r < 3 * n; ++r) {
    for (int c = 0; c < 3 * n; ++c) out(to_interleaved[r], to_interleaved[c]) = full(r, c);
  }
  return out;
}

double DenseMinEigenvalue(const Eigen::SparseMatrix<double>& s) {
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Eigen::MatrixXd(s)).eigenvalues()(0);
}

TEST(OptimalityCertificateTest, WeightsAreSeSyncs) {
  Eigen::Matrix3d information;
  information << 4, 1, 0.5, 1, 2, 0.2, 0.5, 0.2, 7;
  const IsotropicWeights w = SeSyncWeights(information);
  EXPECT_DOUBLE_EQ(w.kappa, 7.0);
  // Omega_tt^-1 = [2 -1; -1 4] / 7, trace 6 / 7.
  EXPECT_NEAR(w.tau, 2.0 / (6.0 / 7.0), 1e-12);
}

TEST(OptimalityCertificateTest, DataMatrixMatchesDenseConstructionAndTheCost) {
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const PoseGraph g = SmallGraph(seed);
    const Eigen::MatrixXd m(SeSyncDataMatrix(g));
    const Eigen::MatrixXd dense = DenseDataMatrix(g);
    EXPECT_LT((m - dense).cwiseAbs().maxCoeff(), 1e-12 * dense.cwiseAbs().maxCoeff()) << seed;
    // f(X) = trace(X M X^T) with X = [t_1 R_1 ... t_n R_n].
    Eigen::MatrixXd x(2, 12);
    for (int i = 0; i < 4; ++i) {
      const Pose2& p = g.vertices()[i].pose;
      x.col(3 * i) = p.translation();
      x.block<2, 2>(0, 3 * i + 1) = Rot(p.theta());
    }
    EXPECT_NEAR((x * m * x.transpose()).trace(), SeSyncCost(g), 1e-9 * SeSyncCost(g)) << seed;
  }
}

TEST(OptimalityCertificateTest, MinimumEigenvalueMatchesADenseSolver) {
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const PoseGraph g = SmallGraph(seed);
    // Arbitrary (non-stationary) poses: S has negative eigenvalues of various sizes.
    const Eigen::SparseMatrix<double> s = CertificateMatrix(g);
    const double dense = DenseMinEigenvalue(s);
    EXPECT_NEAR(MinimumEigenvalue(s, 1e-6), dense, 1e-8 * std::max(1.0, std::abs(dense))) << seed;
    // And on a positive semidefinite matrix: M itself (lambda_min = 0, its kernel holds the
    // constant translation).
    const Eigen::SparseMatrix<double> m = SeSyncDataMatrix(g);
    EXPECT_NEAR(MinimumEigenvalue(m, 1e-6), DenseMinEigenvalue(m), 1e-9) << seed;
  }
}

TEST(OptimalityCertificateTest, CertifiesTheOptimumOfLowNoiseGraphs) {
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    testing::RandomPoseGraph r = testing::MakeRandomPoseGraph(
        {.num_poses = 60, .sigma_xy_m = 0.05, .sigma_theta_rad = 0.02, .seed = seed});
    InitializeChordal(&r.graph);
    PoseGraphOptimizer({}).Optimize(&r.graph);
    const PoseGraph before = r.graph;
    const OptimalityCertificate c = CertifyOptimality(r.graph);
    EXPECT_TRUE(c.certified) << CertificateLine(c);
    EXPECT_TRUE(c.relaxation_tight);
    EXPECT_TRUE(c.refine_converged);
    EXPECT_GE(c.lambda_min, -c.tolerance);
    EXPECT_NEAR(c.dual_value, c.cost, 1e-8 * c.cost);  // strong duality
    EXPECT_LE(c.cost, c.cost_at_input);
    EXPECT_NEAR(c.chi2_from_certified, c.chi2, 1e-6 * c.chi2);
    EXPECT_DOUBLE_EQ(c.chi2, Chi2(r.graph));
    for (std::size_t i = 0; i < before.vertices().size(); ++i) {  // the input is untouched
      EXPECT_EQ(before.vertices()[i].pose.x(), r.graph.vertices()[i].pose.x());
    }
    // At a critical point S X^T = 0, so lambda_min is 0 (up to rounding), not positive.
    EXPECT_LT(std::abs(c.lambda_min), c.tolerance);
  }
}

// Graph SLAM's graphs: stiff edges (kappa 2.5e5: 0.002 rad) and residuals of a few milliradians,
// far from the origin. There 1 - cos(e) computed as written loses six digits, the rounding in f
// outgrew a Newton step's decrease near the minimum, the undamped steps looked like rises, and a
// heavily damped step stopped the refinement short of the minimum: a duality gap of 2e-4 f.
TEST(OptimalityCertificateTest, RefinesStiffGraphsToTheirStationaryPoint) {
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    testing::RandomPoseGraph r = testing::MakeRandomPoseGraph({.num_poses = 150,
                                                               .loop_closure_probability = 0.2,
                                                               .sigma_xy_m = 0.005,
                                                               .sigma_theta_rad = 0.002,
                                                               .seed = seed});
    for (const PoseGraphVertex& v : r.graph.vertices()) {  // far from the origin
      r.graph.SetPose(v.id, Pose2(40.0, -30.0, 0.0) * v.pose);
    }
    PoseGraphOptimizer({}).Optimize(&r.graph);
    const OptimalityCertificate c = CertifyOptimality(r.graph);
    EXPECT_TRUE(c.refine_converged) << CertificateLine(c);
    EXPECT_TRUE(c.certified) << CertificateLine(c);
    EXPECT_NEAR(c.dual_value, c.cost, 1e-9 * c.cost) << "seed " << seed;
  }
}

TEST(OptimalityCertificateTest, APerturbedPointIsNotStationaryAndFailsTheTest) {
  testing::RandomPoseGraph r = testing::MakeRandomPoseGraph(
      {.num_poses = 40, .sigma_xy_m = 0.05, .sigma_theta_rad = 0.02, .seed = 3});
  // S at the true poses (not a critical point) perturbed further: negative well below -tol.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0.0, 0.2);
  for (std::size_t i = 1; i < r.graph.vertices().size(); ++i) {
    const PoseGraphVertex& v = r.graph.vertices()[i];
    r.graph.SetPose(v.id, v.pose * DrawPose(n, rng));
  }
  const Eigen::SparseMatrix<double> s = CertificateMatrix(r.graph);
  const double tolerance = 1e-8 * Eigen::VectorXd(s.diagonal()).maxCoeff();
  EXPECT_LT(MinimumEigenvalue(s, tolerance), -1e3 * tolerance);
}

// A noisy graph (0.2 rad heading noise) whose odometry initialisation ends in a poor local
// minimum: the certificate must reject it, and chordal initialisation must reach the minimum
// that it certifies. Seeds 3 and 4 fail in the two ways the check tells apart: at seed 3 the
// relaxation is not tight at the refined poses (a far, poor minimum of SE-Sync's cost too); at
// seed 4 SE-Sync's cost refines to its certified optimum, from which chi2 reaches far lower.
TEST(OptimalityCertificateTest, RejectsPoorLocalMinimaThatChordalInitialisationAvoids) {
  for (std::uint64_t seed : {3, 4}) {
    testing::RandomPoseGraph r = testing::MakeRandomPoseGraph({.num_poses = 100,
                                                               .loop_closure_probability = 0.2,
                                                               .sigma_xy_m = 0.1,
                                                               .sigma_theta_rad = 0.2,
                                                               .seed = seed});
    PoseGraph from_odometry = r.graph, from_chordal = r.graph;
    InitializeFromOdometry(&from_odometry);
    InitializeChordal(&from_chordal);
    const double odometry_chi2 = PoseGraphOptimizer({}).Optimize(&from_odometry).final_chi2;
    const double chordal_chi2 = PoseGraphOptimizer({}).Optimize(&from_chordal).final_chi2;
    EXPECT_GT(odometry_chi2, 5.0 * chordal_chi2) << seed;

    const OptimalityCertificate bad = CertifyOptimality(from_odometry);
    EXPECT_FALSE(bad.certified) << seed << ": " << CertificateLine(bad);
    const OptimalityCertificate good = CertifyOptimality(from_chordal);
    EXPECT_TRUE(good.certified) << seed << ": " << CertificateLine(good);
    if (seed == 3) {
      EXPECT_FALSE(bad.relaxation_tight);
      EXPECT_LT(bad.lambda_min, -1.0);
      EXPECT_GT(bad.cost, 2.0 * good.cost);
    } else {
      EXPECT_TRUE(bad.relaxation_tight);
      EXPECT_NEAR(bad.cost, good.cost, 1e-6 * good.cost);
      EXPECT_NEAR(bad.chi2_from_certified, chordal_chi2, 1e-6 * chordal_chi2);
    }
  }
}

}  // namespace
}  // namespace slamrig::slam
