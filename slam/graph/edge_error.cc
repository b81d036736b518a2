#include "slam/graph/edge_error.h"

#include <cmath>

namespace slamrig::slam {

EdgeErrorResult EvaluateEdgeError(const Eigen::Vector3d& xi, const Eigen::Vector3d& xj,
                                  const Pose2& z) {
  // With R(a) the rotation by a:  e_t = R(tz)^T (R(ti)^T (tj - ti) - t_z),
  //                               e_theta = wrap(theta_j - theta_i - theta_z).
  const double ci = std::cos(xi.z()), si = std::sin(xi.z());
  const double cz = std::cos(z.theta()), sz = std::sin(z.theta());
  const double dx = xj.x() - xi.x(), dy = xj.y() - xi.y();
  // Xi^-1 * Xj translation, then minus Z's translation.
  const double ux = ci * dx + si * dy - z.x();
  const double uy = -si * dx + ci * dy - z.y();
  EdgeErrorResult r;
  r.error << cz * ux + sz * uy, -sz * ux + cz * uy, NormalizeAngle(xj.z() - xi.z() - z.theta());

  // M = R(tz)^T R(ti)^T = R(theta_i + theta_z)^T.
  const double cm = std::cos(xi.z() + z.theta()), sm = std::sin(xi.z() + z.theta());
  Eigen::Matrix2d m;
  m << cm, sm, -sm, cm;
  // d/d theta_i of R(ti)^T (tj - ti) is (-si dx + ci dy, -ci dx - si dy); then rotate by R(tz)^T.
  const double px = -si * dx + ci * dy, py = -ci * dx - si * dy;
  r.d_error_d_xi.setZero();
  r.d_error_d_xi.topLeftCorner<2, 2>() = -m;
  r.d_error_d_xi(0, 2) = cz * px + sz * py;
  r.d_error_d_xi(1, 2) = -sz * px + cz * py;
  r.d_error_d_xi(2, 2) = -1.0;
  r.d_error_d_xj.setZero();
  r.d_error_d_xj.topLeftCorner<2, 2>() = m;
  r.d_error_d_xj(2, 2) = 1.0;
  return r;
}

Eigen::Vector3d EdgeError(const PoseGraph& graph, const PoseGraphEdge& edge) {
  const Pose2& a = graph.pose(edge.from);
  const Pose2& b = graph.pose(edge.to);
  return EvaluateEdgeError({a.x(), a.y(), a.theta()}, {b.x(), b.y(), b.theta()}, edge.measurement)
      .error;
}

double EdgeChi2(const PoseGraph& graph, const PoseGraphEdge& edge) {
  const Eigen::Vector3d e = EdgeError(graph, edge);
  return e.dot(edge.information * e);
}

double Chi2(const PoseGraph& graph) {
  double chi2 = 0.0;
  for (const PoseGraphEdge& edge : graph.edges()) chi2 += EdgeChi2(graph, edge);
  return chi2;
}

}  // namespace slamrig::slam
