#pragma once

#include <fstream>
#include <sstream>
#include <string>

namespace slamrig::testing {

/// A whole file's bytes; empty when it cannot be read (the caller's expectation then fails on
/// the content).
inline std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace slamrig::testing
