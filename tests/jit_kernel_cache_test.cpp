// The kernel cache (docs/architecture.md, "The CUDA backend"): a hit loads the stored CUBIN; a corrupt or stale
// entry is detected, never loaded, and rebuilt. Needs NVRTC, not a GPU.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#if LUCENT_HAVE_CUDA
#include "cuda/jit/nvrtc_compiler.h"
#endif

namespace {

#if LUCENT_HAVE_CUDA
namespace fs = std::filesystem;

class KernelCache : public ::testing::Test {
  protected:
    void SetUp() override {
        dir = fs::temp_directory_path() / ("lucent-cache-test-" + std::to_string(::getpid()));
        fs::remove_all(dir);
        ::setenv("LUCENT_CACHE_DIR", dir.c_str(), 1);
        request.name = "cache_test.cu";
        request.source =
            "extern \"C\" __global__ void scale(float* x) { x[threadIdx.x] *= 2.0f; }\n";
        request.sm = 90;
    }
    void TearDown() override {
        fs::remove_all(dir);
        ::unsetenv("LUCENT_CACHE_DIR");
    }
    fs::path only_entry() const {
        std::vector<fs::path> files;
        for (auto& e : fs::directory_iterator(dir)) files.push_back(e.path());
        EXPECT_EQ(files.size(), 1u);
        return files.empty() ? fs::path() : files[0];
    }
    fs::path dir;
    lucent::cuda::CompileRequest request;
};

TEST_F(KernelCache, SecondCompileIsAHitWithTheSameBinary) {
    auto cold = lucent::cuda::compile_cubin(request);
    EXPECT_FALSE(cold.from_cache);
    ASSERT_FALSE(cold.cubin.empty());
    auto warm = lucent::cuda::compile_cubin(request);
    EXPECT_TRUE(warm.from_cache);
    EXPECT_EQ(warm.cubin, cold.cubin);
}

TEST_F(KernelCache, CorruptEntryIsRebuiltNotLoaded) {
    auto cold = lucent::cuda::compile_cubin(request);
    const fs::path entry = only_entry();
    {  // flip a byte in the middle of the stored binary
        std::fstream f(entry, std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(std::streamoff(fs::file_size(entry) / 2));
        f.put('\x5a' ^ char(f.peek()));
    }
    auto again = lucent::cuda::compile_cubin(request);
    EXPECT_FALSE(again.from_cache) << "a corrupt entry must not be loaded";
    EXPECT_EQ(again.cubin, cold.cubin);
    EXPECT_TRUE(lucent::cuda::compile_cubin(request).from_cache) << "the entry was rewritten";
}

TEST_F(KernelCache, TruncatedEntryIsRebuilt) {
    lucent::cuda::compile_cubin(request);
    const fs::path entry = only_entry();
    fs::resize_file(entry, fs::file_size(entry) / 3);
    EXPECT_FALSE(lucent::cuda::compile_cubin(request).from_cache);
}

TEST_F(KernelCache, ChangedSourceOrOptionsMissTheCache) {
    lucent::cuda::compile_cubin(request);
    auto other = request;
    other.options.push_back("-DLUCENT_OTHER=1");
    EXPECT_FALSE(lucent::cuda::compile_cubin(other).from_cache);
    other = request;
    other.sm = 80;
    EXPECT_FALSE(lucent::cuda::compile_cubin(other).from_cache);
}

TEST_F(KernelCache, CompileErrorNamesTheFileAndKeepsNothing) {
    request.source = "extern \"C\" __global__ void broken() { undeclared_name = 1; }\n";
    try {
        lucent::cuda::compile_cubin(request);
        FAIL() << "expected a compile error";
    } catch (const std::exception& e) {
        EXPECT_NE(std::string(e.what()).find("cache_test.cu"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("undeclared_name"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(!fs::exists(dir) || fs::is_empty(dir));
}
#else
TEST(KernelCache, NeedsTheCudaToolkit) {
    GTEST_SKIP() << "built without the CUDA toolkit";
}
#endif

}  // namespace
