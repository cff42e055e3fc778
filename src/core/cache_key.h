// The key of an on-disk cache entry (GPU kernels, CPU modules compiled at run time): a hash
// of everything that decides the entry's contents.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

namespace lucent::core {

/// 128-bit FNV-1a as two 64-bit lanes with different offsets: a cache key, not security.
/// Each add() ends with a separator, so ("ab", "c") and ("a", "bc") differ.
struct CacheKey {
    uint64_t a = 1469598103934665603ull, b = 0x84222325cbf29ce4ull;
    void add(std::string_view s) {
        for (unsigned char c : s) {
            a = (a ^ c) * 1099511628211ull;
            b = (b ^ c) * 0x100000001b3ull + 0x9e3779b97f4a7c15ull;
        }
        a = (a ^ 0xff) * 1099511628211ull;
    }
    /// 32 hexadecimal digits.
    std::string hex() const {
        char s[33];
        std::snprintf(s, sizeof s, "%016llx%016llx", (unsigned long long)a, (unsigned long long)b);
        return s;
    }
};

}  // namespace lucent::core
