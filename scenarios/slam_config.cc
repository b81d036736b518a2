#include "scenarios/slam_config.h"

#include <sstream>

namespace slamrig::scenario {
namespace {

// Reads an enum from its name; any other text is a ConfigError listing the choices.
template <typename Enum>
void ReadEnum(const YamlNode& node, const std::string& key,
              const std::vector<std::pair<std::string, Enum>>& choices, Enum* value) {
  const auto child = node.Optional(key);
  if (!child) return;
  const std::string text = child->As<std::string>();
  std::string names;
  for (const auto& [name, e] : choices) {
    if (name == text) {
      *value = e;
      return;
    }
    names += (names.empty() ? "" : ", ") + name;
  }
  child->Fail("expected one of " + names + ", got '" + text + "'");
}

template <typename Enum>
std::string EnumName(const std::vector<std::pair<std::string, Enum>>& choices, Enum value) {
  for (const auto& [name, e] : choices) {
    if (e == value) return name;
  }
  return "?";
}

const std::vector<std::pair<std::string, slam::MotionNoiseModel>> kMotionNoise = {
    {"gaussian", slam::MotionNoiseModel::kGaussianPerStep},
    {"rot_trans_rot", slam::MotionNoiseModel::kRotTransRot}};
const std::vector<std::pair<std::string, slam::ObservationModel>> kObservation = {
    {"correlation", slam::ObservationModel::kMapCorrelation},
    {"likelihood_field", slam::ObservationModel::kLikelihoodField}};
const std::vector<std::pair<std::string, slam::ResamplingScheme>> kResampling = {
    {"systematic", slam::ResamplingScheme::kSystematic},
    {"stratified", slam::ResamplingScheme::kStratified}};
const std::vector<std::pair<std::string, slam::CorrelationValue>> kCorrelationValue = {
    {"occupied", slam::CorrelationValue::kOccupiedIndicator},
    {"log_odds", slam::CorrelationValue::kRawValue}};
const std::vector<std::pair<std::string, slam::OdometrySource>> kOdometrySource = {
    {"auto", slam::OdometrySource::kAuto},
    {"wheel_ticks", slam::OdometrySource::kWheelTicks},
    {"poses", slam::OdometrySource::kOdometryPoses},
    {"none", slam::OdometrySource::kNone}};
const std::vector<std::pair<std::string, slam::DiffDriveIntegration>> kIntegration = {
    {"exact_arc", slam::DiffDriveIntegration::kExactArc},
    {"euler", slam::DiffDriveIntegration::kEuler}};
const std::vector<std::pair<std::string, SlamAlgorithm>> kAlgorithm = {
    {"pf", SlamAlgorithm::kParticleFilter}, {"dead-reckoning", SlamAlgorithm::kDeadReckoning}};

}  // namespace

void ParseGridOptions(const YamlNode& node, slam::OccupancyGridOptions* o) {
  node.Read("resolution_m", &o->resolution_m);
  node.Read("hit_log_odds", &o->hit_log_odds);
  node.Read("miss_log_odds", &o->miss_log_odds);
  node.Read("min_log_odds", &o->min_log_odds);
  node.Read("max_log_odds", &o->max_log_odds);
  node.Read("max_range_m", &o->max_range_m);
  node.Read("no_return_clear_range_m", &o->no_return_clear_range_m);
  node.Read("update_once_per_scan", &o->update_once_per_scan);
  node.Read("grow_margin_m", &o->grow_margin_m);
  node.ThrowIfInvalid(o->Validate());
}

SlamConfig ParseSlamConfig(const std::string& name, const YamlNode& node) {
  SlamConfig config;
  config.name = name;
  if (name.empty() || name.find_first_of(" ,./\"") != std::string::npos) {
    node.Fail("configuration name '" + name +
              "' must be non-empty, without spaces, commas, dots or slashes");
  }
  ReadEnum(node, "algorithm", kAlgorithm, &config.algorithm);
  std::string preset = "default";
  node.Read("preset", &preset);
  if (preset == "reports") {
    config.pf = slam::ParticleFilterOptions::ReportsPreset();
  } else if (preset != "default") {
    node.Required("preset").Fail("expected default or reports, got '" + preset + "'");
  }
  slam::ParticleFilterOptions& pf = config.pf;
  node.Read("particles", &pf.num_particles);
  ReadEnum(node, "motion_noise", kMotionNoise, &pf.motion_noise);
  node.Read("sigma_xy_m", &pf.sigma_xy_m);
  node.Read("sigma_yaw_rad", &pf.sigma_yaw_rad);
  if (auto n = node.Optional("rot_trans_rot")) {
    n->Read("alpha1", &pf.rot_trans_rot.alpha1);
    n->Read("alpha2", &pf.rot_trans_rot.alpha2);
    n->Read("alpha3", &pf.rot_trans_rot.alpha3);
    n->Read("alpha4", &pf.rot_trans_rot.alpha4);
    n->Read("min_trans_sigma_m", &pf.rot_trans_rot.min_trans_sigma_m);
    n->Read("min_rot_sigma_rad", &pf.rot_trans_rot.min_rot_sigma_rad);
  }
  ReadEnum(node, "observation", kObservation, &pf.observation);
  if (auto n = node.Optional("points")) {
    n->Read("min_range_m", &pf.points.min_range_m);
    n->Read("max_range_m", &pf.points.max_range_m);
    n->Read("beam_stride", &pf.points.beam_stride);
    n->Read("voxel_size_m", &pf.points.voxel_size_m);
  }
  if (auto n = node.Optional("correlation")) {
    n->Read("xy_half_width_cells", &pf.correlation.xy_half_width_cells);
    n->Read("yaw_half_steps", &pf.correlation.yaw_half_steps);
    n->Read("yaw_step_rad", &pf.correlation.yaw_step_rad);
    ReadEnum(*n, "value", kCorrelationValue, &pf.correlation.value);
    n->Read("occupied_threshold", &pf.correlation.occupied_threshold);
    n->Read("prior_sigma_xy_m", &pf.correlation.prior_sigma_xy_m);
    n->Read("prior_sigma_yaw_rad", &pf.correlation.prior_sigma_yaw_rad);
    n->Read("min_shift_gain", &pf.correlation.min_shift_gain);
  }
  if (auto n = node.Optional("likelihood_field")) {
    n->Read("sigma_m", &pf.likelihood_field.sigma_m);
    n->Read("z_hit", &pf.likelihood_field.z_hit);
    n->Read("z_rand", &pf.likelihood_field.z_rand);
    n->Read("occupied_threshold", &pf.likelihood_field.occupied_threshold);
    n->Read("cutoff_sigmas", &pf.likelihood_field.cutoff_sigmas);
  }
  node.Read("observation_scale", &pf.observation_scale);
  node.Read("move_to_best_shift", &pf.move_to_best_shift);
  node.Read("refine", &pf.refine);
  if (auto n = node.Optional("refiner")) {
    n->Read("max_iterations", &pf.refiner.max_iterations);
    n->Read("max_step_m", &pf.refiner.max_step_m);
    n->Read("max_step_rad", &pf.refiner.max_step_rad);
    n->Read("converged_step_m", &pf.refiner.converged_step_m);
    n->Read("prior_sigma_xy_m", &pf.refiner.prior_sigma_xy_m);
    n->Read("prior_sigma_yaw_rad", &pf.refiner.prior_sigma_yaw_rad);
  }
  node.Read("min_update_distance_m", &pf.min_update_distance_m);
  node.Read("min_update_angle_rad", &pf.min_update_angle_rad);
  ReadEnum(node, "resampling", kResampling, &pf.resampling);
  node.Read("resample_neff_ratio", &pf.resample_neff_ratio);
  node.Read("threads", &pf.num_threads);
  config.map = pf.map;
  if (auto n = node.Optional("map")) {
    ParseGridOptions(*n, &pf.map);
    config.map = pf.map;
  }
  if (auto n = node.Optional("odometry")) {
    ReadEnum(*n, "source", kOdometrySource, &config.sync.source);
    n->Read("use_gyro", &config.sync.use_gyro);
    ReadEnum(*n, "integration", kIntegration, &config.sync.integration);
  }
  std::vector<std::string> errors = pf.Validate();
  node.ThrowIfInvalid(errors);
  return config;
}

std::string SlamConfigToYaml(const SlamConfig& c) {
  const slam::ParticleFilterOptions& pf = c.pf;
  std::ostringstream s;
  s.precision(10);
  s << c.name << ":\n  algorithm: " << EnumName(kAlgorithm, c.algorithm) << "\n";
  if (c.algorithm == SlamAlgorithm::kParticleFilter) {
    s << "  particles: " << pf.num_particles << "\n"
      << "  motion_noise: " << EnumName(kMotionNoise, pf.motion_noise) << "\n"
      << "  sigma_xy_m: " << pf.sigma_xy_m << "\n  sigma_yaw_rad: " << pf.sigma_yaw_rad << "\n"
      << "  rot_trans_rot: {alpha1: " << pf.rot_trans_rot.alpha1
      << ", alpha2: " << pf.rot_trans_rot.alpha2 << ", alpha3: " << pf.rot_trans_rot.alpha3
      << ", alpha4: " << pf.rot_trans_rot.alpha4
      << ", min_trans_sigma_m: " << pf.rot_trans_rot.min_trans_sigma_m
      << ", min_rot_sigma_rad: " << pf.rot_trans_rot.min_rot_sigma_rad << "}\n"
      << "  observation: " << EnumName(kObservation, pf.observation) << "\n"
      << "  points: {min_range_m: " << pf.points.min_range_m
      << ", max_range_m: " << pf.points.max_range_m << ", beam_stride: " << pf.points.beam_stride
      << ", voxel_size_m: " << pf.points.voxel_size_m << "}\n"
      << "  correlation: {xy_half_width_cells: " << pf.correlation.xy_half_width_cells
      << ", yaw_half_steps: " << pf.correlation.yaw_half_steps
      << ", yaw_step_rad: " << pf.correlation.yaw_step_rad
      << ", value: " << EnumName(kCorrelationValue, pf.correlation.value)
      << ", occupied_threshold: " << pf.correlation.occupied_threshold
      << ", prior_sigma_xy_m: " << pf.correlation.prior_sigma_xy_m
      << ", prior_sigma_yaw_rad: " << pf.correlation.prior_sigma_yaw_rad
      << ", min_shift_gain: " << pf.correlation.min_shift_gain << "}\n"
      << "  likelihood_field: {sigma_m: " << pf.likelihood_field.sigma_m
      << ", z_hit: " << pf.likelihood_field.z_hit << ", z_rand: " << pf.likelihood_field.z_rand
      << ", occupied_threshold: " << pf.likelihood_field.occupied_threshold
      << ", cutoff_sigmas: " << pf.likelihood_field.cutoff_sigmas << "}\n"
      << "  observation_scale: " << pf.observation_scale << "\n"
      << "  move_to_best_shift: " << (pf.move_to_best_shift ? "true" : "false") << "\n"
      << "  refine: " << (pf.refine ? "true" : "false") << "\n"
      << "  refiner: {max_iterations: " << pf.refiner.max_iterations
      << ", max_step_m: " << pf.refiner.max_step_m << ", max_step_rad: " << pf.refiner.max_step_rad
      << ", converged_step_m: " << pf.refiner.converged_step_m
      << ", prior_sigma_xy_m: " << pf.refiner.prior_sigma_xy_m
      << ", prior_sigma_yaw_rad: " << pf.refiner.prior_sigma_yaw_rad << "}\n"
      << "  min_update_distance_m: " << pf.min_update_distance_m << "\n"
      << "  min_update_angle_rad: " << pf.min_update_angle_rad << "\n"
      << "  resampling: " << EnumName(kResampling, pf.resampling) << "\n"
      << "  resample_neff_ratio: " << pf.resample_neff_ratio << "\n  threads: " << pf.num_threads
      << "\n";
  }
  const slam::OccupancyGridOptions& m =
      c.algorithm == SlamAlgorithm::kParticleFilter ? pf.map : c.map;
  s << "  map: {resolution_m: " << m.resolution_m << ", hit_log_odds: " << m.hit_log_odds
    << ", miss_log_odds: " << m.miss_log_odds << ", min_log_odds: " << m.min_log_odds
    << ", max_log_odds: " << m.max_log_odds << ", max_range_m: " << m.max_range_m
    << ", no_return_clear_range_m: " << m.no_return_clear_range_m
    << ", update_once_per_scan: " << (m.update_once_per_scan ? "true" : "false")
    << ", grow_margin_m: " << m.grow_margin_m << "}\n";
  s << "  odometry: {source: " << EnumName(kOdometrySource, c.sync.source)
    << ", use_gyro: " << (c.sync.use_gyro ? "true" : "false")
    << ", integration: " << EnumName(kIntegration, c.sync.integration) << "}\n";
  return s.str();
}

}  // namespace slamrig::scenario
