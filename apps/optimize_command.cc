// `slamrig optimize GRAPH.g2o [--init ...] [--robust ...] [--out OUT.g2o]`: pose-graph
// optimisation of a g2o file with Ceres, from the odometry chain, a chordal initialisation or
// the file's own vertex estimates.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <utility>

#include "apps/cli_args.h"
#include "apps/commands.h"
#include "slam/graph/g2o_io.h"
#include "slam/graph/graph_initialization.h"
#include "slam/graph/optimality_certificate.h"
#include "slam/graph/pose_graph_optimizer.h"
#include "slam/io/log_reader.h"
#include "slam/types/error.h"
#include "slam/types/format.h"

namespace slamrig::app {
namespace {

using slam::PoseGraphOptimizerOptions;

// Reads the flag values that name an enumerator; anything else is a ConfigError.
PoseGraphOptimizerOptions ParseChoices(const std::string& robust, const std::string& strategy,
                                       PoseGraphOptimizerOptions options) {
  if (robust == "none") {
    options.robust_loss = slam::RobustLoss::kNone;
  } else if (robust == "huber") {
    options.robust_loss = slam::RobustLoss::kHuber;
  } else if (robust == "cauchy") {
    options.robust_loss = slam::RobustLoss::kCauchy;
  } else if (robust == "switchable") {
    options.robust_loss = slam::RobustLoss::kSwitchable;
  } else {
    throw ConfigError(
        "slamrig optimize: --robust: expected none, huber, cauchy or switchable, got '" + robust +
        "'");
  }
  if (strategy == "lm") {
    options.trust_region = slam::TrustRegion::kLevenbergMarquardt;
  } else if (strategy == "dogleg") {
    options.trust_region = slam::TrustRegion::kDogleg;
  } else {
    throw ConfigError("slamrig optimize: --trust-region: expected lm or dogleg, got '" + strategy +
                      "'");
  }
  for (const std::string& e : options.Validate()) throw ConfigError("slamrig optimize: " + e);
  return options;
}

// Initialises `graph` by `init` (odometry, chordal or file) and optimises it.
slam::PoseGraphSummary InitializeAndOptimize(const std::string& init,
                                             const PoseGraphOptimizerOptions& options,
                                             slam::PoseGraph* graph) {
  if (init == "odometry") slam::InitializeFromOdometry(graph);
  if (init == "chordal") slam::InitializeChordal(graph);
  return slam::PoseGraphOptimizer(options).Optimize(graph);
}

// --init best: optimises from both the odometry chain and the chordal initialisation and keeps
// the lower final chi2: chordal unless odometry's is lower by more than 1e-6 of it (below that
// the two are one minimum, apart by the solver's stopping tolerances). `used` names the one
// kept; the summary's time is both solves'.
slam::PoseGraphSummary OptimizeFromBest(const PoseGraphOptimizerOptions& options,
                                        slam::PoseGraph* graph, std::string* used) {
  slam::PoseGraph from_odometry = *graph;
  slam::PoseGraphSummary odometry = InitializeAndOptimize("odometry", options, &from_odometry);
  slam::PoseGraphSummary chordal = InitializeAndOptimize("chordal", options, graph);
  const double total_s = odometry.time_s + chordal.time_s;
  if (odometry.final_chi2 < chordal.final_chi2 - 1e-6 * chordal.final_chi2) {
    *graph = std::move(from_odometry);
    odometry.time_s = total_s;
    *used = "best (odometry, chordal reached chi2 " + Number("%.6g", chordal.final_chi2) + ")";
    return odometry;
  }
  chordal.time_s = total_s;
  *used = "best (chordal, odometry reached chi2 " + Number("%.6g", odometry.final_chi2) + ")";
  return chordal;
}

}  // namespace

int RunOptimizeCommand(const std::vector<std::string>& args) {
  std::string graph_path, out_path, init = "chordal", robust = "none", strategy = "lm";
  bool no_certificate = false;
  PoseGraphOptimizerOptions options;
  ArgParser parser("slamrig optimize", "GRAPH.g2o [options]",
                   "Optimises a 2D pose graph (g2o VERTEX_SE2/EDGE_SE2/FIX, plain or .gz) with\n"
                   "Ceres and prints one line: vertices, edges, initial and final chi2 (g2o's,\n"
                   "sum of e^T Omega e), iterations and time. The first vertex, or the FIX ones,\n"
                   "stay where they are. A second line checks global optimality: the SE-Sync\n"
                   "certificate of the graph's isotropic problem (docs/cli.md), 'certified\n"
                   "optimal' or 'not certified', with the certificate matrix's lambda_min.");
  parser.AddPositional("GRAPH", "g2o file; a path, or relative to SLAMRIG_DATA_DIR", &graph_path);
  parser.AddOption("init", "METHOD",
                   "chordal (Carlone et al. 2015; the default), odometry (compose the "
                   "consecutive-id edges), best (both, keeping the lower final chi2) or file "
                   "(the file's vertex estimates)",
                   &init);
  parser.AddFlag("no-certificate", "skip the optimality certificate", &no_certificate);
  parser.AddOption("robust", "LOSS", "none, huber, cauchy or switchable, on loop-closure edges",
                   &robust);
  parser.AddOption("robust-scale", "S", "robust loss scale, in whitened error units",
                   &options.robust_loss_scale);
  parser.AddFlag("robust-all", "apply the robust loss to every edge, odometry too",
                 &options.robust_loss_on_all_edges);
  parser.AddOption("trust-region", "NAME", "lm (Levenberg-Marquardt) or dogleg", &strategy);
  parser.AddOption("max-iterations", "N", "Ceres iteration limit", &options.max_iterations);
  parser.AddOption("threads", "N", "Ceres threads (1 gives the same bits every run)",
                   &options.num_threads);
  parser.AddOption("out", "OUT.g2o", "write the optimised graph here (atomically)", &out_path);
  if (!parser.Parse(args)) return 0;
  if (init != "odometry" && init != "chordal" && init != "best" && init != "file") {
    throw ConfigError("slamrig optimize: --init: expected chordal, odometry, best or file, got '" +
                      init + "'");
  }
  options = ParseChoices(robust, strategy, options);

  slam::PoseGraph graph = slam::ReadG2o(slam::ResolveLogPath(graph_path));
  const auto start = std::chrono::steady_clock::now();
  std::string used = init;
  const slam::PoseGraphSummary s = init == "best" ? OptimizeFromBest(options, &graph, &used)
                                                  : InitializeAndOptimize(init, options, &graph);
  const double total_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!out_path.empty()) slam::WriteG2o(out_path, graph);

