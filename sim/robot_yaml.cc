#include "sim/robot_yaml.h"

#include <filesystem>

#include "sim/mount_pose.h"
#include "slam/config/fields.h"

// The camera's intrinsics and mounting are data-contract types (namespace slamrig): their field
// tables live there so that argument-dependent lookup finds them.
namespace slamrig {

template <typename V>
void VisitFields(V& v, CameraIntrinsics& k) {
  v("fx_px", k.fx_px);
  v("fy_px", k.fy_px);
  v("cx_px", k.cx_px);
  v("cy_px", k.cy_px);
}

template <typename V>
void VisitFields(V& v, CameraMount& m) {
  v("x_m", m.x_m);
  v("y_m", m.y_m);
  v("z_m", m.z_m);
  v("roll_rad", m.roll_rad);
  v("pitch_rad", m.pitch_rad);
  v("yaw_rad", m.yaw_rad);
}

}  // namespace slamrig

namespace slamrig::sim {

// The robot file's schema: one field list per struct, shared by reader and writer.

template <typename V>
void VisitFields(V& v, ChassisOptions& c) {
  v("mass_kg", c.mass_kg);
  v("length_m", c.length_m);
  v("width_m", c.width_m);
  v("yaw_inertia_kg_m2", c.yaw_inertia_kg_m2);
  v("wall_friction", c.wall_friction);
}

template <typename V>
void VisitFields(V& v, WheelOptions& w) {
  v("radius_m", w.radius_m);
  v("track_width_m", w.track_width_m);
  v("per_side", w.per_side);
  v("wheelbase_m", w.wheelbase_m);
  v("spin_inertia_kg_m2", w.spin_inertia_kg_m2);
  v("caster_load_fraction", w.caster_load_fraction);
  v("contact_stiffness_per_m", w.contact_stiffness_per_m);
  v("relaxation_length_m", w.relaxation_length_m);
  v("contact_damping_s_m", w.contact_damping_s_m);
}

template <typename V>
void VisitFields(V& v, MotorOptions& m) {
  v("max_torque_n_m", m.max_torque_n_m);
  v("kp_n_m_s_rad", m.kp_n_m_s_rad);
  v("ki_n_m_rad", m.ki_n_m_rad);
  v("max_wheel_speed_rad_s", m.max_wheel_speed_rad_s);
}

template <typename V>
void VisitFields(V& v, CalibrationErrors& c) {
  v("left_radius_error", c.left_radius_error);
  v("right_radius_error", c.right_radius_error);
  v("track_width_error", c.track_width_error);
}

template <typename V>
void VisitFields(V& v, MotionLimits& l) {
  v("max_speed_m_s", l.max_speed_m_s);
  v("max_accel_m_s2", l.max_accel_m_s2);
  v("max_yaw_rate_rad_s", l.max_yaw_rate_rad_s);
  v("max_yaw_accel_rad_s2", l.max_yaw_accel_rad_s2);
}

template <typename V>
void VisitFields(V& v, EncoderOptions& e) {
  v("enabled", e.enabled);
  v("rate_hz", e.rate_hz);
  v("ticks_per_revolution", e.ticks_per_revolution);
  v("slip_stddev", e.slip_stddev);
  v("slip_common_stddev", e.slip_common_stddev);
  v("slip_length_m", e.slip_length_m);
}

template <typename V>
void VisitFields(V& v, ImuNoise& n) {
  v("noise_density", n.noise_density);
  v("random_walk", n.random_walk);
  v("bias", n.bias);
  v("turn_on_bias_stddev", n.turn_on_bias_stddev);
  v("scale_error", n.scale_error);
  v("saturation", n.saturation);
}

template <typename V>
void VisitFields(V& v, ImuOptions& i) {
  v("enabled", i.enabled);
  v("rate_hz", i.rate_hz);
  v.Struct("mount", i.mount);
  v("gravity_m_s2", i.gravity_m_s2);
  v.Struct("gyro", i.gyro);
  v.Struct("accel", i.accel);
}

template <typename V>
void VisitFields(V& v, LidarOptions& l) {
  v("enabled", l.enabled);
  v("rate_hz", l.rate_hz);
  v("num_beams", l.num_beams);
  v("fov_deg", l.fov_deg);
  v("beams_per_revolution", l.beams_per_revolution);
  v("range_min_m", l.range_min_m);
  v("range_max_m", l.range_max_m);
  v("range_noise_stddev_m", l.range_noise_stddev_m);
  v("range_noise_fraction", l.range_noise_fraction);
  v("range_resolution_m", l.range_resolution_m);
  v("p_short", l.p_short);
  v("short_decay_per_m", l.short_decay_per_m);
  v("p_max", l.p_max);
  v("p_random", l.p_random);
  v.Struct("mount", l.mount);
}

template <typename V>
void VisitFields(V& v, ZoneTexture& z) {
  v("zone", z.zone);
  v("image", z.image);
  v("tile_m", z.tile_m);
}

template <typename V>
void VisitFields(V& v, CameraSpec& c) {
  v("name", c.name);
  v("width_px", c.width_px);
  v("height_px", c.height_px);
  v("rate_hz", c.rate_hz);
  v.Struct("intrinsics", c.intrinsics);
  v.Struct("mount", c.mount);
  v("depth_offset_x_m", c.depth_offset_x_m);
  v.Enum("depth_model", c.depth_model,
         {{DepthModel::kIdeal, "ideal"}, {DepthModel::kKinectDisparity, "kinect_disparity"}});
  v("disparity_noise_stddev", c.disparity_noise_stddev);
  v("quantize_disparity", c.quantize_disparity);
  v("min_depth_m", c.min_depth_m);
  v("max_depth_m", c.max_depth_m);
  v("rgb_noise_stddev", c.rgb_noise_stddev);
  v("texture_dir", c.texture_dir);
  v("floor_image", c.floor_image);
  v("floor_tile_m", c.floor_tile_m);
  v.List("zones", c.zones);
  v("floor_texel_m", c.floor_texel_m);
  v("wall_height_m", c.wall_height_m);
  v("wall_rgb", c.wall_rgb);
  v("wall_image", c.wall_image);
  v("wall_tile_m", c.wall_tile_m);
  v("znear_m", c.znear_m);
  v("zfar_m", c.zfar_m);
}

template <typename V>
void VisitFields(V& v, RobotSpec& r) {
  v("name", r.name);
  v.Struct("chassis", r.chassis);
  v.Struct("wheels", r.wheels);
  v.Struct("motor", r.motor);
  v.Struct("calibration", r.calibration);
  v.Struct("limits", r.limits);
  v.Struct("encoders", r.encoders);
  v.Struct("imu", r.imu);
  v.Struct("lidar", r.lidar);
  v.OptionalStruct("camera", r.camera);
}

RobotSpec ParseRobotSpec(const YamlNode& node) {
  RobotSpec spec;
  FieldReader reader(node);
  VisitFields(reader, spec);
  // The camera's texture folder, like a world's map file, is relative to the file naming it: the
  // robot file, the scenario whose robot_overrides set it, or the working directory for
  // --set robot.camera.texture_dir=... on the command line.
  if (spec.camera && !spec.camera->texture_dir.empty()) {
    namespace fs = std::filesystem;
    const YamlNode dir_node = node.Required("camera").Required("texture_dir");
    spec.camera->texture_dir = dir_node.ResolvePath(spec.camera->texture_dir);
    std::error_code error;
    if (!fs::is_directory(spec.camera->texture_dir, error)) {
      dir_node.Fail("no such folder '" + spec.camera->texture_dir + "'");
    }
  }
  node.ThrowIfInvalid(spec.Validate());
  return spec;
}

RobotSpec LoadRobotSpec(const std::string& path) {
  const YamlNode root = YamlNode::LoadFile(path);
  if (!root.IsMap()) root.Fail("a robot file is a map (name, chassis, wheels, ...)");
  RobotSpec spec = ParseRobotSpec(root);
  root.CheckAllKeysUsed();
  return spec;
}

std::string RobotSpecToYaml(const RobotSpec& spec) {
  return ToYaml(spec, "slamrig robot (resolved: every field, defaults included)");
}

}  // namespace slamrig::sim
