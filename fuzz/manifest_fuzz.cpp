// ParseManifest on arbitrary text: it must return or throw InputError /
// std::exception, never crash, hang or exhaust memory.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <string>

#include "io/manifest.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    // Paths resolve against a folder that does not exist: file checks fail
    // cleanly, the parsing and validation before them are what is fuzzed.
    impactlab::ParseManifest(text, "/nonexistent-impactlab-fuzz/session.toml");
  } catch (const std::exception&) {
  }
  return 0;
}
