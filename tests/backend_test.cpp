// Backend choice: `auto` takes the GPU when a driver and device answer, else the CPU with a
// notice; `cuda` without a usable GPU is a clear error; `cpu` never touches the driver.
#include <gtest/gtest.h>

#include "lucent/context.h"
#if LUCENT_HAVE_CUDA
#include "cuda/backend/driver_api.h"
#endif

namespace {

bool gpu_answers() {
#if LUCENT_HAVE_CUDA
    return lucent::cuda::driver() != nullptr;
#else
    return false;
#endif
}

TEST(Backend, CpuIsAlwaysTheCpu) {
    lucent::Context ctx(lucent::ContextOptions{lucent::BackendKind::kCpu, 2});
    EXPECT_EQ(ctx.backend_name(), "cpu (2 threads)");
    EXPECT_TRUE(ctx.backend_notice().empty());
}

TEST(Backend, AutoFallsBackToTheCpuWithANoticeWithoutAGpu) {
    lucent::Context ctx(lucent::ContextOptions{lucent::BackendKind::kAuto, 1});
    if (gpu_answers()) {
        EXPECT_EQ(ctx.backend_name().rfind("cuda", 0), 0u) << ctx.backend_name();
        EXPECT_TRUE(ctx.backend_notice().empty());
    } else {
        EXPECT_EQ(ctx.backend_name(), "cpu (1 thread)");
        EXPECT_NE(ctx.backend_notice().find("running on the CPU"), std::string::npos)
            << ctx.backend_notice();
    }
}

TEST(Backend, CudaWithoutAGpuIsAClearError) {
    if (gpu_answers()) GTEST_SKIP() << "a GPU answers here";
    try {
        lucent::Context ctx(lucent::ContextOptions{lucent::BackendKind::kCuda});
        FAIL() << "expected lucent::Error";
    } catch (const lucent::Error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("CUDA backend"), std::string::npos) << what;
        EXPECT_NE(what.find("--backend cpu"), std::string::npos) << what;
    }
}

}  // namespace
