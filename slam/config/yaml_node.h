#pragma once

#include <yaml-cpp/yaml.h>

#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "slam/types/error.h"

namespace slamrig {

/// A strict view of a YAML document: every access knows its file, line, column and key path,
/// every error is a ConfigError that says so (`world.yaml:12:3: robot.wheels[0].radius_m: ...`),
/// and `CheckAllKeysUsed()` turns a key nobody read (a typo) into an error, the way
/// Cartographer's parameter dictionary insists every key is used exactly once.
class YamlNode {
 public:
  /// Parses `path`; a missing file or a syntax error is a ConfigError naming the file and line.
  static YamlNode LoadFile(const std::string& path);
  /// Parses `text`; `source_name` stands in for the file name in messages.
  static YamlNode LoadString(const std::string& text, const std::string& source_name);

  bool IsMap() const { return node_.IsMap(); }
  bool IsSequence() const { return node_.IsSequence(); }
  bool IsScalar() const { return node_.IsScalar(); }
  bool IsNull() const { return node_.IsNull(); }

  /// True if this is a map with `key`.
  bool Has(const std::string& key) const;
  /// The value at `key`, marked as used; a ConfigError if this is not a map or `key` is missing.
  YamlNode Required(const std::string& key) const;
  /// The value at `key` marked as used, or nullopt when absent.
  std::optional<YamlNode> Optional(const std::string& key) const;
  /// The keys of a map, in document order.
  std::vector<std::string> Keys() const;
  /// The elements of a sequence (a ConfigError if this is not one).
  std::vector<YamlNode> Elements() const;

  /// This scalar converted to T (double, float, int, int64, bool, std::string), or a ConfigError
  /// naming the expected type and the text found.
  template <typename T>
  T As() const;

  /// Reads optional `key` into `*value`, keeping the default already there when absent.
  template <typename T>
  void Read(const std::string& key, T* value) const {
    if (auto child = Optional(key)) *value = child->As<T>();
  }
  /// Reads required `key`.
  template <typename T>
  T Get(const std::string& key) const {
    return Required(key).As<T>();
  }

  /// Sets the value at dotted `key_path` (`slam.pf.num_particles`, `drive.waypoints[2]`) to the
  /// YAML text `value`, creating missing map keys: overrides of a file from the command line or
  /// from another file. A path through a scalar, or an index past a list's end, is a ConfigError
  /// naming the path. `origin` names where the override came from (e.g. "--set
  /// slam.pf.particles=0", or a scenario's "scenario.yaml:5:18: robot_overrides.x"): errors about
  /// the new value, or anything below it, name it instead of a line of this file. A relative path
  /// in an override with an origin is relative to `base_dir` (empty: the working directory, as
  /// for anything typed on the command line).
  void Override(const std::string& key_path, const std::string& value,
                const std::string& origin = "", const std::string& base_dir = "");

  /// `text`, a path this node holds, made absolute: relative to the folder of the file it was
  /// read from, or to the base_dir of the Override that set it (or a node above it).
  std::string ResolvePath(const std::string& text) const;

  /// This node as it was written, as one line of flow YAML (`{algorithm: pf, particles: 100}`):
  /// a part of one file passed on into another.
  std::string ToFlowYaml() const;

  /// Throws a ConfigError for the first map key, anywhere below this node, that was never read.
  void CheckAllKeysUsed() const;

  /// `file:line:col: path` of this node (1-based line and column).
  std::string Where() const;
  /// Throws ConfigError("<Where()>: <message>").
  [[noreturn]] void Fail(const std::string& message) const;
  /// Throws one ConfigError listing `errors` (from an options struct's Validate(), keys under this
  /// node's path) at the deepest node the first broken key reaches (at least this node); does
  /// nothing when `errors` is empty.
  void ThrowIfInvalid(const std::vector<std::string>& errors) const;

  const std::string& path() const { return path_; }
  const std::string& file() const { return usage_->file; }

 private:
  struct Usage {
    std::string file;
    std::map<std::string, std::set<std::string>> used_keys;  // by node path
    std::map<std::string, std::string> overridden;           // node path -> origin
    // Paths overridden with an origin -> the folder relative paths in them are relative to.
    std::map<std::string, std::string> path_base;
  };

  YamlNode(YAML::Node node, std::string path, std::shared_ptr<Usage> usage)
      : node_(std::move(node)), path_(std::move(path)), usage_(std::move(usage)) {}
  std::string ChildPath(const std::string& key) const;
  std::string Describe() const;
  void CheckUsedRecursive(const YAML::Node& node, const std::string& path) const;

  YAML::Node node_;
  std::string path_;
  std::shared_ptr<Usage> usage_;
};

}  // namespace slamrig
