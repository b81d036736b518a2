#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace slamrig::app {

/// A small, strict command-line parser for one subcommand: `--name value`, `--name=value`,
/// boolean `--flag`, positionals, and `-h/--help`. Unknown flags, missing values, values of the
/// wrong type and missing positionals are ConfigErrors naming the command and the flag.
class ArgParser {
 public:
  /// `command` as typed ("slamrig map"), the usage line after it, and a paragraph of help.
  ArgParser(std::string command, std::string usage, std::string description);

  void AddFlag(const std::string& name, const std::string& help, bool* value);
  void AddOption(const std::string& name, const std::string& value_name, const std::string& help,
                 std::string* value);
  void AddOption(const std::string& name, const std::string& value_name, const std::string& help,
                 double* value);
  void AddOption(const std::string& name, const std::string& value_name, const std::string& help,
                 int* value);
  void AddOption(const std::string& name, const std::string& value_name, const std::string& help,
                 std::uint64_t* value);
  /// An option that may be given several times (`--set a=1 --set b=2`); values in order.
  void AddRepeated(const std::string& name, const std::string& value_name, const std::string& help,
                   std::vector<std::string>* values);
  /// A positional argument; required ones must be given.
  void AddPositional(const std::string& name, const std::string& help, std::string* value,
                     bool required = true);

  /// Parses `args` (without the program and command names). Returns false when help was asked
  /// for (and printed to stdout); throws ConfigError on a bad command line.
  bool Parse(const std::vector<std::string>& args);

  /// The help text: usage, description, positionals and options with their defaults.
  std::string Help() const;

 private:
  struct Option {
    std::string name;
    std::string value_name;  // empty for boolean flags
    std::string help;
    std::string default_text;
    std::function<void(const std::string&)> set;
  };
  struct Positional {
    std::string name;
    std::string help;
    std::string* value;
    bool required;
  };
  [[noreturn]] void Fail(const std::string& message) const;
  void AddTyped(const std::string& name, const std::string& value_name, const std::string& help,
                std::string default_text, std::function<void(const std::string&)> set);

  std::string command_;
  std::string usage_;
  std::string description_;
  std::vector<Option> options_;
  std::vector<Positional> positionals_;
};

}  // namespace slamrig::app
