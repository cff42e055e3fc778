// `lucent bench tea --backend cuda`, stream-ordered (tea_bench_cuda.h). Every row queues its
// 1 MB operations on a stream without waiting, timed by CUDA events around the whole run:
//  - into device memory: launch k writes megabyte k of one device buffer; the baseline
//    copies a 1 MB device buffer into megabyte k instead;
//  - with read-back: the same launches on one stream, and on a second stream megabyte k is
//    copied into megabyte k of pinned host memory as soon as launch k is done, so the copy
//    of one megabyte overlaps the launches after it; the baseline is the copies alone.
// The outputs are checked afterwards (untimed): an XOR fold on the GPU for device memory and
// on the host for the read-back, each equal to what the engine's launches produced.
#include "bench/tea/tea_bench_cuda.h"

#include <algorithm>
#include <vector>

#include "bench/gpu/bench_sources.h"
#include "bench/gpu/gpu_session.h"
#include "cuda/backend/device_buffer.h"
#include "lucent/error.h"

namespace lucent::cuda {

namespace {

constexpr size_t kMegabyte = size_t(1) << 20;
constexpr unsigned kBlocksPerMegabyte = unsigned(kMegabyte / sizeof(uint2));
constexpr unsigned kThreads = 256;

class Stream {
  public:
    explicit Stream(const DriverApi& api) : m_api(api) {
        check(api.cuStreamCreate(&m_stream, CU_STREAM_NON_BLOCKING), "cuStreamCreate");
    }
    ~Stream() { m_api.cuStreamDestroy(m_stream); }
    Stream(const Stream&) = delete;
    Stream& operator=(const Stream&) = delete;
    CUstream get() const { return m_stream; }

  private:
    const DriverApi& m_api;
    CUstream m_stream = nullptr;
};

/// Page-locked host memory: what a device-to-host copy can write at the link's full rate.
class PinnedHost {
  public:
    PinnedHost(const DriverApi& api, size_t bytes) : m_api(api) {
        check(api.cuMemAllocHost(&m_data, bytes), "cuMemAllocHost (pinned host memory)");
    }
    ~PinnedHost() { m_api.cuMemFreeHost(m_data); }
    PinnedHost(const PinnedHost&) = delete;
    PinnedHost& operator=(const PinnedHost&) = delete;
    unsigned char* data() const { return static_cast<unsigned char*>(m_data); }

  private:
    const DriverApi& m_api;
    void* m_data = nullptr;
};

CompileResult compile_tea_kernels(int sm) {
    return compile_cubin(bench_kernel_request(
        "lucent_bench_tea.cu", "#include \"lucent_bench/tea_kernels.cuh\"\n", {"--std=c++17"}, sm));
}

/// The median of the repeats' rates, with their spread.
TeaStreamRow summarize(std::vector<double> rates, unsigned checksum) {
    std::sort(rates.begin(), rates.end());
    TeaStreamRow row;
    row.mb_per_s = rates[rates.size() / 2];
    row.min_mb_per_s = rates.front();
    row.max_mb_per_s = rates.back();
    row.checksum = checksum;
    return row;
}

class TeaStreams {
  public:
    TeaStreams(const DriverApi& api, const ContextScope& scope, unsigned megabytes)
        : m_api(api),
          m_megabytes(megabytes),
          m_module(api, compile_tea_kernels(scope.sm()).cubin),
          m_tea(m_module.function("lucent_bench_tea")),
          m_fold(m_module.function("lucent_bench_xor_fold")),
          m_output(size_t(megabytes) * kMegabyte),
          m_source(kMegabyte),
          m_checksum(sizeof(unsigned)),
          m_host(api, size_t(megabytes) * kMegabyte),
          m_compute(api),
          m_copy(api),
          m_start(api),
          m_stop(api),
          m_generated(api) {
        m_source.fill(0x5a);
    }

    /// Launch k writes megabyte k of device memory; MB/s over all of them.
    double generate(uint4 key, unsigned rounds) {
        begin(m_compute.get());
        for (unsigned k = 0; k < m_megabytes; ++k) launch(k, key, rounds);
        return end(m_compute.get());
    }
    /// Baseline: the same bytes copied from a 1 MB device buffer instead of generated.
    double copy_device() {
        begin(m_compute.get());
        for (unsigned k = 0; k < m_megabytes; ++k)
            check(m_api.cuMemcpyDtoDAsync(megabyte(k), m_source.ptr(), kMegabyte, m_compute.get()),
                  "cuMemcpyDtoDAsync");
        return end(m_compute.get());
    }
    /// Generation with each megabyte copied into pinned host memory on the copy stream once
    /// its launch is done, while the following launches run; MB/s until the last copy.
    double generate_and_read_back(uint4 key, unsigned rounds) {
        begin(m_compute.get());
        for (unsigned k = 0; k < m_megabytes; ++k) {
            launch(k, key, rounds);
            // The wait takes the event as just recorded, so one event serves every megabyte.
            check(m_api.cuEventRecord(m_generated.get(), m_compute.get()), "cuEventRecord");
            check(m_api.cuStreamWaitEvent(m_copy.get(), m_generated.get(), 0), "cuStreamWaitEvent");
            read_back(k);
        }
        return end(m_copy.get());
    }
    /// Baseline: the device-to-host copies alone.
    double copy_to_host() {
        begin(m_copy.get());
        for (unsigned k = 0; k < m_megabytes; ++k) read_back(k);
        return end(m_copy.get());
    }

