#include "pipeline/process_memory.h"

#include <cstdint>
#include <cstdlib>  // defines __GLIBC__ on the GNU C library

#if defined(__GLIBC__)
#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace impactlab {

void KeepFreedMemoryForReuse() {
#if defined(__GLIBC__)
  // Blocks up to 32 MiB (a 16-bit colour photo of 5 megapixels) come from the
  // heap instead of mappings of their own, and up to 256 MiB of free heap is
  // kept rather than trimmed.
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
#endif
}

void HeapInHugePages() {
#if defined(__GLIBC__) && defined(MADV_HUGEPAGE)
  // One heap: the worker threads' own arenas would be fresh mappings of
  // small pages (and, with one heap, the photo sample's peak memory is 54
  // MiB rather than 62).
  mallopt(M_ARENA_MAX, 1);
  mallopt(M_TOP_PAD, kHugeHeapReserveMiB << 20);
  // A block larger than the heap's free top makes it grow now, by the block
  // and the reserve; freed, it stays (KeepFreedMemoryForReuse). Volatile: a
  // malloc freed unused may otherwise be left out by the compiler.
  char* const before = static_cast<char*>(sbrk(0));
  void* volatile block = std::malloc(std::size_t{1} << 20);
  char* const after = static_cast<char*>(sbrk(0));
  std::free(block);
  // The whole huge pages inside the growth; none where the heap did not
  // grow by sbrk (the C library then maps its memory elsewhere).
  constexpr std::uintptr_t kHuge = std::uintptr_t{2} << 20;
  const std::uintptr_t from =
      (reinterpret_cast<std::uintptr_t>(before) + kHuge - 1) / kHuge * kHuge;
  const std::uintptr_t to = reinterpret_cast<std::uintptr_t>(after) / kHuge * kHuge;
  // A kernel without transparent huge pages refuses (EINVAL): nothing lost.
  if (to > from)
    static_cast<void>(madvise(reinterpret_cast<void*>(from), to - from, MADV_HUGEPAGE));
#endif
}

}  // namespace impactlab
