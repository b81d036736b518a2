#pragma once

// Field tables: each options struct lists its fields once, in a VisitFields(visitor, struct)
// overload beside the struct (a template: the struct's header includes no YAML), and the same list
// reads a file (FieldReader, strict, through YamlNode), writes the resolved config (FieldWriter)
// and writes metrics.json (slam/eval/json_fields.h). Reader and writers cannot drift apart.
//
// The visitor interface every VisitFields may use:
//   v(key, scalar)                  double, float, int, bool, std::string, std::uint64_t,
//                                   Eigen::Vector2d ([x, y]), Eigen::Vector3d ([x, y, z]),
//                                   std::vector<Eigen::Vector2d>, std::vector<std::string>
//                                   (a list of texts: a command's arguments)
//   v.Enum(key, e, {{E::kA, "a"}})  an enum by name; absent keeps the default
//   v.RequiredEnum(key, e, names)   the same, but the key must be there
//   v.Struct(key, s)                a nested map (its own VisitFields and Validate(), whose keys
//                                   are relative to s: the reader prefixes the path)
//   v.OptionalStruct(key, opt)      a nested map that may be absent (std::optional)
//   v.List(key, vector)             a list of maps

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <charconv>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "slam/config/yaml_node.h"
#include "slam/types/validation.h"

namespace slamrig {

/// Reads fields from a YAML map, keeping defaults for absent keys. A nested struct or list
/// element is validated where it is read, so its errors point at its own line.
class FieldReader {
 public:
  /// Reads the keys of the map `node`.
  explicit FieldReader(const YamlNode& node) : node_(node) {}

  /// A scalar (double, int, bool, string, uint64).
  template <typename T>
  void operator()(const char* key, T& value) {
    node_.Read(key, &value);
  }
  /// `[x, y]`.
  void operator()(const char* key, Eigen::Vector2d& value) {
    if (auto child = node_.Optional(key)) value = ReadPoint(*child);
  }
  /// `[x, y, z]`.
  void operator()(const char* key, Eigen::Vector3d& value) {
    auto child = node_.Optional(key);
    if (!child) return;
    const auto elements = child->Elements();
    if (elements.size() != 3)
      child->Fail("expected [x, y, z], got " + std::to_string(elements.size()) + " numbers");
    value = {elements[0].As<double>(), elements[1].As<double>(), elements[2].As<double>()};
  }
  /// `[[x, y], ...]`.
  void operator()(const char* key, std::vector<Eigen::Vector2d>& values) {
    auto child = node_.Optional(key);
    if (!child) return;
    values.clear();
    for (const YamlNode& element : child->Elements()) values.push_back(ReadPoint(element));
  }
  /// `[text, ...]`: every element a scalar, read as text.
  void operator()(const char* key, std::vector<std::string>& values) {
    auto child = node_.Optional(key);
    if (!child) return;
    if (child->IsScalar()) child->Fail("expected a list of texts, got a single value");
    values.clear();
    for (const YamlNode& element : child->Elements()) {
      if (!element.IsScalar())
        element.Fail(
            "expected a text (one argument), got a list or a map (quote a placeholder: "
            "\"{input}\")");
      values.push_back(element.As<std::string>());
    }
  }
  /// One of `names` (pairs of enum value and name); absent keeps the default.
  template <typename E>
  void Enum(const char* key, E& value, const std::vector<std::pair<E, const char*>>& names) {
    if (node_.Has(key)) RequiredEnum(key, value, names);
  }
  /// One of `names`; the key must be there.
  template <typename E>
  void RequiredEnum(const char* key, E& value,
                    const std::vector<std::pair<E, const char*>>& names) {
    const YamlNode child = node_.Required(key);
    const std::string text = child.As<std::string>();
    std::string choices;
    for (const auto& [option, name] : names) {
      if (text == name) {
        value = option;
        return;
      }
      choices += (choices.empty() ? "" : ", ") + std::string(name);
    }
    child.Fail("'" + text + "' is not one of: " + choices);
  }
  /// A nested map.
  template <typename T>
  void Struct(const char* key, T& value) {
    if (auto child = node_.Optional(key)) ReadStruct(*child, value);
  }
  /// A nested map that may be absent.
  template <typename T>
  void OptionalStruct(const char* key, std::optional<T>& value) {
    auto child = node_.Optional(key);
    if (!child) return;
    value.emplace();
    ReadStruct(*child, *value);
  }
  /// A list of maps.
  template <typename T>
  void List(const char* key, std::vector<T>& values) {
    auto child = node_.Optional(key);
    if (!child) return;
    values.clear();
    for (const YamlNode& element : child->Elements()) {
      values.emplace_back();
      ReadStruct(element, values.back());
    }
  }

