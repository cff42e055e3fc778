// The process's resident memory, for the viewer's soak (`lucent view --soak`).
#pragma once

#include <cstdint>

namespace lucent::viewer {

/// Resident set size in bytes (/proc/self/statm), taken after handing the allocator's free
/// memory back to the system (glibc's malloc_trim): freed blocks malloc keeps for reuse are
/// then not counted as memory in use, so the figure follows what the process holds. 0 where
/// /proc is missing.
uint64_t resident_bytes();

}  // namespace lucent::viewer
