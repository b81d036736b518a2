// `slamrig_fuzz_replay TARGET FILE...`: runs files through a reader entry as the fuzz target
// would, without libFuzzer, and prints what the reader made of each (for triage and for
// checking that seeds get past the parsers). Exits 1 if any file escaped the contract.
#include <cstdio>
#include <exception>
#include <fstream>
#include <iterator>
#include <string>

#include "fuzz/reader_entries.h"

int main(int argc, char** argv) {
  if (argc < 3 || slamrig::fuzz::FindReaderEntry(argv[1]) == nullptr) {
    std::fprintf(stderr, "usage: %s TARGET FILE...; targets:", argv[0]);
    for (const auto& entry : slamrig::fuzz::ReaderEntries()) {
      std::fprintf(stderr, " %s", entry.name.c_str());
    }
    std::fprintf(stderr, "\n");
    return 2;
  }
  const slamrig::fuzz::ReaderEntry& entry = *slamrig::fuzz::FindReaderEntry(argv[1]);
  int bugs = 0;
  for (int i = 2; i < argc; ++i) {
    std::ifstream in(argv[i], std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    try {
      const slamrig::fuzz::ReaderResult result = slamrig::fuzz::RunReaderEntry(entry, bytes);
      if (result.outcome == slamrig::fuzz::ReaderOutcome::kAccepted) {
        std::printf("accepted %s\n", argv[i]);
      } else {
        std::printf("rejected %s: %s\n", argv[i], result.message.c_str());
      }
    } catch (const std::exception& e) {
      ++bugs;
      std::printf("BUG      %s: %s\n", argv[i], e.what());
    }
  }
  return bugs > 0 ? 1 : 0;
}
