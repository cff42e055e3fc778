// Which instruction-set variant of the CPU triangle traversal runs (triangle_traverse.h):
// the best one this build has and this CPU supports, chosen at the first query, unless the
// environment variable LUCENT_CPU_ISA=scalar|avx2|avx512 asks for another (for tests and
// comparisons; a variant the CPU lacks is refused with a warning, as it would crash).
#pragma once

#include <optional>
#include <string_view>

namespace lucent::accel {

struct TraverseVariant;

enum class CpuIsa { kScalar, kAvx2, kAvx512 };  // in rising order
inline constexpr CpuIsa kCpuIsas[] = {CpuIsa::kScalar, CpuIsa::kAvx2, CpuIsa::kAvx512};

/// "scalar", "avx2", "avx512": the names LUCENT_CPU_ISA and `lucent bench rays` use.
const char* cpu_isa_name(CpuIsa isa);
std::optional<CpuIsa> parse_cpu_isa(std::string_view name);

/// True when this build has the variant and this CPU (and OS) can run it.
bool cpu_isa_supported(CpuIsa isa);

/// The variant TriangleAccel's queries use in this process (fixed at the first call).
CpuIsa active_cpu_isa();

/// A variant's entry points, to call one directly (tests); only for supported variants.
const TraverseVariant& traverse_variant(CpuIsa isa);

}  // namespace lucent::accel
