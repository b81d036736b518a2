#pragma once

#include <stdexcept>
#include <string>

namespace slamrig {

/// A configuration value (YAML, CLI flag, options struct) that breaks a rule.
/// The message names where it came from: `file:line:col: key.path: what is wrong`.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Input data (a log, a map, a trajectory file) that cannot be read.
/// The message names the file, the line and the field: `file:line: field: what is wrong`.
class ParseError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An output that cannot be written: a full disk, a read-only folder, a failed rename. The
/// message names the file. main exits with code 74 (EX_IOERR) for it, so that a sweep tells "the
/// run could not write its results" (not a result: run it again) from a run that failed.
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace slamrig
