// The choice of the traversal's instruction-set variant (cpu_isa.h). cmake/isa_variants.cmake
// defines LUCENT_ISA_HAVE_AVX2 and LUCENT_ISA_HAVE_AVX512 here when it builds those variants.
#include "accel/cpu_isa.h"

#include <cstdio>
#include <cstdlib>

#include "accel/triangle_traverse.h"

namespace lucent::accel {

namespace {

/// The variants are compiled for the x86-64 micro-architecture levels (x86-64-v3: AVX2,
/// FMA, BMI1/2, LZCNT, MOVBE, F16C; x86-64-v4: v3 and AVX-512 F, VL, BW, DQ, CD), so the
/// check is for the whole level. libgcc's check includes the OS's consent (XCR0) for the
/// AVX and AVX-512 register state.
[[maybe_unused]] bool cpu_has_level([[maybe_unused]] int level) {
#if defined(__x86_64__)
    __builtin_cpu_init();  // in case the first query runs in a static constructor
#if !defined(__clang__) && __GNUC__ >= 12
    return level == 3 ? __builtin_cpu_supports("x86-64-v3") : __builtin_cpu_supports("x86-64-v4");
#else
    // Compilers without the level names: these features imply the rest of each level on
    // every CPU made.
    const bool v3 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
                    __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2");
    if (level == 3) return v3;
    return v3 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
           __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq") &&
           __builtin_cpu_supports("avx512cd");
#endif
#else
    return false;
#endif
}

CpuIsa best_supported() {
    CpuIsa best = CpuIsa::kScalar;
    for (CpuIsa isa : kCpuIsas)
        if (cpu_isa_supported(isa)) best = isa;
    return best;
}

CpuIsa choose() {
    const CpuIsa best = best_supported();
    const char* env = std::getenv("LUCENT_CPU_ISA");
    if (!env || !*env) return best;
    const std::optional<CpuIsa> asked = parse_cpu_isa(env);
    if (!asked) {
        std::fprintf(stderr,
                     "lucent: LUCENT_CPU_ISA=%s is none of scalar, avx2, avx512; using %s\n", env,
                     cpu_isa_name(best));
        return best;
    }
    if (!cpu_isa_supported(*asked)) {
        std::fprintf(stderr,
                     "lucent: LUCENT_CPU_ISA=%s: this build or this CPU lacks it; using %s\n", env,
                     cpu_isa_name(best));
        return best;
    }
    return *asked;
}

}  // namespace

const char* cpu_isa_name(CpuIsa isa) {
    switch (isa) {
        case CpuIsa::kScalar:
            return "scalar";
        case CpuIsa::kAvx2:
            return "avx2";
        case CpuIsa::kAvx512:
            return "avx512";
    }
    return "?";
}

std::optional<CpuIsa> parse_cpu_isa(std::string_view name) {
    for (CpuIsa isa : kCpuIsas)
        if (name == cpu_isa_name(isa)) return isa;
    return std::nullopt;
}

bool cpu_isa_supported(CpuIsa isa) {
    switch (isa) {
        case CpuIsa::kScalar:
            return true;
#ifdef LUCENT_ISA_HAVE_AVX2
        case CpuIsa::kAvx2:
            return cpu_has_level(3);
#endif
#ifdef LUCENT_ISA_HAVE_AVX512
        case CpuIsa::kAvx512:
            return cpu_has_level(4);
#endif
        default:
            return false;
    }
}

CpuIsa active_cpu_isa() {
    static const CpuIsa isa = choose();
    return isa;
}

const TraverseVariant& traverse_variant(CpuIsa isa) {
    switch (isa) {
#ifdef LUCENT_ISA_HAVE_AVX2
        case CpuIsa::kAvx2:
            return isa_avx2::kTraverse;
#endif
#ifdef LUCENT_ISA_HAVE_AVX512
        case CpuIsa::kAvx512:
            return isa_avx512::kTraverse;
#endif
        default:
            return isa_scalar::kTraverse;
    }
}

}  // namespace lucent::accel
