#include "apps/cli_args.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "slam/types/error.h"

namespace slamrig::app {
namespace {

template <typename T>
bool ParseNumber(const std::string& text, T* out) {
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), *out);
  return ec == std::errc() && end == text.data() + text.size();
}

std::string ShortDouble(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

ArgParser::ArgParser(std::string command, std::string usage, std::string description)
    : command_(std::move(command)),
      usage_(std::move(usage)),
      description_(std::move(description)) {}

void ArgParser::Fail(const std::string& message) const {
  throw ConfigError(command_ + ": " + message + " (see '" + command_ + " --help')");
}

void ArgParser::AddTyped(const std::string& name, const std::string& value_name,
                         const std::string& help, std::string default_text,
                         std::function<void(const std::string&)> set) {
  options_.push_back({name, value_name, help, std::move(default_text), std::move(set)});
}

void ArgParser::AddFlag(const std::string& name, const std::string& help, bool* value) {
  AddTyped(name, "", help, "", [value](const std::string&) { *value = true; });
}

void ArgParser::AddOption(const std::string& name, const std::string& value_name,
                          const std::string& help, std::string* value) {
  AddTyped(name, value_name, help, *value, [value](const std::string& v) { *value = v; });
}

void ArgParser::AddOption(const std::string& name, const std::string& value_name,
                          const std::string& help, double* value) {
  AddTyped(name, value_name, help, ShortDouble(*value), [this, name, value](const std::string& v) {
    double parsed = 0;
    if (!ParseNumber(v, &parsed) || !std::isfinite(parsed)) {
      Fail("--" + name + ": expected a number, got '" + v + "'");
    }
    *value = parsed;
  });
}

void ArgParser::AddOption(const std::string& name, const std::string& value_name,
                          const std::string& help, int* value) {
  AddTyped(name, value_name, help, std::to_string(*value),
           [this, name, value](const std::string& v) {
             if (!ParseNumber(v, value))
               Fail("--" + name + ": expected an integer, got '" + v + "'");
           });
}

void ArgParser::AddOption(const std::string& name, const std::string& value_name,
                          const std::string& help, std::uint64_t* value) {
  AddTyped(name, value_name, help, std::to_string(*value),
           [this, name, value](const std::string& v) {
             if (!ParseNumber(v, value)) {
               Fail("--" + name + ": expected a non-negative integer, got '" + v + "'");
             }
           });
}

void ArgParser::AddRepeated(const std::string& name, const std::string& value_name,
                            const std::string& help, std::vector<std::string>* values) {
  AddTyped(name, value_name, help + " (repeatable)", "",
           [values](const std::string& v) { values->push_back(v); });
}

void ArgParser::AddPositional(const std::string& name, const std::string& help, std::string* value,
                              bool required) {
  positionals_.push_back({name, help, value, required});
}

bool ArgParser::Parse(const std::vector<std::string>& args) {
  std::size_t next_positional = 0;
  bool only_positionals = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (!only_positionals && (arg == "-h" || arg == "--help")) {
      std::fputs(Help().c_str(), stdout);
      return false;
    }
    if (!only_positionals && arg == "--") {
      only_positionals = true;
      continue;
    }
    if (!only_positionals && arg.size() > 1 && arg[0] == '-') {
      if (arg.rfind("--", 0) != 0) Fail("unknown option '" + arg + "'");
      const std::size_t eq = arg.find('=');
      const std::string name = arg.substr(2, eq == std::string::npos ? std::string::npos : eq - 2);
      const Option* option = nullptr;
      for (const Option& o : options_) {
        if (o.name == name) option = &o;
      }
      if (option == nullptr) Fail("unknown option '--" + name + "'");
      if (option->value_name.empty()) {
        if (eq != std::string::npos) Fail("--" + name + " takes no value");
        option->set("");
        continue;
      }
      std::string value;
      if (eq != std::string::npos) {
        value = arg.substr(eq + 1);
      } else {
        if (i + 1 >= args.size()) Fail("--" + name + " needs a value (" + option->value_name + ")");
        value = args[++i];
      }
      option->set(value);
      continue;
    }
    if (next_positional >= positionals_.size()) Fail("unexpected argument '" + arg + "'");
    *positionals_[next_positional++].value = arg;
  }
  for (std::size_t p = next_positional; p < positionals_.size(); ++p) {
    if (positionals_[p].required) Fail("missing " + positionals_[p].name);
  }
  return true;
}

std::string ArgParser::Help() const {
  std::string out = "Usage: " + command_ + " " + usage_ + "\n\n" + description_ + "\n";
  auto row = [&out](const std::string& left, const std::string& help) {
    out += "  " + left;
    out += left.size() < 24 ? std::string(24 - left.size(), ' ') : "\n" + std::string(26, ' ');
    out += help + "\n";
  };
  if (!positionals_.empty()) {
    out += "\nArguments:\n";
    for (const auto& p : positionals_) row(p.name, p.help);
  }
  out += "\nOptions:\n";
  for (const auto& o : options_) {
    const std::string left = "--" + o.name + (o.value_name.empty() ? "" : " " + o.value_name);
    // Not where the help says its own default ("until the drive is done" reads better than 0).
    const bool show_default = !o.value_name.empty() && !o.default_text.empty() &&
                              o.help.find("default") == std::string::npos;
    row(left, o.help + (show_default ? " [default: " + o.default_text + "]" : ""));
  }
  row("-h, --help", "show this help and exit");
  return out;
}

}  // namespace slamrig::app
