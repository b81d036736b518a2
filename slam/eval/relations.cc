// The relations-based SLAM metric: Kümmerle, Steder, Dornhege, Ruhnke, Grisetti, Stachniss,
// Kleiner, "On measuring the accuracy of SLAM algorithms", Autonomous Robots 27(4), 2009,
// Sec. 3 (Eq. 1: epsilon(delta) = sum trans(delta_ij ominus delta*_ij)^2 + rot(...)^2; Eq. 2).
#include "slam/eval/relations.h"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "slam/odometry/gaussian.h"
#include "slam/types/error.h"
#include "slam/types/validation.h"

namespace slamrig::slam {

std::vector<std::string> RelationGeneratorOptions::Validate() const {
  Rules rules;
  rules.NonNegative("consecutive_step", consecutive_step);
  for (const double d : path_distances_m) rules.Positive("path_distances_m", d);
  rules.NonNegative("num_random_pairs", num_random_pairs);
  return PrefixErrors("relations", rules.errors());
}

std::vector<Relation> GenerateRelations(const Trajectory& reference,
                                        const RelationGeneratorOptions& options) {
  std::vector<Relation> relations;
  const std::vector<StampedPose>& p = reference.poses();
  const std::size_t n = p.size();
  auto add = [&](std::size_t i, std::size_t j) {
    if (j >= n || p[i].time == p[j].time) return;
    relations.push_back({p[i].time, p[j].time, p[i].pose.Between(p[j].pose)});
  };
  if (options.consecutive_step > 0) {
    for (std::size_t i = 0; i < n; ++i)
      add(i, i + static_cast<std::size_t>(options.consecutive_step));
  }
  std::vector<double> along(n, 0.0);
  for (std::size_t i = 1; i < n; ++i) {
    along[i] = along[i - 1] + (p[i].pose.translation() - p[i - 1].pose.translation()).norm();
  }
  for (const double d : options.path_distances_m) {
    std::size_t j = 0;
    for (std::size_t i = 0; i < n; ++i) {
      j = std::max(j, i + 1);
      while (j < n && along[j] - along[i] < d) ++j;
      if (j >= n) break;
      add(i, j);
    }
  }
  RandomEngine rng(options.seed);
  for (int k = 0; k < options.num_random_pairs && n >= 2; ++k) {
    const auto i = static_cast<std::size_t>(Uniform01(rng) * static_cast<double>(n));
    const auto j = static_cast<std::size_t>(Uniform01(rng) * static_cast<double>(n));
    if (i != j) add(std::min(i, j), std::max(i, j));
  }
  return relations;
}

std::string FormatRelations(const std::vector<Relation>& relations) {
  std::string out;
  char line[256];
  for (const Relation& r : relations) {
    std::snprintf(line, sizeof(line), "%.9f %.9f %.9f %.9f 0 0 0 %.9f\n", r.t1.seconds(),
                  r.t2.seconds(), r.relative.x(), r.relative.y(), r.relative.theta());
    out += line;
  }
  return out;
}

std::vector<Relation> ParseRelations(const std::string& text, const std::string& source_name) {
  std::vector<Relation> relations;
  std::istringstream in(text);
  std::string line;
  int line_number = 0;
  static const char* kFields[] = {"t1", "t2", "x", "y", "z", "roll", "pitch", "yaw"};
  while (std::getline(in, line)) {
    ++line_number;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream fields(line);
    double v[8];
    for (int f = 0; f < 8; ++f) {
      if (!(fields >> v[f]) || !std::isfinite(v[f])) {
        throw ParseError(source_name + ":" + std::to_string(line_number) + ": " + kFields[f] +
                         ": expected a number (`t1 t2 x y z roll pitch yaw`)");
      }
    }
    std::string extra;
    if (fields >> extra) {
      throw ParseError(source_name + ":" + std::to_string(line_number) + ": unexpected field '" +
                       extra + "' after yaw");
    }
    relations.push_back(
        {Time::FromSeconds(v[0]), Time::FromSeconds(v[1]), Pose2(v[2], v[3], v[7])});
  }
  return relations;
}

RelationsResult EvaluateRelations(const Trajectory& estimate,
                                  const std::vector<Relation>& relations) {
  RelationsResult result;
  std::vector<double> trans, trans_sq, rot, rot_sq;
  for (const Relation& r : relations) {
    const std::optional<Pose2> a = estimate.Interpolate(r.t1);
    const std::optional<Pose2> b = estimate.Interpolate(r.t2);
    if (!a || !b) {
      ++result.skipped;
      continue;
    }
    const Pose2 error = r.relative.Between(a->Between(*b));
    const double t = error.translation().norm();
    const double th = std::abs(error.theta());
    trans.push_back(t);
    trans_sq.push_back(t * t);
    rot.push_back(th);
    rot_sq.push_back(th * th);
  }
  result.used = static_cast<int>(trans.size());
  result.translation_m = ErrorStats::Of(std::move(trans));
  result.translation_sq_m2 = ErrorStats::Of(std::move(trans_sq));
  result.rotation_rad = ErrorStats::Of(std::move(rot));
  result.rotation_sq_rad2 = ErrorStats::Of(std::move(rot_sq));
  return result;
}

}  // namespace slamrig::slam
