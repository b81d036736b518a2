#pragma once

// The disparity model lives in slam/io, where the ECE276A reader and writer need it; the camera
// renders through the same functions.
#include "slam/io/kinect_disparity.h"

namespace slamrig::sim {

using slam::KinectDepthFromDisparity;
using slam::KinectDisparityFromDepth;

}  // namespace slamrig::sim