  std::string line = std::filesystem::path(graph_path).filename().string() + ": " +
                     std::to_string(s.num_vertices) + " vertices, " + std::to_string(s.num_edges) +
                     " edges; init " + used + "; chi2 " + Number("%.6g", s.initial_chi2) + " -> " +
                     Number("%.6g", s.final_chi2) + " in " + std::to_string(s.iterations) +
                     " iterations, solve " + Number("%.3f", s.time_s) + " s, init and solve " +
                     Number("%.3f", total_s) + " s" +
                     (s.converged ? "" : " (not converged: " + s.message + ")");
  if (!out_path.empty()) line += " -> " + out_path;
  std::puts(line.c_str());
  const auto fixed = std::count_if(graph.vertices().begin(), graph.vertices().end(),
                                   [](const slam::PoseGraphVertex& v) { return v.fixed; });
  if (!no_certificate && fixed > 1) {
    std::puts(("not certified: the graph has " + std::to_string(fixed) +
               " fixed vertices; the certificate is for a graph anchored at one pose")
                  .c_str());
  } else if (!no_certificate && !graph.edges().empty()) {
    // With a robust loss: the weighted least-squares problem the robust solution is stationary
    // for, the weights carrying the loss.
    slam::OptimalityCertificateOptions certificate_options;
    certificate_options.optimizer = options;
    certificate_options.optimizer.robust_loss = slam::RobustLoss::kNone;
    const slam::OptimalityCertificate c = slam::CertifyOptimality(
        slam::WithRobustWeights(graph, options, s.switches), certificate_options);
    const std::string cert =
        slam::CertificateLine(c) + "; check " + Number("%.3f", c.time_s) + " s";
    std::puts(cert.c_str());
  }
  return 0;
}

}  // namespace slamrig::app
