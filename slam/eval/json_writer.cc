#include "slam/eval/json_writer.h"

#include <cmath>
#include <cstdio>

#include "slam/types/check.h"

namespace slamrig::slam {

std::string JsonQuote(const std::string& text) {
  std::string out = "\"";
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '"') {
      out += "\\\"";
    } else if (c == '\\') {
      out += "\\\\";
    } else if (c == '\n') {
      out += "\\n";
    } else if (c < 0x20) {
      char buffer[8];
      std::snprintf(buffer, sizeof(buffer), "\\u%04x", c);
      out += buffer;
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

JsonWriter::JsonWriter() : out_("{"), has_member_{false} {}

void JsonWriter::Key(const std::string& key) {
  SLAMRIG_CHECK(!has_member_.empty(), "JsonWriter: write after the document was closed");
  out_ += has_member_.back() ? ",\n" : "\n";
  out_ += std::string(2 * has_member_.size(), ' ') + JsonQuote(key) + ": ";
  has_member_.back() = true;
}

namespace {

std::string NumberText(double value) {
  if (!std::isfinite(value)) return "null";
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.9g", value);
  return buffer;
}

}  // namespace

JsonWriter& JsonWriter::Number(const std::string& key, double value) {
  Key(key);
  out_ += NumberText(value);
  return *this;
}

JsonWriter& JsonWriter::NumberArray(const std::string& key, const std::vector<double>& values) {
  Key(key);
  out_ += "[";
  for (std::size_t i = 0; i < values.size(); ++i) out_ += (i ? ", " : "") + NumberText(values[i]);
  out_ += "]";
  return *this;
}

JsonWriter& JsonWriter::Integer(const std::string& key, long long value) {
  Key(key);
  out_ += std::to_string(value);
  return *this;
}

JsonWriter& JsonWriter::String(const std::string& key, const std::string& value) {
  Key(key);
  out_ += JsonQuote(value);
  return *this;
}

JsonWriter& JsonWriter::Bool(const std::string& key, bool value) {
  Key(key);
  out_ += value ? "true" : "false";
  return *this;
}

JsonWriter& JsonWriter::StringArray(const std::string& key,
                                    const std::vector<std::string>& values) {
  Key(key);
  out_ += "[";
  for (std::size_t i = 0; i < values.size(); ++i) out_ += (i ? ", " : "") + JsonQuote(values[i]);
  out_ += "]";
  return *this;
}

JsonWriter& JsonWriter::BeginObject(const std::string& key) {
  Key(key);
  out_ += "{";
  has_member_.push_back(false);
  return *this;
}

JsonWriter& JsonWriter::EndObject() {
  SLAMRIG_CHECK(has_member_.size() > 1, "JsonWriter: EndObject without BeginObject");
  const bool had = has_member_.back();
  has_member_.pop_back();
  out_ += had ? "\n" + std::string(2 * has_member_.size(), ' ') + "}" : "}";
  return *this;
}

std::string JsonWriter::Finish() const {
  std::string out = out_;
  for (std::size_t depth = has_member_.size(); depth-- > 0;) {
    out += "\n" + std::string(2 * depth, ' ') + "}";
  }
  return out + "\n";
}

}  // namespace slamrig::slam
