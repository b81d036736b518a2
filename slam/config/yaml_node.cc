#include "slam/config/yaml_node.h"

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace slamrig {
namespace {

std::string MarkString(const std::string& file, const YAML::Mark& mark) {
  if (mark.is_null()) return file;
  return file + ":" + std::to_string(mark.line + 1) + ":" + std::to_string(mark.column + 1);
}

// True when key path `path` is `ancestor` or lies below it ("a.b" and "a.b[2].c" below "a.b";
// "a.bc" not).
bool IsAtOrBelow(const std::string& path, const std::string& ancestor) {
  return path == ancestor ||
         (path.size() > ancestor.size() && path.compare(0, ancestor.size(), ancestor) == 0 &&
          (path[ancestor.size()] == '.' || path[ancestor.size()] == '['));
}

// One step of a key path: a map key, or (index >= 0) a list element.
struct KeyStep {
  std::string key;
  long index = -1;
};

// "a.b[2].c" (or ".c", "[2].c": the rest of a longer path) as its steps; an unclosed '[' or an
// index that is not a number is a std::invalid_argument naming which.
std::vector<KeyStep> SplitKeyPath(const std::string& key_path) {
  std::vector<KeyStep> steps;
  std::string token;
  for (std::size_t i = 0; i <= key_path.size(); ++i) {
    const char c = i < key_path.size() ? key_path[i] : '.';
    if (c == '.' || c == '[') {
      if (!token.empty()) steps.push_back({token, -1});
      token.clear();
      if (c == '[') {
        const std::size_t close = key_path.find(']', i);
        if (close == std::string::npos) throw std::invalid_argument("unclosed '['");
        try {
          steps.push_back({"", std::stol(key_path.substr(i + 1, close - i - 1))});
        } catch (const std::logic_error&) {
          throw std::invalid_argument("bad index");
        }
        i = close;
      }
    } else {
      token += c;
    }
  }
  return steps;
}

}  // namespace

YamlNode YamlNode::LoadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(path + ": cannot open file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return LoadString(buffer.str(), path);
}

YamlNode YamlNode::LoadString(const std::string& text, const std::string& source_name) {
  auto usage = std::make_shared<Usage>();
  usage->file = source_name;
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(MarkString(source_name, e.mark) + ": YAML syntax error: " + e.msg);
  }
  return YamlNode(root, "", usage);
}

std::string YamlNode::ChildPath(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

std::string YamlNode::Where() const {
  // A value set by an override (or inside one) is located by the override, not the file.
  for (const auto& [path, origin] : usage_->overridden) {
    if (IsAtOrBelow(path_, path)) return origin + ": " + path_;
  }
  const std::string location = MarkString(usage_->file, node_.Mark());
  return path_.empty() ? location : location + ": " + path_;
}

std::string YamlNode::ResolvePath(const std::string& text) const {
  namespace fs = std::filesystem;
  fs::path path(text);
  if (path.is_relative()) {
    // The innermost override that set this node (or a node above it) decides; else the file.
    const std::string* base = nullptr;
    std::size_t matched = 0;
    for (const auto& [set_path, dir] : usage_->path_base) {
      if (IsAtOrBelow(path_, set_path) && (base == nullptr || set_path.size() > matched)) {
        base = &dir;
        matched = set_path.size();
      }
    }
    if (base != nullptr) {
      if (!base->empty()) path = fs::path(*base) / path;
    } else if (!usage_->file.empty()) {
      path = fs::path(usage_->file).parent_path() / path;
    }
  }
  return fs::absolute(path).lexically_normal().string();
}

void YamlNode::Fail(const std::string& message) const {
  throw ConfigError(Where() + ": " + message);
}

void YamlNode::ThrowIfInvalid(const std::vector<std::string>& errors) const {
  if (errors.empty()) return;
  std::string joined;
  for (const auto& e : errors) joined += (joined.empty() ? "" : "; ") + e;
  // A broken rule about a value an override set is located by the override.
  for (const auto& e : errors) {
    const std::string field = e.substr(0, e.find(" = "));
    for (const auto& [path, origin] : usage_->overridden) {
      if (IsAtOrBelow(field, path)) throw ConfigError(origin + ": " + joined);
    }
  }
  // Otherwise by the deepest node of this map that the first broken key reaches.
  const std::string field = errors.front().substr(0, errors.front().find(" = "));
  std::vector<KeyStep> steps;
  if (path_.empty() || (field != path_ && IsAtOrBelow(field, path_))) {
    try {
      steps = SplitKeyPath(field.substr(path_.size()));
    } catch (const std::invalid_argument&) {
      // Not a key path: the error stays at this node.
    }
  }
  // Map keys only: a key whose element is named ("walls[0]") stays at the map that holds it (a
  // rule about a list element, such as a wall holding the spawn point, is the document's).
  YAML::Node located = node_;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    if (steps[i].index >= 0 || (i + 1 < steps.size() && steps[i + 1].index >= 0)) break;
    const YAML::Node parent = located;  // const: a missing key must not be created
    if (!parent.IsMap() || !parent[steps[i].key].IsDefined()) break;
    located.reset(parent[steps[i].key]);
  }
  throw ConfigError(MarkString(usage_->file, located.Mark()) + ": " + joined);
}

std::string YamlNode::Describe() const {
  if (node_.IsScalar()) return "'" + node_.Scalar() + "'";
  if (node_.IsMap()) return "a map";
  if (node_.IsSequence()) return "a list";
  return "nothing";
}

bool YamlNode::Has(const std::string& key) const { return node_.IsMap() && node_[key]; }

YamlNode YamlNode::Required(const std::string& key) const {
  auto child = Optional(key);
  if (!child) Fail("missing required key '" + key + "'");
  return *child;
}