    /// XOR of every word in device memory (a fold on the GPU).
    unsigned device_checksum() {
        m_checksum.fill(0);
        CUdeviceptr words = m_output.ptr(), result = m_checksum.ptr();
        unsigned long long count = (unsigned long long)m_megabytes * kBlocksPerMegabyte;
        void* args[] = {&words, &count, &result};
        check(m_api.cuLaunchKernel(m_fold, 4096, 1, 1, kThreads, 1, 1, 0, m_compute.get(), args,
                                   nullptr),
              "fold the output");
        check(m_api.cuStreamSynchronize(m_compute.get()), "fold the output");
        unsigned value = 0;
        m_checksum.download(&value, sizeof value);
        return value;
    }
    /// XOR of every word that reached pinned host memory.
    unsigned host_checksum() const {
        const auto* words = reinterpret_cast<const uint2*>(m_host.data());
        unsigned x = 0, y = 0;
        const size_t count = size_t(m_megabytes) * kBlocksPerMegabyte;
        for (size_t i = 0; i < count; ++i) x ^= words[i].x, y ^= words[i].y;
        return x ^ y;
    }

  private:
    CUdeviceptr megabyte(unsigned k) const { return m_output.ptr() + CUdeviceptr(k) * kMegabyte; }

    void launch(unsigned k, uint4 key, unsigned rounds) {
        CUdeviceptr out = megabyte(k);
        unsigned first = k * kBlocksPerMegabyte, blocks = kBlocksPerMegabyte;
        void* args[] = {&out, &first, &blocks, &key, &rounds};
        check(m_api.cuLaunchKernel(m_tea, kBlocksPerMegabyte / kThreads, 1, 1, kThreads, 1, 1, 0,
                                   m_compute.get(), args, nullptr),
              "launch the TEA kernel");
    }
    void read_back(unsigned k) {
        check(m_api.cuMemcpyDtoHAsync(m_host.data() + size_t(k) * kMegabyte, megabyte(k), kMegabyte,
                                      m_copy.get()),
              "cuMemcpyDtoHAsync");
    }
    void begin(CUstream stream) {
        check(m_api.cuCtxSynchronize(), "cuCtxSynchronize");
        check(m_api.cuEventRecord(m_start.get(), stream), "cuEventRecord");
    }
    double end(CUstream stream) {
        check(m_api.cuEventRecord(m_stop.get(), stream), "cuEventRecord");
        check(m_api.cuEventSynchronize(m_stop.get()), "the stream-ordered run");
        float ms = 0;
        check(m_api.cuEventElapsedTime(&ms, m_start.get(), m_stop.get()), "cuEventElapsedTime");
        return m_megabytes / (double(ms) / 1000.0);
    }

    const DriverApi& m_api;
    unsigned m_megabytes;
    Module m_module;
    CUfunction m_tea, m_fold;
    DeviceBuffer m_output, m_source, m_checksum;
    PinnedHost m_host;
    Stream m_compute, m_copy;
    Event m_start, m_stop, m_generated;
};

}  // namespace

TeaStreamResult run_tea_stream_cuda(const TeaStreamInput& input) {
    if (input.megabytes > kTeaStreamMaxMegabytes)
        throw Error("bench tea --backend cuda: --megabytes " + std::to_string(input.megabytes) +
                    ": the stream-ordered rows hold the whole output in device and pinned host "
                    "memory, at most " + std::to_string(kTeaStreamMaxMegabytes) +
                    " MB; give --megabytes " + std::to_string(kTeaStreamMaxMegabytes) + " or less");
    const DriverApi& api = require_bench_driver();
    ContextScope scope(api);
    TeaStreams streams(api, scope, input.megabytes);
    // Warm-up, untimed: the first launches and copies (module load, first-touch of memory).
    streams.generate(input.fixed_key, input.rounds);
    streams.generate_and_read_back(input.fixed_key, input.rounds);

    const int repeat = std::max(1, input.repeat);
    std::vector<double> rates[6];
    unsigned sums[6] = {};
    for (int r = 0; r < repeat; ++r) {
        // The rows take turns, so drift in the machine's speed falls on all alike.
        rates[0].push_back(streams.generate(input.fixed_key, input.rounds));
        if (r == 0) sums[0] = streams.device_checksum();
        rates[1].push_back(streams.generate(input.generated_key, input.rounds));
        if (r == 0) sums[1] = streams.device_checksum();
        rates[2].push_back(streams.copy_device());
        rates[3].push_back(streams.generate_and_read_back(input.fixed_key, input.rounds));
        if (r == 0) sums[3] = streams.host_checksum();
        rates[4].push_back(streams.generate_and_read_back(input.generated_key, input.rounds));
        if (r == 0) sums[4] = streams.host_checksum();
        rates[5].push_back(streams.copy_to_host());
    }
    TeaStreamResult result;
    result.device = scope.name();
    result.repeat = repeat;
    result.device_fixed = summarize(rates[0], sums[0]);
    result.device_generated = summarize(rates[1], sums[1]);
    result.device_copy = summarize(rates[2], 0);
    result.readback_fixed = summarize(rates[3], sums[3]);
    result.readback_generated = summarize(rates[4], sums[4]);
    result.readback_copy = summarize(rates[5], 0);
    return result;
}

}  // namespace lucent::cuda
