#include "resident_memory.h"

#include <unistd.h>

#include <fstream>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace lucent::viewer {

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