std::optional<YamlNode> YamlNode::Optional(const std::string& key) const {
  if (node_.IsNull()) return std::nullopt;
  if (!node_.IsMap()) Fail("expected a map with key '" + key + "', got " + Describe());
  const YAML::Node child = node_[key];
  if (!child) return std::nullopt;
  usage_->used_keys[path_].insert(key);
  return YamlNode(child, ChildPath(key), usage_);
}

std::vector<std::string> YamlNode::Keys() const {
  std::vector<std::string> keys;
  if (node_.IsNull()) return keys;
  if (!node_.IsMap()) Fail("expected a map, got " + Describe());
  for (const auto& kv : node_) keys.push_back(kv.first.Scalar());
  return keys;
}

std::vector<YamlNode> YamlNode::Elements() const {
  if (!node_.IsSequence()) Fail("expected a list, got " + Describe());
  std::vector<YamlNode> elements;
  for (std::size_t i = 0; i < node_.size(); ++i) {
    elements.push_back(YamlNode(node_[i], path_ + "[" + std::to_string(i) + "]", usage_));
  }
  return elements;
}

template <typename T>
T YamlNode::As() const {
  const char* expected = "a value";
  if constexpr (std::is_same_v<T, bool>) {
    expected = "true or false";
  } else if constexpr (std::is_integral_v<T>) {
    expected = "an integer";
  } else if constexpr (std::is_floating_point_v<T>) {
    expected = "a number";
  } else {
    expected = "a string";
  }
  if (!node_.IsScalar()) Fail("expected " + std::string(expected) + ", got " + Describe());
  T value{};
  try {
    value = node_.as<T>();
  } catch (const YAML::Exception&) {
    Fail("expected " + std::string(expected) + ", got " + Describe());
  }
  if constexpr (std::is_floating_point_v<T>) {
    if (!std::isfinite(value)) Fail("expected a finite number, got " + Describe());
  }
  return value;
}

template bool YamlNode::As<bool>() const;
template int YamlNode::As<int>() const;
template std::int64_t YamlNode::As<std::int64_t>() const;
template std::uint64_t YamlNode::As<std::uint64_t>() const;
template float YamlNode::As<float>() const;
template double YamlNode::As<double>() const;
template std::string YamlNode::As<std::string>() const;

void YamlNode::Override(const std::string& key_path, const std::string& value,
                        const std::string& origin, const std::string& base_dir) {
  const std::string label = origin.empty() ? "override " + key_path + "=" + value : origin;
  const std::string where = origin.empty() ? usage_->file + ": " + label + ": " : label + ": ";
  const std::string full_path = path_.empty() ? key_path : path_ + "." + key_path;
  usage_->overridden[full_path] = label;
  if (origin.empty()) {
    usage_->path_base.erase(full_path);
  } else {
    usage_->path_base[full_path] = base_dir;
  }
  std::vector<KeyStep> steps;
  try {
    steps = SplitKeyPath(key_path);
  } catch (const std::invalid_argument& e) {
    throw ConfigError(where + e.what());
  }
  if (steps.empty()) throw ConfigError(where + "empty key");
  YAML::Node parsed;
  try {
    parsed = YAML::Load(value);
  } catch (const YAML::Exception& e) {
    throw ConfigError(where + "value is not valid YAML: " + e.msg);
  }
  // Walk with copies of YAML::Node handles; they refer to the same underlying tree.
  YAML::Node node = node_;
  for (std::size_t s = 0; s < steps.size(); ++s) {
    const bool last = s + 1 == steps.size();
    if (steps[s].index >= 0) {
      if (!node.IsSequence() || static_cast<std::size_t>(steps[s].index) >= node.size()) {
        throw ConfigError(where + "no list element [" + std::to_string(steps[s].index) + "]");
      }
      if (last) {
        node[static_cast<std::size_t>(steps[s].index)] = parsed;
        return;
      }
      node.reset(node[static_cast<std::size_t>(steps[s].index)]);
      continue;
    }
    if (!node.IsMap() && !node.IsNull()) {
      throw ConfigError(where + "'" + steps[s].key + "' is below a value that is not a map");
    }
    if (last) {
      node[steps[s].key] = parsed;
      return;
    }
    if (!node[steps[s].key]) node[steps[s].key] = YAML::Node(YAML::NodeType::Map);
    node.reset(node[steps[s].key]);
  }
}

std::string YamlNode::ToFlowYaml() const {
  YAML::Emitter out;
  out.SetMapFormat(YAML::Flow);
  out.SetSeqFormat(YAML::Flow);
  out << node_;
  return out.c_str();
}

void YamlNode::CheckAllKeysUsed() const { CheckUsedRecursive(node_, path_); }

void YamlNode::CheckUsedRecursive(const YAML::Node& node, const std::string& path) const {
  if (node.IsMap()) {
    const auto used = usage_->used_keys.find(path);
    for (const auto& kv : node) {
      const std::string key = kv.first.Scalar();
      const std::string child_path = path.empty() ? key : path + "." + key;
      if (used == usage_->used_keys.end() || !used->second.count(key)) {
        // A key an override created (itself, or a map on the way to the overridden value) is
        // located by the override.
        std::string where = MarkString(usage_->file, kv.first.Mark());
        for (const auto& [set_path, origin] : usage_->overridden) {
          if (IsAtOrBelow(set_path, child_path)) {
            where = origin;
            break;
          }
        }
        throw ConfigError(where + ": " + child_path + ": unknown key");
      }
      CheckUsedRecursive(kv.second, child_path);
    }
  } else if (node.IsSequence()) {
    for (std::size_t i = 0; i < node.size(); ++i) {
      CheckUsedRecursive(node[i], path + "[" + std::to_string(i) + "]");
    }
  }
}

}  // namespace slamrig