  /// The map being read.
  const YamlNode& node() const { return node_; }

 private:
  static Eigen::Vector2d ReadPoint(const YamlNode& node) {
    const auto elements = node.Elements();
    if (elements.size() != 2)
      node.Fail("expected a point [x, y], got " + std::to_string(elements.size()) + " numbers");
    return {elements[0].As<double>(), elements[1].As<double>()};
  }
  template <typename T>
  static void ReadStruct(const YamlNode& node, T& value) {
    if (!node.IsMap()) node.Fail("expected a map");
    FieldReader reader(node);
    VisitFields(reader, value);
    if constexpr (requires { value.Validate(); }) {
      node.ThrowIfInvalid(PrefixErrors(node.path(), value.Validate()));
    }
  }

  YamlNode node_;
};

/// Writes the same fields as block YAML with shortest round-trip numbers.
class FieldWriter {
 public:
  /// Writes into `out`, which must be inside a map.
  explicit FieldWriter(YAML::Emitter* out) : out_(*out) {}

  /// Scalars, points and point lists, written as `key: value`.
  void operator()(const char* key, const double& value) {
    out_ << YAML::Key << key << YAML::Value << FormatNumber(value);
  }
  void operator()(const char* key, const float& value) {
    char buffer[32];  // the shortest text that reads back as this float
    const auto end = std::to_chars(buffer, buffer + sizeof(buffer), value).ptr;
    out_ << YAML::Key << key << YAML::Value << std::string(buffer, end);
  }
  void operator()(const char* key, const int& value) {
    out_ << YAML::Key << key << YAML::Value << value;
  }
  void operator()(const char* key, const std::uint64_t& value) {
    out_ << YAML::Key << key << YAML::Value << value;
  }
  void operator()(const char* key, const bool& value) {
    out_ << YAML::Key << key << YAML::Value << value;
  }
  void operator()(const char* key, const std::string& value) {
    out_ << YAML::Key << key << YAML::Value << value;
  }
  void operator()(const char* key, const Eigen::Vector2d& value) {
    out_ << YAML::Key << key << YAML::Value;
    WritePoint(value);
  }
  void operator()(const char* key, const Eigen::Vector3d& value) {
    out_ << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq
         << FormatNumber(value.x()) << FormatNumber(value.y()) << FormatNumber(value.z())
         << YAML::EndSeq;
  }
  void operator()(const char* key, const std::vector<Eigen::Vector2d>& values) {
    out_ << YAML::Key << key << YAML::Value << YAML::BeginSeq;
    for (const auto& v : values) WritePoint(v);
    out_ << YAML::EndSeq;
  }
  void operator()(const char* key, const std::vector<std::string>& values) {
    out_ << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (const auto& v : values) out_ << YAML::DoubleQuoted << v;
    out_ << YAML::EndSeq;
  }
  /// An enum by its name in `names`.
  template <typename E>
  void Enum(const char* key, E& value, const std::vector<std::pair<E, const char*>>& names) {
    for (const auto& [option, name] : names) {
      if (option == value) out_ << YAML::Key << key << YAML::Value << name;
    }
  }
  template <typename E>
  void RequiredEnum(const char* key, E& value,
                    const std::vector<std::pair<E, const char*>>& names) {
    Enum(key, value, names);
  }
  /// A nested map.
  template <typename T>
  void Struct(const char* key, T& value) {
    out_ << YAML::Key << key << YAML::Value;
    WriteStruct(value);
  }
  /// A nested map, only when present.
  template <typename T>
  void OptionalStruct(const char* key, std::optional<T>& value) {
    if (value) Struct(key, *value);
  }
  /// A list of maps.
  template <typename T>
  void List(const char* key, std::vector<T>& values) {
    out_ << YAML::Key << key << YAML::Value << YAML::BeginSeq;
    for (auto& value : values) WriteStruct(value);
    out_ << YAML::EndSeq;
  }

 private:
  void WritePoint(const Eigen::Vector2d& v) {
    out_ << YAML::Flow << YAML::BeginSeq << FormatNumber(v.x()) << FormatNumber(v.y())
         << YAML::EndSeq;
  }
  template <typename T>
  void WriteStruct(T& value) {
    out_ << YAML::BeginMap;
    VisitFields(*this, value);
    out_ << YAML::EndMap;
  }

  YAML::Emitter& out_;
};

/// Emits `value` (a struct with a VisitFields overload) as a YAML document.
template <typename T>
std::string ToYaml(T value, const std::string& header_comment) {
  YAML::Emitter out;
  if (!header_comment.empty()) out << YAML::Comment(header_comment);
  out << YAML::BeginMap;
  FieldWriter writer(&out);
  VisitFields(writer, value);
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace slamrig
