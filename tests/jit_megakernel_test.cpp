// The GPU path must never silently stop compiling: for every sample, generate the CUDA
// megakernel of its scene and compile it with NVRTC for sm_90 (no GPU needed).
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "samples/sample.h"

namespace {

/// Renders `sample` at 8x8 on the CPU with its megakernel also compiled for sm_90.
lucent::samples::RenderResult render_with_jit_check(const lucent::samples::Sample& sample) {
    lucent::samples::RenderSettings settings;
    settings.width = 8;
    settings.height = 8;
    settings.backend = lucent::BackendKind::kCpu;
    settings.jit_check_sm = 90;
    return sample.render(settings);
}

TEST(jit, EverySampleMegakernelCompilesForSm90) {
#if !LUCENT_HAVE_CUDA
    GTEST_SKIP() << "built without the CUDA toolkit: no megakernel to compile";
#else
    ::setenv("LUCENT_CACHE_DIR", "off", 1);  // a real NVRTC compile, not a cache hit
    for (const lucent::samples::Sample* sample : lucent::samples::all_samples()) {
        lucent::samples::RenderResult result;
        ASSERT_NO_THROW(result = render_with_jit_check(*sample)) << sample->name;
        EXPECT_GT(result.report.jit_ms, 0.0) << sample->name << ": no megakernel was compiled";
        EXPECT_FALSE(result.report.jit_cached) << sample->name;
    }
#endif
}

TEST(jit, TheLaneRefillVariantCompilesForSm90) {
#if !LUCENT_HAVE_CUDA
    GTEST_SKIP() << "built without the CUDA toolkit: no megakernel to compile";
#else
    // The CUDA backend compiles this variant only on a GPU, in the background; here it must
    // compile too. The samples whose traces do not recurse get it (the others would unroll
    // their recursion when trace() is inlined).
    ::setenv("LUCENT_CACHE_DIR", "off", 1);
    ::setenv("LUCENT_NVRTC_OPTIONS", "-DLUCENT_GPU_INLINE_TRACE=1 -DLUCENT_GPU_LANE_REFILL=1", 1);
    int compiled = 0;
    for (const lucent::samples::Sample* sample : lucent::samples::all_samples()) {
        if (sample->name != std::string("direct") && sample->name != std::string("pathtracer"))
            continue;
        lucent::samples::RenderResult result;
        ASSERT_NO_THROW(result = render_with_jit_check(*sample)) << sample->name;
        EXPECT_GT(result.report.jit_ms, 0.0) << sample->name;
        ++compiled;
    }
    ::unsetenv("LUCENT_NVRTC_OPTIONS");
    EXPECT_EQ(compiled, 2);
#endif
}

}  // namespace
