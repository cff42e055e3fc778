// The kernel cache (docs/architecture.md, "The CUDA backend"): a hit loads the stored CUBIN; a corrupt or stale
// entry is detected, never loaded, and rebuilt. Needs NVRTC, not a GPU.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include <sys/stat.h>

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
    /// The kernels' folder under the cache.
    fs::path kernels() const { return dir / "kernels"; }
    /// The one CUBIN entry (beside it, `.calls` keeps its call graph).
    fs::path only_entry() const {
        std::vector<fs::path> files;
        for (auto& e : fs::directory_iterator(kernels()))
            if (e.path().extension() == ".cubin") files.push_back(e.path());
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

TEST_F(KernelCache, TheCallGraphIsKeptBesideTheBinary) {
    // f and g call each other; scale calls f: the graph ptx_calls.h reads from the PTX, and
    // the same graph from the cache's `.calls` entry on a hit.
    request.source =
        "__device__ __noinline__ int g(int x);\n"
        "__device__ __noinline__ int f(int x) { return x > 0 ? g(x - 1) * 2 : 1; }\n"
        "__device__ __noinline__ int g(int x) { return x > 0 ? f(x - 1) + 1 : 0; }\n"
        "extern \"C\" __global__ void scale(int* x) { x[threadIdx.x] = f(x[threadIdx.x]); }\n";
    auto cold = lucent::cuda::compile_cubin(request);
    ASSERT_TRUE(cold.call_graph_known);
    const lucent::cuda::PtxCallGraph expected{
        {"scale", {"_Z1fi"}}, {"_Z1fi", {"_Z1gi"}}, {"_Z1gi", {"_Z1fi"}}};
    EXPECT_EQ(cold.call_graph, expected);
    EXPECT_EQ(lucent::cuda::recursive_functions(cold.call_graph),
              (std::vector<std::string>{"_Z1fi", "_Z1gi"}));
    auto warm = lucent::cuda::compile_cubin(request);
    ASSERT_TRUE(warm.from_cache);
    ASSERT_TRUE(warm.call_graph_known);
    EXPECT_EQ(warm.call_graph, expected);
    // Without its `.calls` entry (cached before call graphs were kept) the graph is unknown.
    fs::path calls = only_entry();
    calls.replace_extension(".calls");
    ASSERT_TRUE(fs::remove(calls));
    auto older = lucent::cuda::compile_cubin(request);
    EXPECT_TRUE(older.from_cache);
    EXPECT_FALSE(older.call_graph_known);
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
    EXPECT_TRUE(!fs::exists(kernels()) || fs::is_empty(kernels()));
}

TEST_F(KernelCache, TheFolderIsPrivateAndOneOthersCanWriteIsNotUsed) {
    lucent::cuda::compile_cubin(request);
    EXPECT_EQ(fs::status(kernels()).permissions() & fs::perms::all, fs::perms::owner_all);
    fs::permissions(kernels(), fs::perms::all);  // 0777: anyone could plant an entry
    testing::internal::CaptureStderr();
    EXPECT_FALSE(lucent::cuda::compile_cubin(request).from_cache);
    EXPECT_FALSE(lucent::cuda::compile_cubin(request).from_cache);
    const std::string warning = testing::internal::GetCapturedStderr();
    EXPECT_NE(warning.find("others can write to it (mode 777; chmod 700 it)"), std::string::npos)
        << warning;
    EXPECT_EQ(warning.find("lucent:"), warning.rfind("lucent:")) << "warned once: " << warning;
}

TEST_F(KernelCache, ALinkPlantedAtTheEntryIsNeitherFollowedNorLoaded) {
    const auto cold = lucent::cuda::compile_cubin(request);
    const fs::path entry = only_entry();
    // A valid entry elsewhere, linked in: not loaded (O_NOFOLLOW).
    const fs::path elsewhere = dir / "elsewhere.cubin";
    fs::rename(entry, elsewhere);
    fs::create_symlink(elsewhere, entry);
    EXPECT_FALSE(lucent::cuda::compile_cubin(request).from_cache);
    // The rewrite replaced the link with an entry and left its target alone.
    EXPECT_FALSE(fs::is_symlink(entry));
    EXPECT_TRUE(lucent::cuda::compile_cubin(request).from_cache);
    // A link to a victim file, planted where the entry goes: the victim is never written.
    const fs::path victim = dir / "victim.txt";
    std::ofstream(victim) << "precious";
    fs::remove(entry);
    fs::create_symlink(victim, entry);
    EXPECT_EQ(lucent::cuda::compile_cubin(request).cubin, cold.cubin);
    std::ifstream in(victim);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(text, "precious");
}

TEST_F(KernelCache, AFifoOrAHeaderThatLiesIsNeverWaitedOnOrAllocated) {
    lucent::cuda::compile_cubin(request);
    const fs::path entry = only_entry();
    std::string bytes;
    {
        std::ifstream in(entry, std::ios::binary);
        bytes.assign((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    }
    // A header claiming a 1 GiB payload over a short file: refused before allocating.
    const uint64_t huge = uint64_t(1) << 30;
    std::memcpy(bytes.data() + 40, &huge, 8);
    std::ofstream(entry, std::ios::binary | std::ios::trunc) << bytes;
    EXPECT_FALSE(lucent::cuda::compile_cubin(request).from_cache);
    // A FIFO in the entry's place: not opened for a blocking read, replaced by the entry.
    fs::remove(entry);
    ASSERT_EQ(::mkfifo(entry.c_str(), 0600), 0);
    EXPECT_FALSE(lucent::cuda::compile_cubin(request).from_cache);
    EXPECT_TRUE(fs::is_regular_file(entry));
    EXPECT_TRUE(lucent::cuda::compile_cubin(request).from_cache);
}

TEST_F(KernelCache, ConcurrentColdCompilesLeaveOneValidEntryAndNoTemporaries) {
    std::vector<std::thread> threads;
    std::vector<std::string> cubins(4);
    for (int k = 0; k < 4; ++k)
        threads.emplace_back([&, k] { cubins[k] = lucent::cuda::compile_cubin(request).cubin; });
    for (auto& t : threads) t.join();
    for (const std::string& c : cubins) EXPECT_EQ(c, cubins[0]);
    only_entry();  // exactly one file: no temporary left
    EXPECT_TRUE(lucent::cuda::compile_cubin(request).from_cache);
}
#else
TEST(KernelCache, NeedsTheCudaToolkit) {
    GTEST_SKIP() << "built without the CUDA toolkit";
}
#endif

}  // namespace
