#pragma once

#include <cstdint>

namespace slamrig::slam {

/// The raw disparity the ECE276A Kinect files hold where there is no reading (the sensor's 11-bit
/// maximum; the depth formula below gives a negative depth for it).
inline constexpr std::uint16_t kKinectNoDisparity = 2047;

/// The ECE276A Kinect's depth from its raw disparity value `d` (Wang, "Simultaneous Localization
/// and Mapping with Texture", ECE276A report, Eq. 18): depth = 1.03 / (-0.00304 d + 3.31) metres.
/// Returns 0 (no reading) where the denominator is not positive (d >= ~1088.8).
inline double KinectDepthFromDisparity(double d) {
  const double denominator = -0.00304 * d + 3.31;
  return denominator > 0.0 ? 1.03 / denominator : 0.0;
}

/// The inverse of KinectDepthFromDisparity for a depth > 0: d = (3.31 - 1.03 / depth) / 0.00304.
inline double KinectDisparityFromDepth(double depth_m) { return (3.31 - 1.03 / depth_m) / 0.00304; }

}  // namespace slamrig::slam
