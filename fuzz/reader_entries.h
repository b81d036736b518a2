#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace slamrig::fuzz {

/// What a reader made of one input.
enum class ReaderOutcome {
  kAccepted,  ///< the reader returned a result and the result passed its checks
  kRejected,  ///< the reader threw slamrig::ParseError or slamrig::ConfigError
};

/// The outcome of one input, with the rejection's message (empty when accepted).
struct ReaderResult {
  ReaderOutcome outcome = ReaderOutcome::kAccepted;
  std::string message;
};

/// One reader of outside data as the fuzz targets and the regression test drive it.
struct ReaderEntry {
  /// Target name: fuzz/corpus/<name>/, fuzz/regressions/<name>/ and the binary fuzz_<name>.
  std::string name;
  /// Hands `data` to the reader (through files in the ScratchDir) and checks the result's
  /// invariants. May throw ParseError/ConfigError (a clean rejection); anything else escaping
  /// it is a bug: std::logic_error for a broken invariant, or whatever the reader leaked.
  void (*run)(std::string_view data);
  /// How the bytes are laid out, for people writing corpus files.
  std::string input_format;
};

/// Every reader of outside data: carmen, npz, ece276a_csv, tum, map_server, world_yaml,
/// robot_yaml, scenario_yaml, sweep_yaml, bag.
const std::vector<ReaderEntry>& ReaderEntries();

/// The entry named `name`, or nullptr.
const ReaderEntry* FindReaderEntry(std::string_view name);

/// Runs `entry` on `data`: kAccepted, or kRejected when the reader threw ParseError or
/// ConfigError. Every other exception propagates to the caller (a fuzzer reports it as a crash).
ReaderResult RunReaderEntry(const ReaderEntry& entry, std::string_view data);

/// The part of a two-file input before the first NUL byte (all of it when there is none).
std::string_view FirstPart(std::string_view data);
/// The part after the first NUL byte (empty when there is none).
std::string_view SecondPart(std::string_view data);

}  // namespace slamrig::fuzz
