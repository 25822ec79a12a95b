// LoadPhoto (digitize/) on arbitrary bytes: JPEG first (the photos' format),
// PNG when the input starts with PNG's signature.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <exception>

#include "digitize/digitize.h"
#include "fuzz/fuzz_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const bool png = size >= 4 && std::memcmp(data, "\x89PNG", 4) == 0;
  const auto path = impactlab::fuzz::WriteInput(data, size, png ? "photo.png" : "photo.jpg");
  try {
    impactlab::LoadPhoto(path);
  } catch (const std::exception&) {
  }
  return 0;
}
