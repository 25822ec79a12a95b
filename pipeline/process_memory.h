// How the process's memory allocator treats its heap: settings for a
// program's main(), not for library code (they are process-wide).
#pragma once

namespace impactlab {

// Asks the C library to keep freed memory for reuse rather than return it to
// the system. Reducing a session allocates and frees megabytes per photo (the
// decoded image, the working copies); handed back to the system each time,
// every photo's buffers are fresh pages, and faulting them in cost about
// 15 % of a reduce's CPU. Peak memory does not grow: the same buffers are
// reused. Does nothing where the C library has no such setting.
void KeepFreedMemoryForReuse();

// Backs the heap with the kernel's transparent huge pages where it offers
// them for regions that ask (Linux's `madvise` mode): every thread allocates
// from one heap, which reserves kHugeHeapReserveMiB of address space at a
// time, and the first reservation is marked MADV_HUGEPAGE. A first touch
// then maps 2 MiB at once instead of 4 KiB: on a virtual machine whose page
// faults cost 12 us each they were a third of a short reduce (2370 faults for
// the typed-in thesis). Memory is committed only as it is touched, in 2 MiB
// steps. Does nothing where the C library or the kernel has no such setting.
// Call after KeepFreedMemoryForReuse, before any thread starts.
void HeapInHugePages();

// The address space each growth of the heap reserves ahead, MiB.
inline constexpr int kHugeHeapReserveMiB = 64;

}  // namespace impactlab
