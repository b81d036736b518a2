// `slamrig optimize GRAPH.g2o [--init ...] [--robust ...] [--out OUT.g2o]`: pose-graph
// optimisation of a g2o file with Ceres, from the odometry chain, a chordal initialisation or
// the file's own vertex estimates.

#include <chrono>
#include <cstdio>
#include <filesystem>

#include "apps/cli_args.h"
#include "apps/commands.h"
#include "slam/graph/g2o_io.h"
#include "slam/graph/graph_initialization.h"
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

}  // namespace

int RunOptimizeCommand(const std::vector<std::string>& args) {
  std::string graph_path, out_path, init = "odometry", robust = "none", strategy = "lm";
  PoseGraphOptimizerOptions options;
  ArgParser parser("slamrig optimize", "GRAPH.g2o [options]",
                   "Optimises a 2D pose graph (g2o VERTEX_SE2/EDGE_SE2/FIX, plain or .gz) with\n"
                   "Ceres and prints one line: vertices, edges, initial and final chi2 (g2o's,\n"
                   "sum of e^T Omega e), iterations and time. The first vertex, or the FIX ones,\n"
                   "stay where they are.");
  parser.AddPositional("GRAPH", "g2o file; a path, or relative to SLAMRIG_DATA_DIR", &graph_path);
  parser.AddOption("init", "METHOD",
                   "odometry (compose the consecutive-id edges), chordal (Carlone et al. 2015) or "
                   "file (the file's vertex estimates)",
                   &init);
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
  if (init != "odometry" && init != "chordal" && init != "file") {
    throw ConfigError("slamrig optimize: --init: expected odometry, chordal or file, got '" + init +
                      "'");
  }
  options = ParseChoices(robust, strategy, options);

  slam::PoseGraph graph = slam::ReadG2o(slam::ResolveLogPath(graph_path));
  const auto start = std::chrono::steady_clock::now();
  if (init == "odometry") slam::InitializeFromOdometry(&graph);
  if (init == "chordal") slam::InitializeChordal(&graph);
  const double init_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const slam::PoseGraphSummary s = slam::PoseGraphOptimizer(options).Optimize(&graph);
  if (!out_path.empty()) slam::WriteG2o(out_path, graph);

  std::string line = std::filesystem::path(graph_path).filename().string() + ": " +
                     std::to_string(s.num_vertices) + " vertices, " + std::to_string(s.num_edges) +
                     " edges; init " + init + " " + Number("%.3f", init_s) + " s; chi2 " +
                     Number("%.6g", s.initial_chi2) + " -> " + Number("%.6g", s.final_chi2) +
                     " in " + std::to_string(s.iterations) + " iterations, " +
                     Number("%.3f", s.time_s) + " s" +
                     (s.converged ? "" : " (not converged: " + s.message + ")");
  if (!out_path.empty()) line += " -> " + out_path;
  std::puts(line.c_str());
  return 0;
}

}  // namespace slamrig::app
