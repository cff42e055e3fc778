// An allocator for the arrays a traversal reads at random, the wide nodes and the triangle
// blocks. Arrays of a megabyte or more are aligned to 2 MiB and offered to the kernel for
// transparent huge pages (madvise; Linux's default THP mode only backs regions asked for
// this way), so a tree of a few megabytes sits in a few TLB entries instead of a thousand
// 4 KiB pages. Where huge pages are not available it is an aligned allocator, no more.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <limits>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace lucent::accel {

template <class T>
struct HugePageAllocator {
    using value_type = T;
    static constexpr size_t kHugePage = size_t(2) << 20;

    HugePageAllocator() = default;
    template <class U>
    HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

    T* allocate(size_t n) {
        if (n > std::numeric_limits<size_t>::max() / sizeof(T)) throw std::bad_array_new_length();
        const size_t bytes = n * sizeof(T);
        if (!is_huge(bytes))
            return static_cast<T*>(::operator new(bytes, std::align_val_t(alignof(T))));
        const size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
        void* p = std::aligned_alloc(kHugePage, rounded);
        if (!p) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
        madvise(p, rounded, MADV_HUGEPAGE);  // a hint: failure leaves ordinary pages
#endif
        return static_cast<T*>(p);
    }

    void deallocate(T* p, size_t n) noexcept {
        if (is_huge(n * sizeof(T)))
            std::free(p);
        else
            ::operator delete(p, std::align_val_t(alignof(T)));
    }

    template <class U>
    bool operator==(const HugePageAllocator<U>&) const noexcept {
        return true;
    }

  private:
    static bool is_huge(size_t bytes) {
        return bytes >= kHugePage / 2;
    }
};

}  // namespace lucent::accel
