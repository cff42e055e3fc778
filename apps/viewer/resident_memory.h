// The process's resident memory, for the viewer's soak (`lucent view --soak`).
#pragma once

#include <cstdint>

namespace lucent::viewer {

/// Makes the allocator give every block of 1 MiB or more (images, buffers, a window's
/// framebuffer) its own mapping, returned to the system when freed (glibc: a fixed mmap
/// threshold instead of the one that grows with the largest block freed). Resident memory
/// then follows what is live: otherwise a large image freed into a thread arena's top stays
/// resident (malloc_trim leaves the tops of threads' arenas), and the soak's figure moved
/// by 13 MiB between cycles depending on the order of frees. Call it before the threads
/// start; a no-op elsewhere.
void return_large_blocks_when_freed();

/// Resident set size in bytes (/proc/self/statm), taken after handing the allocator's free
/// memory back to the system (glibc's malloc_trim): freed blocks malloc keeps for reuse are
/// then not counted as memory in use, so the figure follows what the process holds. 0 where
/// /proc is missing.
uint64_t resident_bytes();

}  // namespace lucent::viewer
