// The checksums of the BENCH.md ray sets, and how two engines' checksums are compared.
#pragma once

#include <cstddef>
#include <string>

namespace lucent::bench {

struct RayChecksums {
    size_t primary_hits = 0, shadow_rays = 0, occluded = 0, diffuse_rays = 0, diffuse_hits = 0;
    double primary_sum_t = 0, diffuse_sum_t = 0;
};

/// The checksums that differ between engines a and b, as text naming each ("" when they
/// agree): counts must be equal, sums of t within 1e-6 relative (BENCH.md).
std::string checksum_differences(const RayChecksums& a, const RayChecksums& b, const char* a_name,
                                 const char* b_name);

}  // namespace lucent::bench
