#include "bench/common/option_checks.h"

#include <string>

#include "lucent/error.h"

namespace lucent::bench {

void require_in_range(const char* command, const char* option, long long value, long long low,
                      long long high) {
    if (value >= low && value <= high) return;
    throw Error(std::string(command) + ": " + option + " is " + std::to_string(value) +
                "; it must lie in [" + std::to_string(low) + ", " + std::to_string(high) + "]");
}

void require_image_size(const char* command, unsigned width, unsigned height) {
    constexpr unsigned kMostPixelsASide = 65536;
    if (width >= 1 && height >= 1 && width <= kMostPixelsASide && height <= kMostPixelsASide)
        return;
    throw Error(std::string(command) + ": the image size (size, --size) is " +
                std::to_string(width) + "x" + std::to_string(height) +
                "; each side must lie in [1, 65536]");
}

}  // namespace lucent::bench
