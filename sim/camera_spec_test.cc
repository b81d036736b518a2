#include "sim/camera_spec.h"

#include <gtest/gtest.h>

namespace slamrig::sim {
namespace {

TEST(CameraSpecTest, DefaultsAreTheReportsKinectAndValid) {
  const CameraSpec c;
  EXPECT_TRUE(c.Validate().empty());
  EXPECT_EQ(c.width_px, 640);
  EXPECT_EQ(c.height_px, 480);
  EXPECT_DOUBLE_EQ(c.intrinsics.fx_px, 585.05108211);
  EXPECT_DOUBLE_EQ(c.mount.pitch_rad, 0.36);
  EXPECT_DOUBLE_EQ(c.mount.z_m, 0.36);
  EXPECT_DOUBLE_EQ(c.period_s(), 0.1);
}

TEST(CameraSpecTest, NamesTheFieldTheValueAndTheRule) {
  CameraSpec c;
  c.width_px = 0;
  c.intrinsics.fx_px = 500.0;
  c.zfar_m = 0.01;
  const std::vector<std::string> e = c.Validate();
  ASSERT_GE(e.size(), 3u);
  EXPECT_EQ(e[0], "width_px = 0; must be in [1, 4096]");
  EXPECT_EQ(e[1],
            "intrinsics.fx_px = 500; must equal intrinsics.fy_px (MuJoCo 2.2 renders "
            "square pixels)");
  EXPECT_NE(std::find(e.begin(), e.end(), "zfar_m = 0.01; must be > znear_m"), e.end());
}

}  // namespace
}  // namespace slamrig::sim
