// libFuzzer entry point, built once per reader (fuzz_<name>, with SLAMRIG_FUZZ_ENTRY="<name>").
// A clean rejection (ParseError/ConfigError) is a normal outcome; any other exception escapes
// and aborts, which libFuzzer reports as a crash with the input that caused it.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "fuzz/reader_entries.h"

namespace {

const slamrig::fuzz::ReaderEntry& Entry() {
  static const slamrig::fuzz::ReaderEntry* entry = [] {
    const auto* found = slamrig::fuzz::FindReaderEntry(SLAMRIG_FUZZ_ENTRY);
    if (found == nullptr) {
      std::fprintf(stderr, "no reader entry named %s\n", SLAMRIG_FUZZ_ENTRY);
      std::abort();
    }
    return found;
  }();
  return *entry;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  slamrig::fuzz::RunReaderEntry(Entry(),
                                std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}
