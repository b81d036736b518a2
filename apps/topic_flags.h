#pragma once

#include <string>
#include <vector>

#include "slam/io/bag/bag_writer.h"

namespace slamrig::app {

/// The bag topic names that `--topic KEY=NAME` flags ask for, starting from the ROS defaults
/// (slam::BagTopicNames): `--topic scan=/front/scan --topic odom=/wheel_odom`. Throws
/// ConfigError naming `command` and the flag for an unknown key, a missing '=' or a name that
/// is not an absolute ROS topic name.
slam::BagTopicNames ParseTopicFlags(const std::string& command,
                                    const std::vector<std::string>& flags);

}  // namespace slamrig::app
