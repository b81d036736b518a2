#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "slam/eval/json_writer.h"

namespace slamrig::slam {

/// The JSON side of the field tables (slam/config/fields.h): writes an options struct into
/// metrics.json with the same keys the YAML reader takes, through the struct's VisitFields.
/// Only what estimator options use: scalars, lists of texts, enums and nested maps.
class JsonFieldWriter {
 public:
  /// Writes into the currently open object of `json`.
  explicit JsonFieldWriter(JsonWriter* json) : json_(*json) {}

  void operator()(const char* key, const double& value) { json_.Number(key, value); }
  void operator()(const char* key, const float& value) {
    json_.Number(key, static_cast<double>(value));
  }
  void operator()(const char* key, const int& value) { json_.Integer(key, value); }
  void operator()(const char* key, const std::uint64_t& value) {
    json_.Integer(key, static_cast<long long>(value));
  }
  void operator()(const char* key, const bool& value) { json_.Bool(key, value); }
  void operator()(const char* key, const std::string& value) { json_.String(key, value); }
  void operator()(const char* key, const std::vector<std::string>& values) {
    json_.StringArray(key, values);
  }
  template <typename E>
  void Enum(const char* key, E& value, const std::vector<std::pair<E, const char*>>& names) {
    for (const auto& [option, name] : names) {
      if (option == value) json_.String(key, name);
    }
  }
  template <typename E>
  void RequiredEnum(const char* key, E& value,
                    const std::vector<std::pair<E, const char*>>& names) {
    Enum(key, value, names);
  }
  template <typename T>
  void Struct(const char* key, T& value) {
    json_.BeginObject(key);
    VisitFields(*this, value);
    json_.EndObject();
  }
  template <typename T>
  void OptionalStruct(const char* key, std::optional<T>& value) {
    if (value) Struct(key, *value);
  }

 private:
  JsonWriter& json_;
};

}  // namespace slamrig::slam
