// `slamrig eval --estimate A.tum --truth B.tum [--out DIR]`: trajectory scores of any estimate
// against any reference, and the Kümmerle et al. 2009 relations metric.

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "apps/cli_args.h"
#include "apps/commands.h"
#include "slam/eval/json_writer.h"
#include "slam/eval/relations.h"
#include "slam/eval/trajectory_metrics.h"
#include "slam/io/atomic_file.h"
#include "slam/io/tum_io.h"
#include "slam/types/error.h"
#include "slam/types/format.h"

namespace slamrig::app {
namespace {

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ParseError(path + ": no such file");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<double> ParseDistances(const std::string& text) {
  std::vector<double> out;
  std::stringstream s(text);
  std::string item;
  while (std::getline(s, item, ',')) {
    char* end = nullptr;
    const double d = std::strtod(item.c_str(), &end);
    if (item.empty() || end != item.c_str() + item.size() || !(d > 0.0)) {
      throw ConfigError("slamrig eval: --relation-distances: '" + item +
                        "' is not a positive number");
    }
    out.push_back(d);
  }
  return out;
}

void WriteRelations(slam::JsonWriter& json, const slam::RelationsResult& r) {
  json.BeginObject("relations").Integer("used", r.used).Integer("skipped", r.skipped);
  slam::WriteErrorStats(json, "translation_m", r.translation_m);
  slam::WriteErrorStats(json, "translation_sq_m2", r.translation_sq_m2);
  slam::WriteErrorStats(json, "rotation_rad", r.rotation_rad);
  slam::WriteErrorStats(json, "rotation_sq_rad2", r.rotation_sq_rad2);
  json.EndObject();
}

}  // namespace

int RunEvalCommand(const std::vector<std::string>& args) {
  std::string estimate_path, truth_path, out_dir, relations_path, make_relations,
      distances = "1,10";
  int random_pairs = 0;
  double max_gap_s = 1.0;
  ArgParser parser(
      "slamrig eval", "--estimate A.tum --truth B.tum [options]",
      "Scores a trajectory against a reference: ATE after SE(2) alignment (RMSE, mean,\n"
      "median, max), RPE per pose pair, over 1 m and over 10 m, and optionally the\n"
      "relations metric of Kuemmerle et al. 2009. Writes DIR/metrics.json with --out.\n"
      "--make-relations writes a relations file generated from the truth.");
  parser.AddOption("estimate", "FILE", "estimated trajectory (TUM)", &estimate_path);
  parser.AddOption("truth", "FILE", "reference trajectory (TUM)", &truth_path);
  parser.AddOption("out", "DIR", "write DIR/metrics.json (created)", &out_dir);
  parser.AddOption("relations", "FILE", "relations file (t1 t2 x y z roll pitch yaw) to evaluate",
                   &relations_path);
  parser.AddOption("make-relations", "FILE", "generate relations from --truth into FILE",
                   &make_relations);
  parser.AddOption("relation-distances", "LIST", "path distances of generated relations, metres",
                   &distances);
  parser.AddOption("random-pairs", "N", "random pose pairs added to generated relations",
                   &random_pairs);
  parser.AddOption("max-gap", "S", "interpolate the truth only across gaps up to S seconds",
                   &max_gap_s);
  if (!parser.Parse(args)) return 0;
  if (truth_path.empty()) throw ConfigError("slamrig eval: --truth FILE is required");
  if (estimate_path.empty() && make_relations.empty()) {
    throw ConfigError("slamrig eval: --estimate FILE is required (or --make-relations FILE)");
  }
  slam::RelationGeneratorOptions generator;
  generator.path_distances_m = ParseDistances(distances);
  generator.num_random_pairs = random_pairs;
  for (const std::string& e : generator.Validate()) throw ConfigError("slamrig eval: " + e);
  if (!(max_gap_s > 0.0))
    throw ConfigError("slamrig eval: --max-gap = " + Fixed(max_gap_s, 3) + "; must be > 0");

  const Trajectory truth = slam::ReadTum(truth_path);
  if (!make_relations.empty()) {
    const std::vector<slam::Relation> generated = slam::GenerateRelations(truth, generator);
    slam::WriteFileAtomically(make_relations, slam::FormatRelations(generated));
    std::printf("%zu relations from %s -> %s\n", generated.size(), truth_path.c_str(),
                make_relations.c_str());
    if (estimate_path.empty()) return 0;
  }
  const Trajectory estimate = slam::ReadTum(estimate_path);
  slam::AssociationOptions association;
  association.max_interpolation_gap_s = max_gap_s;
  const slam::TrajectoryMetrics metrics = slam::EvaluateTrajectory(estimate, truth, association);
  if (metrics.matched_poses == 0) {
    throw ParseError(estimate_path + ": no pose falls inside " + truth_path + "'s time span");
  }
  std::optional<slam::RelationsResult> relations;
  if (!relations_path.empty()) {
    relations = slam::EvaluateRelations(
        estimate, slam::ParseRelations(ReadText(relations_path), relations_path));
  }

  slam::JsonWriter json;
  json.String("estimate", estimate_path).String("truth", truth_path);
  slam::WriteTrajectoryMetrics(json, metrics);
  if (relations) WriteRelations(json, *relations);
  const std::string document = json.Finish();
  if (!out_dir.empty()) {
    std::filesystem::create_directories(out_dir);
    slam::WriteFileAtomically(out_dir + "/metrics.json", document);
  }
  std::string line = "ATE RMSE " + Fixed(metrics.ate.translation_m.rmse, 3) + " m (mean " +
                     Fixed(metrics.ate.translation_m.mean, 3) + ", median " +
                     Fixed(metrics.ate.translation_m.median, 3) + ", max " +
                     Fixed(metrics.ate.translation_m.max, 3) + ") over " +
                     std::to_string(metrics.matched_poses) + " poses; RPE per pose " +
                     Fixed(metrics.rpe_per_scan.translation_m.mean, 3) + " m, over 1 m " +
                     Fixed(metrics.rpe_1m.translation_m.mean, 3) + " m, over 10 m " +
                     Fixed(metrics.rpe_10m.translation_m.mean, 3) + " m";
  if (relations) {
    line += "; relations: " + std::to_string(relations->used) + " used, translation " +
            Fixed(relations->translation_m.mean, 3) + " +- " +
            Fixed(relations->translation_m.std_dev, 3) + " m";
  }
  std::puts(line.c_str());
  if (out_dir.empty()) std::fputs(document.c_str(), stdout);
  return 0;
}

}  // namespace slamrig::app
