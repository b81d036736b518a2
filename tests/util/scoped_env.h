#pragma once

#include <cstdlib>
#include <optional>
#include <string>
#include <utility>

namespace slamrig::testing {

/// One environment variable set (or unset) for a scope, and given back what it was at the end,
/// so that a test's environment does not leak into the next.
class ScopedEnv {
 public:
  /// Sets `name` to `value`, or unsets it for nullptr.
  ScopedEnv(std::string name, const char* value) : name_(std::move(name)) {
    if (const char* old = std::getenv(name_.c_str()); old != nullptr) saved_ = old;
    Set(value);
  }
  ~ScopedEnv() { Set(saved_ ? saved_->c_str() : nullptr); }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

  /// Sets it again (nullptr: unsets it).
  void Set(const char* value) const {
    if (value != nullptr) {
      ::setenv(name_.c_str(), value, 1);
    } else {
      ::unsetenv(name_.c_str());
    }
  }

 private:
  std::string name_;
  std::optional<std::string> saved_;
};

}  // namespace slamrig::testing
