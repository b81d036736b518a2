#include "sim/camera/rgbd_camera.h"

#include <mujoco/mujoco.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "sim/camera/egl_context.h"
#include "sim/camera/kinect_disparity.h"
#include "slam/types/error.h"
#include "slam/types/random_stream.h"

namespace slamrig::sim {
namespace {

constexpr char kModelFile[] = "slamrig_camera.xml";
constexpr char kFloorFile[] = "slamrig_floor.png";
constexpr char kWallFile[] = "slamrig_wall.png";
constexpr double kEdgeWallThicknessM = 0.05;  // polyline walls have no thickness in Box2D
// Moving obstacles (people in the scenarios) in a blue-grey no floor texture or wall uses.
constexpr double kObstacleRgb[3] = {0.25, 0.35, 0.6};

// How the rendered (centred) image maps onto the requested one.
struct RenderLayout {
  int width = 0;   // rendered columns
  int height = 0;  // rendered rows
  int crop_x = 0;  // first rendered column kept
  int crop_y = 0;  // first rendered row kept (top-down)
  double fovy_deg = 45.0;
  CameraIntrinsics effective;
};

// MuJoCo's principal point is the centre of the rendered image, (n - 1) / 2 in pixel-centre
// coordinates. Render n >= size pixels and crop from `offset` so that (n - 1) / 2 - offset is
// nearest to the requested principal point `c` (half-pixel steps of n give 0.25 px at worst).
void Centre(int size, double c, int* n, int* offset, double* effective) {
  const int slack = static_cast<int>(std::ceil(std::abs(c - (size - 1) / 2.0))) * 2 + 2;
  double best = std::numeric_limits<double>::infinity();
  for (int cand = size; cand <= size + slack; ++cand) {
    const int off = static_cast<int>(std::lround((cand - 1) / 2.0 - c));
    if (off < 0 || off > cand - size) continue;
    const double eff = (cand - 1) / 2.0 - off;
    if (std::abs(eff - c) < best - 1e-12) {
      best = std::abs(eff - c);
      *n = cand;
      *offset = off;
      *effective = eff;
    }
  }
}

RenderLayout Layout(const CameraSpec& spec) {
  RenderLayout l;
  Centre(spec.width_px, spec.intrinsics.cx_px, &l.width, &l.crop_x, &l.effective.cx_px);
  Centre(spec.height_px, spec.intrinsics.cy_px, &l.height, &l.crop_y, &l.effective.cy_px);
  l.effective.fx_px = spec.intrinsics.fx_px;
  l.effective.fy_px = spec.intrinsics.fy_px;
  l.fovy_deg = 2.0 * std::atan(0.5 * l.height / spec.intrinsics.fy_px) * 180.0 / std::numbers::pi;
  return l;
}

// The MJCF of the world: walls, the textured floor plane, the camera rig on a mocap body, and a
// mocap body per moving obstacle (named obstacle<i>, at the start of its path).
std::string BuildMjcf(const CameraSpec& spec, const FloorTexture& floor, const RenderLayout& l,
                      bool wall_texture, const std::vector<ObstacleSpec>& obstacles) {
  std::ostringstream x;
  x.precision(9);
  const double h = spec.wall_height_m;
  x << "<mujoco model=\"slamrig_camera\">\n"
    << "  <compiler angle=\"radian\"/>\n"
    << "  <statistic extent=\"1\" center=\"0 0 0\"/>\n"
    << "  <visual>\n"
    << "    <global offwidth=\"" << l.width << "\" offheight=\"" << l.height << "\"/>\n"
    << "    <quality shadowsize=\"0\" offsamples=\"0\"/>\n"
    << "    <map znear=\"" << spec.znear_m << "\" zfar=\"" << spec.zfar_m << "\"/>\n"
    << "    <headlight ambient=\"1 1 1\" diffuse=\"0 0 0\" specular=\"0 0 0\"/>\n"
    << "  </visual>\n"
    << "  <asset>\n"
    << "    <texture name=\"floor\" type=\"2d\" file=\"" << kFloorFile << "\"/>\n"
    << "    <material name=\"floor\" texture=\"floor\" texrepeat=\"1 1\" texuniform=\"false\" "
       "specular=\"0\" shininess=\"0\" reflectance=\"0\"/>\n";
  x << "    <material name=\"wall\" rgba=\"" << spec.wall_rgb[0] << ' ' << spec.wall_rgb[1] << ' '
    << spec.wall_rgb[2] << " 1\" specular=\"0\" shininess=\"0\" reflectance=\"0\"";
  if (wall_texture) {
    x << " texture=\"wall\" texuniform=\"true\" texrepeat=\"" << 1.0 / spec.wall_tile_m << ' '
      << 1.0 / spec.wall_tile_m << "\"";
  }
  x << "/>\n";
  x << "    <material name=\"obstacle\" rgba=\"" << kObstacleRgb[0] << ' ' << kObstacleRgb[1] << ' '
    << kObstacleRgb[2] << " 1\" specular=\"0\" shininess=\"0\" reflectance=\"0\"/>\n";
  if (wall_texture) x << "    <texture name=\"wall\" type=\"2d\" file=\"" << kWallFile << "\"/>\n";
  int mesh_id = 0;
  std::ostringstream geoms;
  geoms.precision(9);
  const auto box = [&](const Eigen::Vector2d& c, double sx, double sy, double angle) {
    geoms << "    <geom type=\"box\" material=\"wall\" pos=\"" << c.x() << ' ' << c.y() << ' '
          << h / 2 << "\" size=\"" << sx / 2 << ' ' << sy / 2 << ' ' << h / 2 << "\" euler=\"0 0 "
          << angle << "\"/>\n";
  };
  const auto edges = [&](const std::vector<Eigen::Vector2d>& pts, bool closed) {
    const std::size_t n = pts.size();
    for (std::size_t i = 0; i + 1 < n + (closed ? 1 : 0); ++i) {
      const Eigen::Vector2d a = pts[i], b = pts[(i + 1) % n];
      const Eigen::Vector2d d = b - a;
      if (d.norm() < 1e-9) continue;
      box(0.5 * (a + b), d.norm() + kEdgeWallThicknessM, kEdgeWallThicknessM,
          std::atan2(d.y(), d.x()));
    }
  };
  for (const ShapeSpec& s : floor.walls()) {
    switch (s.type) {
      case ShapeType::kBox:
        box(s.center_m, s.size_m.x(), s.size_m.y(), s.angle_rad);
        break;
      case ShapeType::kCircle:
        geoms << "    <geom type=\"cylinder\" material=\"wall\" pos=\"" << s.center_m.x() << ' '
              << s.center_m.y() << ' ' << h / 2 << "\" size=\"" << s.radius_m << ' ' << h / 2
              << "\"/>\n";
        break;
      case ShapeType::kPolygon:
        if (s.IsConvexPolygon()) {
          // A convex prism: MuJoCo renders the convex hull of the vertices.
          x << "    <mesh name=\"wall" << mesh_id << "\" vertex=\"";
          for (const Eigen::Vector2d& p : s.Outline()) {
            x << p.x() << ' ' << p.y() << " 0 " << p.x() << ' ' << p.y() << ' ' << h << ' ';
          }
          x << "\"/>\n";
          geoms << "    <geom type=\"mesh\" mesh=\"wall" << mesh_id++ << "\" material=\"wall\"/>\n";
        } else {
          edges(s.Outline(), true);
        }
        break;
      case ShapeType::kPolyline:
        edges(s.points_m, s.closed);
        break;
    }
  }
  const Eigen::Vector2d c = 0.5 * (floor.min_m() + floor.max_m());
  const Eigen::Vector2d half = 0.5 * (floor.max_m() - floor.min_m());
  x << "  </asset>\n"
    << "  <worldbody>\n"
    << "    <geom type=\"plane\" material=\"floor\" pos=\"" << c.x() << ' ' << c.y()
    << " 0\" size=\"" << half.x() << ' ' << half.y() << " 1\"/>\n"
    << geoms.str() << "    <body name=\"rig\" mocap=\"true\">\n"
    << "      <camera name=\"rgb\" pos=\"0 0 0\" fovy=\"" << l.fovy_deg << "\"/>\n"
    << "      <camera name=\"depth\" pos=\"" << spec.depth_offset_x_m << " 0 0\" fovy=\""
    << l.fovy_deg << "\"/>\n"
    << "    </body>\n";
  for (std::size_t i = 0; i < obstacles.size(); ++i) {
    const ObstacleSpec& o = obstacles[i];
    const ShapeSpec& s = o.shape;
    x << "    <body name=\"obstacle" << i << "\" mocap=\"true\" pos=\"" << o.path_m.front().x()
      << ' ' << o.path_m.front().y() << " 0\">\n";
    if (s.type == ShapeType::kCircle) {
      x << "      <geom type=\"cylinder\" material=\"obstacle\" pos=\"" << s.center_m.x() << ' '
        << s.center_m.y() << ' ' << h / 2 << "\" size=\"" << s.radius_m << ' ' << h / 2 << "\"/>\n";
    } else if (s.type == ShapeType::kBox) {
      x << "      <geom type=\"box\" material=\"obstacle\" pos=\"" << s.center_m.x() << ' '
        << s.center_m.y() << ' ' << h / 2 << "\" size=\"" << s.size_m.x() / 2 << ' '
        << s.size_m.y() / 2 << ' ' << h / 2 << "\" euler=\"0 0 " << s.angle_rad << "\"/>\n";
    } else {
      throw ConfigError("camera '" + spec.name + "': obstacles[" + std::to_string(i) + "] ('" +
                        o.name + "'): the camera renders box and circle obstacles only");
    }
    x << "    </body>\n";
  }
  x << "  </worldbody>\n"
    << "</mujoco>\n";
  return x.str();
}

void AddToVfs(mjVFS* vfs, const char* name, const std::vector<unsigned char>& bytes) {
  if (mj_makeEmptyFileVFS(vfs, name, static_cast<int>(bytes.size())) != 0) {
    throw std::runtime_error(std::string("MuJoCo: cannot add ") + name + " to the VFS");
  }
  const int i = mj_findFileVFS(vfs, name);
  std::memcpy(vfs->filedata[i], bytes.data(), bytes.size());
}

std::vector<unsigned char> EncodePng(const cv::Mat3b& rgb) {
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  std::vector<unsigned char> png;
  cv::imencode(".png", bgr, png, {cv::IMWRITE_PNG_COMPRESSION, 1});
  return png;
}

}  // namespace

struct RgbdCamera::Impl {
  CameraSpec spec;
  FloorTexture floor;
  RenderLayout layout;
  RandomStream noise;
  EglContext egl;
  mjModel* model = nullptr;
  mjData* data = nullptr;
  mjvScene scene;
  mjrContext context;
  mjvOption option;
  double near_m = 0.0;
  double far_m = 0.0;
  std::vector<unsigned char> rgb_buffer;
  std::vector<float> depth_buffer;
  int rig_mocap = 0;
  std::vector<int> obstacle_mocap;  // mocap index of obstacle i

