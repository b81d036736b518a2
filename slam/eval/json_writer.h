#pragma once

#include <string>
#include <vector>

namespace slamrig::slam {

/// Builds one JSON object, keys in insertion order (metrics.json stays diffable). Numbers use
/// %.9g; NaN and infinities become null. Nest with `BeginObject`/`EndObject`.
class JsonWriter {
 public:
  JsonWriter();

  JsonWriter& Number(const std::string& key, double value);
  JsonWriter& Integer(const std::string& key, long long value);
  JsonWriter& String(const std::string& key, const std::string& value);
  JsonWriter& Bool(const std::string& key, bool value);
  JsonWriter& StringArray(const std::string& key, const std::vector<std::string>& values);
  /// Numbers as Number() writes them (NaN and infinities null).
  JsonWriter& NumberArray(const std::string& key, const std::vector<double>& values);
  JsonWriter& BeginObject(const std::string& key);
  JsonWriter& EndObject();

  /// The finished document (all objects closed), with a trailing newline.
  std::string Finish() const;

 private:
  void Key(const std::string& key);

  std::string out_;
  std::vector<bool> has_member_;  // one entry per open object
};

/// `text` as a JSON string literal, quotes included.
std::string JsonQuote(const std::string& text);

}  // namespace slamrig::slam
