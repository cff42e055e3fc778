#include "resident_memory.h"

#include <unistd.h>

#include <fstream>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace lucent::viewer {

void return_large_blocks_when_freed() {
#if defined(__GLIBC__)
    mallopt(M_MMAP_THRESHOLD, 1 << 20);
#endif
}

uint64_t resident_bytes() {
#if defined(__GLIBC__)
    malloc_trim(0);  // every arena's free pages, not only the top of the main heap
#endif
    std::ifstream statm("/proc/self/statm");
    uint64_t pages = 0, resident = 0;
    statm >> pages >> resident;
    return resident * uint64_t(::sysconf(_SC_PAGESIZE));
}

}  // namespace lucent::viewer
