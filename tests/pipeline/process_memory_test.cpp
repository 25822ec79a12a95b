// The heap in transparent huge pages (pipeline/process_memory.h): where the
// kernel offers them for regions that ask, the heap's first reservation asks.
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <catch2/catch.hpp>

#include "pipeline/process_memory.h"

namespace impactlab {
namespace {

// The "VmFlags:" line of the mapping holding `address` in /proc/self/smaps
// ("" when none holds it).
std::string VmFlagsAt(std::uintptr_t address) {
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    std::uintptr_t from = 0, to = 0;
    char dash = 0;
    std::istringstream range(line);
    if (range >> std::hex >> from >> dash >> to && dash == '-') {
      inside = from <= address && address < to;
    } else if (inside && line.starts_with("VmFlags:")) {
      return line;
    }
  }
  return "";
}

// Whether this kernel has transparent huge pages, and not switched off.
bool KernelOffersHugePages() {
  std::ifstream mode("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string text;
  std::getline(mode, text);
  return mode && text.find("[never]") == std::string::npos;
}

TEST_CASE("process_memory: a block from the heap lies in pages marked for huge pages") {
  if (!KernelOffersHugePages()) {
    SUCCEED("no transparent huge pages on this kernel: nothing to check");
    return;
  }
  KeepFreedMemoryForReuse();  // a block of megabytes from the heap, not a mapping of its own
  HeapInHugePages();
  constexpr std::size_t kBlock = std::size_t{8} << 20;
  void* volatile block = std::malloc(kBlock);
  REQUIRE(block != nullptr);
  // Its last megabyte: past the unaligned start of the reservation.
  const auto last_megabyte = reinterpret_cast<std::uintptr_t>(block) + kBlock - (1u << 20);
  const std::string flags = VmFlagsAt(last_megabyte);
  std::free(block);
  INFO(flags);
  CHECK(flags.find(" hg") != std::string::npos);  // MADV_HUGEPAGE's flag
}

}  // namespace
}  // namespace impactlab
