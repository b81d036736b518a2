#include "slam/eval/landmark_score.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <map>

namespace slamrig::slam {
namespace {

// The index of the point of `set` nearest `p`, -1 for an empty set.
int Nearest(const std::vector<Eigen::Vector2d>& set, const Eigen::Vector2d& p) {
  int best = -1;
  for (int i = 0; i < static_cast<int>(set.size()); ++i)
    if (best < 0 || (set[i] - p).norm() < (set[best] - p).norm()) best = i;
  return best;
}

// The pillars paired with landmarks, their errors and NEES.
void ScorePairs(const std::vector<Eigen::Vector2d>& pillars,
                const std::vector<ScoredLandmark>& landmarks, double radius, LandmarkScore* s) {
  std::vector<Eigen::Vector2d> estimated;
  for (const ScoredLandmark& l : landmarks) estimated.push_back(l.position_m);
  std::vector<bool> matched(estimated.size(), false);
  double error_sum = 0.0, error_max = 0.0, nees_sum = 0.0;
  for (int i = 0; i < static_cast<int>(pillars.size()); ++i) {
    const int j = Nearest(estimated, pillars[i]);
    if (j < 0 || Nearest(pillars, estimated[j]) != i) continue;
    const Eigen::Vector2d e = pillars[i] - estimated[j];
    if (e.norm() > radius) continue;
    ++s->mapped;
    matched[j] = true;
    error_sum += e.norm();
    error_max = std::max(error_max, e.norm());
    nees_sum += e.dot(landmarks[j].covariance.ldlt().solve(e));
  }
  s->pillars = static_cast<int>(pillars.size());
  s->spurious = static_cast<int>(std::count(matched.begin(), matched.end(), false));
  s->error_max_m = s->mapped > 0 ? error_max : NAN;
  s->error_mean_m = s->mapped > 0 ? error_sum / s->mapped : NAN;
  s->anees = s->mapped > 0 ? nees_sum / s->mapped : NAN;
  if (s->mapped > 0) s->anees_bounds = AneesBounds(2, s->mapped);
}

// The sightings whose pillar is not their landmark's.
int WrongAssociations(const std::vector<Eigen::Vector2d>& pillars,
                      const std::vector<ScoredLandmark>& landmarks,
                      const std::vector<ScoredSighting>& sightings, const Trajectory& truth,
                      double radius) {
  // The true pillar of every sighting, then each landmark's by majority.
  std::vector<int> pillar_of_sighting;
  std::vector<std::optional<Eigen::Vector2d>> true_point;
  std::vector<std::map<int, int>> votes(landmarks.size());
  for (const ScoredSighting& s : sightings) {
    const std::optional<Pose2> pose = truth.Interpolate(s.time);
    int pillar = -1;
    true_point.emplace_back();
    if (pose) {
      const Eigen::Vector2d p = *pose * s.center_base_m;
      true_point.back() = p;
      pillar = Nearest(pillars, p);
      if (pillar >= 0 && (pillars[pillar] - p).norm() > radius) pillar = -1;
    }
    pillar_of_sighting.push_back(pillar);
    if (s.landmark >= 0 && s.landmark < static_cast<int>(votes.size())) ++votes[s.landmark][pillar];
  }
  std::vector<int> pillar_of_landmark(votes.size(), -1);
  for (std::size_t j = 0; j < votes.size(); ++j) {
    int most = 0;
    for (const auto& [pillar, count] : votes[j]) {
      if (count > most) {
        most = count;
        pillar_of_landmark[j] = pillar;
      }
    }
  }
  int wrong = 0;
  for (std::size_t k = 0; k < sightings.size(); ++k) {
    const int j = sightings[k].landmark;
    if (j < 0 || j >= static_cast<int>(votes.size())) continue;
    if (pillar_of_landmark[j] >= 0 || pillar_of_sighting[k] >= 0) {
      wrong += pillar_of_sighting[k] != pillar_of_landmark[j];
    } else {
      wrong += !true_point[k] || (*true_point[k] - landmarks[j].position_m).norm() > radius;
    }
  }
  return wrong;
}

}  // namespace

LandmarkScore ScoreLandmarks(const std::vector<Eigen::Vector2d>& pillars,
                             const std::vector<ScoredLandmark>& landmarks,
                             const std::vector<ScoredSighting>& sightings, const Trajectory& truth,
                             double match_radius_m) {
  LandmarkScore score;
  ScorePairs(pillars, landmarks, match_radius_m, &score);
  score.sightings = static_cast<int>(sightings.size());
  score.wrong_associations =
      WrongAssociations(pillars, landmarks, sightings, truth, match_radius_m);
  return score;
}

}  // namespace slamrig::slam
