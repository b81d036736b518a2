#pragma once

#include <string>
#include <vector>

#include "slam/fusion/landmark_extraction.h"
#include "slam/fusion/pose_ekf_options.h"

namespace slamrig::slam {

/// How observations are paired with mapped landmarks.
enum class LandmarkAssociationMethod {
  kNearestNeighbour,    ///< each observation alone, to its nearest gated landmark
  kJointCompatibility,  ///< JCBB: the largest jointly compatible set (Neira and Tardos 2001)
};

/// Options of EkfSlam: the motion model's noise (PoseEkf's), landmark extraction, association and
/// the rules that admit a landmark into the state.
struct EkfSlamOptions {
  PoseEkfOptions motion;  ///< its keys sit at this level
  LandmarkExtractionOptions extraction;
  LandmarkAssociationMethod association = LandmarkAssociationMethod::kJointCompatibility;
  /// Chi-square probability of the individual and joint compatibility gates.
  double gate_probability = 0.99;
  /// An unpaired observation closer than this chi-square probability (2 dof) to a mapped landmark
  /// is ambiguous and neither updates nor starts one.
  double new_landmark_gate_probability = 0.9999;
  /// A landmark enters the state once it was seen in this many scans at about one place, with
  /// gaps shorter than tentative_max_age_scans (a tentative landmark until then): a pillar in view
  /// is found in nearly every scan, clutter that looks round from some viewpoints (a square
  /// column's corner, a car's) only now and then, and never reaches the state. Its sightings'
  /// fitted radii must also agree within their fits' own variances (chi-square at
  /// gate_probability): a pillar keeps its radius from every viewpoint, a corner that looks round
  /// from a few does not.
  int min_sightings = 10;
  /// Sightings of a tentative landmark lie within this distance of its first, m.
  double tentative_radius_m = 0.3;
  /// A tentative landmark not seen for this many scans is forgotten.
  int tentative_max_age_scans = 3;
  /// Landmarks predicted further away than this are not candidates for association, m; 0: the
  /// scan's range_max.
  double max_range_m = 0.0;

  /// One message per broken rule, named by the YAML keys ("min_sightings = 0; must be >= 1").
  std::vector<std::string> Validate() const;
};

/// The field table of EkfSlamOptions (slam/config/fields.h).
template <typename V>
void VisitFields(V& v, EkfSlamOptions& o) {
  VisitFields(v, o.motion);
  v.Struct("extraction", o.extraction);
  v.Enum("association", o.association,
         {{LandmarkAssociationMethod::kNearestNeighbour, "nn"},
          {LandmarkAssociationMethod::kJointCompatibility, "jcbb"}});
  v("gate_probability", o.gate_probability);
  v("new_landmark_gate_probability", o.new_landmark_gate_probability);
  v("min_sightings", o.min_sightings);
  v("tentative_radius_m", o.tentative_radius_m);
  v("tentative_max_age_scans", o.tentative_max_age_scans);
  v("max_range_m", o.max_range_m);
}

}  // namespace slamrig::slam
