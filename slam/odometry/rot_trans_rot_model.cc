// Odometry motion model: Thrun, Burgard, Fox, "Probabilistic Robotics" (2005), Sec. 5.4,
// Table 5.5 (decomposition) and Table 5.6 (sample_motion_model_odometry), variance form.
#include "slam/odometry/rot_trans_rot_model.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "slam/types/validation.h"

namespace slamrig::slam {
namespace {

// Below this translation the heading of travel is noise: all rotation goes into rot2.
constexpr double kMinTranslationForHeading = 1e-6;

}  // namespace

RotTransRot RotTransRot::FromIncrement(const Pose2& before_from_after) {
  RotTransRot m;
  const double dx = before_from_after.x();
  const double dy = before_from_after.y();
  m.trans_m = std::hypot(dx, dy);
  if (m.trans_m > kMinTranslationForHeading) {
    m.rot1_rad = std::atan2(dy, dx);
    // Driving backwards: travel along -x with a small first rotation.
    if (std::abs(m.rot1_rad) > 0.5 * std::numbers::pi) {
      m.rot1_rad = NormalizeAngle(m.rot1_rad + std::numbers::pi);
      m.trans_m = -m.trans_m;
    }
  }
  m.rot2_rad = NormalizeAngle(before_from_after.theta() - m.rot1_rad);
  return m;
}

Pose2 RotTransRot::ToIncrement() const {
  return Pose2(trans_m * std::cos(rot1_rad), trans_m * std::sin(rot1_rad), rot1_rad + rot2_rad);
}

std::vector<std::string> RotTransRotNoise::Validate() const {
  Rules rules;
  rules.NonNegative("alpha1", alpha1)
      .NonNegative("alpha2", alpha2)
      .NonNegative("alpha3", alpha3)
      .NonNegative("alpha4", alpha4)
      .NonNegative("min_trans_sigma_m", min_trans_sigma_m)
      .NonNegative("min_rot_sigma_rad", min_rot_sigma_rad);
  return rules.errors();
}

Pose2 SampleRotTransRot(const Pose2& before_from_after, const RotTransRotNoise& noise,
                        RandomEngine& rng) {
  const RotTransRot m = RotTransRot::FromIncrement(before_from_after);
  const double r1 = m.rot1_rad * m.rot1_rad;
  const double r2 = m.rot2_rad * m.rot2_rad;
  const double t = m.trans_m * m.trans_m;
  const double sigma_rot1 =
      std::max(std::sqrt(noise.alpha1 * r1 + noise.alpha2 * t), noise.min_rot_sigma_rad);
  const double sigma_trans =
      std::max(std::sqrt(noise.alpha3 * t + noise.alpha4 * (r1 + r2)), noise.min_trans_sigma_m);
  const double sigma_rot2 =
      std::max(std::sqrt(noise.alpha1 * r2 + noise.alpha2 * t), noise.min_rot_sigma_rad);
  // Fixed draw order (rot1, trans, rot2) keeps streams reproducible.
  RotTransRot noisy;
  noisy.rot1_rad = m.rot1_rad + sigma_rot1 * StandardNormal(rng);
  noisy.trans_m = m.trans_m + sigma_trans * StandardNormal(rng);
  noisy.rot2_rad = m.rot2_rad + sigma_rot2 * StandardNormal(rng);
  return noisy.ToIncrement();
}

}  // namespace slamrig::slam
