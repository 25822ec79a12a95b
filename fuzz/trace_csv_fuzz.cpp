// ParseTraceCsv (ReadTraceCsv's parser, io/trace.h) on arbitrary bytes.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <sstream>
#include <string>

#include "io/trace.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    impactlab::ParseTraceCsv(in, "fuzz.csv");
  } catch (const std::exception&) {
  }
  return 0;
}