  Impl(const WorldSpec& world, const CameraSpec& s, std::uint64_t seed)
      : spec(s), floor(world, s), layout(Layout(s)), noise(seed, "camera") {
    mjv_defaultScene(&scene);
    mjr_defaultContext(&context);
  }

  ~Impl() {
    egl.MakeCurrent();
    mjr_freeContext(&context);
    mjv_freeScene(&scene);
    if (data != nullptr) mj_deleteData(data);
    if (model != nullptr) mj_deleteModel(model);
  }

  // Renders camera `id` and reads the full rendered image into the buffers given; a depth-only
  // pass skips the textures (measured: texture sampling is most of llvmpipe's render time).
  void RenderCamera(int id, unsigned char* rgb, float* depth) {
    option.flags[mjVIS_TEXTURE] = rgb != nullptr ? 1 : 0;
    mjvCamera camera;
    mjv_defaultCamera(&camera);
    camera.type = mjCAMERA_FIXED;
    camera.fixedcamid = id;
    mjv_updateScene(model, data, &option, nullptr, &camera, mjCAT_ALL, &scene);
    const mjrRect viewport = {0, 0, layout.width, layout.height};
    mjr_render(viewport, &scene, &context);
    mjr_readPixels(rgb, depth, viewport, &context);
  }
};

RgbdCamera::RgbdCamera(const WorldSpec& world, const CameraSpec& spec, std::uint64_t seed) {
  const std::vector<std::string> errors = spec.Validate();
  if (!errors.empty()) throw ConfigError("camera '" + spec.name + "': camera." + errors.front());
  impl_ = std::make_unique<Impl>(world, spec, seed);
  Impl& m = *impl_;

  // Model: MJCF and textures in a virtual file system, nothing written to disk.
  const bool wall_texture = !spec.wall_image.empty();
  mjVFS vfs;
  mj_defaultVFS(&vfs);
  try {
    AddToVfs(&vfs, kFloorFile, EncodePng(m.floor.image()));
    if (wall_texture) {
      AddToVfs(&vfs, kWallFile,
               EncodePng(ReadTextureImage(spec, spec.wall_image, "camera.wall_image")));
    }
    const std::string xml = BuildMjcf(spec, m.floor, m.layout, wall_texture, world.obstacles);
    AddToVfs(&vfs, kModelFile, std::vector<unsigned char>(xml.begin(), xml.end()));
  } catch (...) {
    mj_deleteVFS(&vfs);
    throw;
  }
  char error[1000] = "";
  m.model = mj_loadXML(kModelFile, &vfs, error, sizeof(error));
  mj_deleteVFS(&vfs);
  if (m.model == nullptr) {
    throw std::runtime_error("camera '" + spec.name + "': MuJoCo rejected the model: " + error);
  }
  m.data = mj_makeData(m.model);
  const auto mocap = [&](const std::string& body) {
    const int id = mj_name2id(m.model, mjOBJ_BODY, body.c_str());
    if (id < 0 || m.model->body_mocapid[id] < 0) {
      throw std::runtime_error("camera '" + spec.name + "': MuJoCo model has no mocap " + body);
    }
    return m.model->body_mocapid[id];
  };
  m.rig_mocap = mocap("rig");
  for (std::size_t i = 0; i < world.obstacles.size(); ++i) {
    m.obstacle_mocap.push_back(mocap("obstacle" + std::to_string(i)));
  }
  m.near_m = m.model->vis.map.znear * m.model->stat.extent;
  m.far_m = m.model->vis.map.zfar * m.model->stat.extent;

  // Rendering: no shadows, reflections, skybox or fog (the scene has none to gain from them).
  mjv_defaultOption(&m.option);
  mjv_makeScene(m.model, &m.scene, m.model->ngeom + 16);
  m.scene.flags[mjRND_SHADOW] = 0;
  m.scene.flags[mjRND_REFLECTION] = 0;
  m.scene.flags[mjRND_SKYBOX] = 0;
  m.scene.flags[mjRND_FOG] = 0;
  mjr_makeContext(m.model, &m.context, mjFONTSCALE_100);
  mjr_setBuffer(mjFB_OFFSCREEN, &m.context);
  if (m.context.currentBuffer != mjFB_OFFSCREEN || m.context.offWidth < m.layout.width ||
      m.context.offHeight < m.layout.height) {
    throw std::runtime_error("camera '" + spec.name + "': MuJoCo has no " +
                             std::to_string(m.layout.width) + " x " +
                             std::to_string(m.layout.height) + " offscreen buffer");
  }
  m.rgb_buffer.resize(static_cast<std::size_t>(m.layout.width) * m.layout.height * 3);
  m.depth_buffer.resize(static_cast<std::size_t>(m.layout.width) * m.layout.height);
}

RgbdCamera::~RgbdCamera() = default;

const CameraSpec& RgbdCamera::spec() const { return impl_->spec; }
const CameraIntrinsics& RgbdCamera::intrinsics() const { return impl_->layout.effective; }
const FloorTexture& RgbdCamera::floor() const { return impl_->floor; }

RgbdFrame RgbdCamera::Render(const Pose2& map_from_base, Time t,
                             const std::vector<Eigen::Vector2d>& obstacle_positions_m) {
  Impl& m = *impl_;
  if (!obstacle_positions_m.empty()) {
    if (obstacle_positions_m.size() != m.obstacle_mocap.size()) {
      throw std::invalid_argument(
          "camera '" + m.spec.name + "': " + std::to_string(obstacle_positions_m.size()) +
          " obstacle positions for " + std::to_string(m.obstacle_mocap.size()) + " obstacles");
    }
    for (std::size_t i = 0; i < obstacle_positions_m.size(); ++i) {
      double* p = m.data->mocap_pos + 3 * m.obstacle_mocap[i];
      p[0] = obstacle_positions_m[i].x();
      p[1] = obstacle_positions_m[i].y();
      p[2] = 0.0;
    }
  }
  const CameraSpec& spec = m.spec;
  m.egl.MakeCurrent();

  // The rig: world_from_base * base_from_camera * camera_from_mujoco (MuJoCo's camera looks along
  // its -z with +y up; x stays right as in the optical frame).
  Eigen::Isometry3d world_from_base = Eigen::Isometry3d::Identity();
  world_from_base.translation() = Eigen::Vector3d(map_from_base.x(), map_from_base.y(), 0.0);
  world_from_base.linear() =
      Eigen::AngleAxisd(map_from_base.theta(), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Eigen::Matrix3d camera_from_mujoco;
  camera_from_mujoco << 0, 0, -1,  //
      -1, 0, 0,                    //
      0, 1, 0;
  const Eigen::Isometry3d world_from_rig = world_from_base * spec.mount.BaseFromCamera();
  const Eigen::Quaterniond q(world_from_rig.linear() * camera_from_mujoco);
  double* rig_pos = m.data->mocap_pos + 3 * m.rig_mocap;
  double* rig_quat = m.data->mocap_quat + 4 * m.rig_mocap;
  for (int i = 0; i < 3; ++i) rig_pos[i] = world_from_rig.translation()[i];
  rig_quat[0] = q.w();
  rig_quat[1] = q.x();
  rig_quat[2] = q.y();
  rig_quat[3] = q.z();
  mj_kinematics(m.model, m.data);
  mj_camlight(m.model, m.data);

  // One view serves both images unless the depth camera is offset.
  const bool two_views = spec.depth_offset_x_m != 0.0;
  m.RenderCamera(0, m.rgb_buffer.data(), two_views ? nullptr : m.depth_buffer.data());
  if (two_views) m.RenderCamera(1, nullptr, m.depth_buffer.data());

  RgbdFrame frame;
  frame.time = t;
  frame.width = spec.width_px;
  frame.height = spec.height_px;
  frame.intrinsics = m.layout.effective;
  frame.base_from_camera = spec.mount;
  frame.depth_offset_x_m = spec.depth_offset_x_m;
  const std::size_t pixels = static_cast<std::size_t>(frame.width) * frame.height;
  frame.rgb.resize(3 * pixels);
  frame.depth_m.resize(pixels);

  // OpenGL's rows run bottom-up: output row v is rendered row height - 1 - (crop_y + v).
  const double near = m.near_m, far = m.far_m;
  const bool kinect = spec.depth_model == DepthModel::kKinectDisparity;
  bool sees_anything = false;
  for (int v = 0; v < frame.height; ++v) {
    const std::size_t src_row =
        static_cast<std::size_t>(m.layout.height - 1 - (m.layout.crop_y + v)) * m.layout.width +
        m.layout.crop_x;
    const std::size_t dst_row = static_cast<std::size_t>(v) * frame.width;
    std::memcpy(&frame.rgb[3 * dst_row], &m.rgb_buffer[3 * src_row], 3 * frame.width);
    for (int u = 0; u < frame.width; ++u) {
      const float d = m.depth_buffer[src_row + u];
      float z_out = 0.0f;
      if (d < 1.0f) {
        sees_anything = true;
        // Window depth to eye-space z for a standard perspective projection.
        double z = near / (1.0 - static_cast<double>(d) * (1.0 - near / far));
        if (kinect) {
          double disparity = KinectDisparityFromDepth(z);
          if (spec.disparity_noise_stddev > 0.0) {
            disparity += spec.disparity_noise_stddev * m.noise.Gaussian();
          }
          if (spec.quantize_disparity) disparity = std::round(disparity);
          z = KinectDepthFromDisparity(disparity);
        }
        if (z >= spec.min_depth_m && z <= spec.max_depth_m) z_out = static_cast<float>(z);
      }
      frame.depth_m[dst_row + u] = z_out;
    }
  }
  if (!sees_anything) {
    std::ostringstream msg;
    msg << "camera '" << spec.name << "': sees nothing at map_from_base (" << map_from_base.x()
        << ", " << map_from_base.y() << ", " << map_from_base.theta()
        << "); is the robot inside the world and the camera pointing at it?";
    throw ConfigError(msg.str());
  }
  if (spec.rgb_noise_stddev > 0.0) {
    for (std::uint8_t& b : frame.rgb) {
      const double noisy = b + spec.rgb_noise_stddev * m.noise.Gaussian();
      b = static_cast<std::uint8_t>(std::clamp(std::round(noisy), 0.0, 255.0));
    }
  }
  return frame;
}

}  // namespace slamrig::sim
