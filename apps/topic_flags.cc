#include "apps/topic_flags.h"

#include "slam/types/error.h"

namespace slamrig::app {

slam::BagTopicNames ParseTopicFlags(const std::string& command,
                                    const std::vector<std::string>& flags) {
  slam::BagTopicNames topics;
  for (const std::string& flag : flags) {
    const std::string where = command + ": --topic " + flag + ": ";
    const std::size_t eq = flag.find('=');
    if (eq == std::string::npos) throw ConfigError(where + "expected KEY=NAME");
    std::string* name = topics.Find(flag.substr(0, eq));
    if (name == nullptr) {
      throw ConfigError(where + "unknown key '" + flag.substr(0, eq) + "' (expected one of " +
                        slam::BagTopicNames::Keys() + ")");
    }
    *name = flag.substr(eq + 1);
  }
  if (const std::vector<std::string> errors = topics.Validate(); !errors.empty()) {
    throw ConfigError(command + ": --topic: " + errors.front());
  }
  return topics;
}

}  // namespace slamrig::app
