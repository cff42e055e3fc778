// Sebald's Table 2: TEA output in 1 MB launches, each read back, with the fixed key, the
// generated key and a plain copy taking turns; on the GPU, also the same output
// stream-ordered against the hardware's copy rates (tea_bench_cuda.h).
#include "bench/tea/tea_bench.h"

#include <array>
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bench/common/option_checks.h"
#include "bench/common/report.h"
#include "bench/tea/tea_bench_cuda.h"
#include "lucent/error.h"
#include "samples/tea/tea_programs.h"

namespace lucent::bench {

namespace {
constexpr unsigned kBlocksPerMegabyte = (1u << 20) / sizeof(uint2);

struct VariantResult {
    double seconds = 0;
    unsigned checksum = 0;  // XOR of every output word, so the work cannot be skipped
};

using Clock = std::chrono::steady_clock;

/// `megabytes` rounds of one 1 MB launch per entry (fixed key, generated key, copy), each read
/// back to the host and folded into a checksum; each entry's time is summed apart. The
/// variants take turns, so drift in the machine's speed falls on all three alike. The
/// launch's first block number is data in a buffer, not a variable: changing a variable
/// recompiles the scene, changing a buffer only uploads it.
std::array<VariantResult, 3> run_variants(Context& ctx, const std::shared_ptr<Buffer>& out,
                                          const std::shared_ptr<Buffer>& first_block,
                                          unsigned megabytes,
                                          const std::function<void(unsigned)>& progress) {
    std::array<VariantResult, 3> r;
    first_block->upload(std::vector<unsigned>{0u});
    // Warm-up, untimed: the compile, the JIT and the CUDA backend's launch-shape trials
    // (its first three launches of each entry).
    for (unsigned entry = 0; entry < 3; ++entry)
        for (int i = 0; i < 3; ++i) ctx.launch(entry, kBlocksPerMegabyte);
    for (unsigned mb = 0; mb < megabytes; ++mb)
        for (unsigned entry = 0; entry < 3; ++entry) {
            const Clock::time_point start = Clock::now();
            first_block->upload(std::vector<unsigned>{mb * kBlocksPerMegabyte});
            ctx.launch(entry, kBlocksPerMegabyte);
            const uint2* words = out->data<uint2>();  // the 1 MB reaches the host, as in the seed
            for (unsigned i = 0; i < kBlocksPerMegabyte; ++i)
                r[entry].checksum ^= words[i].x ^ words[i].y;
            r[entry].seconds += std::chrono::duration<double>(Clock::now() - start).count();
            if (progress) progress(3 * mb + entry + 1);
        }
    return r;
}

/// What `lucent bench tea` measured: fixed key, generated key, copy; on the GPU also the
/// stream-ordered rows.
struct TeaResult {
    const TeaBenchOptions* options = nullptr;
    std::string backend, notice;
    std::array<VariantResult, 3> variants;
    std::optional<cuda::TeaStreamResult> stream;
};

std::string hex8(unsigned value) {
    char buf[9];
    std::snprintf(buf, sizeof buf, "%08x", value);
    return buf;
}

Json row_json(const cuda::TeaStreamRow& row) {
    Json j{{"mb_per_s", rounded(row.mb_per_s, 1)},
           {"min_mb_per_s", rounded(row.min_mb_per_s, 1)},
           {"max_mb_per_s", rounded(row.max_mb_per_s, 1)}};
    if (row.checksum) j["checksum"] = hex8(row.checksum);
    return j;
}

Json stream_json(const cuda::TeaStreamResult& s) {
    return Json{{"device", s.device},
                {"repeat", s.repeat},
                {"device_memory",
                 {{"fixed_key", row_json(s.device_fixed)},
                  {"generated_key", row_json(s.device_generated)},
                  {"device_to_device_copy", row_json(s.device_copy)}}},
                {"read_back",
                 {{"fixed_key", row_json(s.readback_fixed)},
                  {"generated_key", row_json(s.readback_generated)},
                  {"pinned_device_to_host_copy", row_json(s.readback_copy)}}}};
}

Json to_json(const TeaResult& r) {
    const TeaBenchOptions& o = *r.options;
    const double mb = o.megabytes;
    const VariantResult &fixed = r.variants[0], &device = r.variants[1], &copy = r.variants[2];
    return Json{{"backend", r.backend},
                {"megabytes", o.megabytes},
                {"rounds", o.rounds},
                {"fixed_key_mb_per_s", rounded(mb / fixed.seconds, 1)},
                {"generated_key_mb_per_s", rounded(mb / device.seconds, 1)},
                {"copy_mb_per_s", rounded(mb / copy.seconds, 1)},
                {"fixed_checksum", hex8(fixed.checksum)},
                {"generated_checksum", hex8(device.checksum)},
                {"stream_ordered", r.stream ? stream_json(*r.stream) : Json(nullptr)}};
}

void print_text(const TeaResult& r) {
    const TeaBenchOptions& options = *r.options;
    const double mb = options.megabytes;
    const VariantResult &fixed = r.variants[0], &device = r.variants[1], &copy = r.variants[2];
    if (!r.notice.empty()) std::printf("note: %s\n", r.notice.c_str());
    std::printf("tea: %u MB in 1 MB launches, each read back, %u rounds, on %s\n",
                options.megabytes, options.rounds, r.backend.c_str());
    std::printf("fixed key      %9.1f MB/s  %5.1f%% of copy  (%.3f s, checksum %08x)\n",
                mb / fixed.seconds, 100.0 * copy.seconds / fixed.seconds, fixed.seconds,
                fixed.checksum);
    std::printf(
        "generated key  %9.1f MB/s  %5.1f%% of copy  (%.3f s, checksum %08x; device %u, "
        "seed %u)\n",
        mb / device.seconds, 100.0 * copy.seconds / device.seconds, device.seconds, device.checksum,
        options.device, options.seed);
    std::printf("copy           %9.1f MB/s  the same launches copying a 1 MB device buffer\n",
                mb / copy.seconds);
    if (!r.stream) return;
    const cuda::TeaStreamResult& s = *r.stream;
    auto line = [](const char* name, const cuda::TeaStreamRow& row, const cuda::TeaStreamRow& base) {
        std::printf("  %-30s %10.1f MB/s  (%.1f-%.1f)", name, row.mb_per_s, row.min_mb_per_s,
                    row.max_mb_per_s);
        if (&row != &base) std::printf("  %5.1f%% of the copy", 100.0 * row.mb_per_s / base.mb_per_s);
        std::printf("\n");
    };
    std::printf("stream-ordered on %s: %u launches of 1 MB queued without a host round trip, "
                "CUDA events, median of %d (min-max)\n",
                s.device.c_str(), options.megabytes, s.repeat);
    std::printf(" into device memory\n");
    line("fixed key", s.device_fixed, s.device_copy);
    line("generated key", s.device_generated, s.device_copy);
    line("device-to-device copy, 1 MB", s.device_copy, s.device_copy);
    std::printf(" read back into pinned host memory, overlapping the next launches\n");
    line("fixed key", s.readback_fixed, s.readback_copy);
    line("generated key", s.readback_generated, s.readback_copy);
    line("pinned device-to-host copy, 1 MB", s.readback_copy, s.readback_copy);
}

/// Every stream-ordered row must have made the engine's numbers: the same XOR over the
/// same blocks and keys.
void check_stream_checksums(const TeaResult& r) {
    const cuda::TeaStreamResult& s = *r.stream;
    const unsigned fixed = r.variants[0].checksum, generated = r.variants[1].checksum;
    const std::pair<const cuda::TeaStreamRow*, unsigned> checks[] = {
        {&s.device_fixed, fixed},
        {&s.device_generated, generated},
        {&s.readback_fixed, fixed},
        {&s.readback_generated, generated}};
    for (const auto& [row, expected] : checks)
        if (row->checksum != expected)
            throw Error("bench tea: the stream-ordered output's checksum " + hex8(row->checksum) +
                        " differs from the engine launches' " + hex8(expected) +
                        "; the GPU made other numbers than the engine's programs");
}

void check_options(const TeaBenchOptions& options) {
    require_in_range("bench tea", "megabytes (--megabytes)", options.megabytes, 1, 65536);
    require_in_range("bench tea", "rounds (--rounds)", options.rounds, 1, 64);
    require_in_range("bench tea", "threads (--threads)", options.threads, 0, 4096);
}

}  // namespace

std::string bench_tea_json(TeaBenchOptions options) {
    return captured_document("bench tea", std::move(options), run_tea_bench);
}

int run_tea_bench(const TeaBenchOptions& options) {
    check_options(options);
    Context ctx(ContextOptions{options.backend, options.threads});
    ctx.set_entry_point_count(3);
    ctx.set_ray_generation_program(0,
                                   ctx.create_program(LUCENT_PROGRAM(tea_sample::tea_fixed_key)));
    ctx.set_ray_generation_program(1,
                                   ctx.create_program(LUCENT_PROGRAM(tea_sample::tea_device_key)));
    ctx.set_ray_generation_program(2, ctx.create_program(LUCENT_PROGRAM(tea_sample::tea_copy)));
    auto out = ctx.create_buffer<uint2>(BufferType::kOutput, kBlocksPerMegabyte);
    auto first_block = ctx.create_buffer<unsigned>(BufferType::kInput, 1);
    // The copy's source: 1 MB of TEA output made on the host, uploaded once.
    auto source = ctx.create_buffer<uint2>(BufferType::kInput, kBlocksPerMegabyte);
    {
        std::vector<uint2> words(kBlocksPerMegabyte);
        for (unsigned i = 0; i < kBlocksPerMegabyte; ++i)
            words[i] = tea(make_uint2(i, 1u), zafar_tea_key(), 2);
        source->upload(words);
    }
    ctx["out"] = out;
    ctx["source"] = source;
    ctx["first_block"] = first_block;
    ctx["rounds"] = options.rounds;
    ctx["key"] = generate_tea_key(zafar_tea_key(), make_uint2(options.device, options.seed));

    const unsigned total = 3 * options.megabytes;
    TeaResult result;
    result.options = &options;
    result.backend = ctx.backend_name();
    result.notice = ctx.backend_notice();
    const bool on_gpu = result.backend.rfind("cuda", 0) == 0;
    if (on_gpu && options.megabytes > cuda::kTeaStreamMaxMegabytes)  // before any work
        throw Error("bench tea --backend cuda: --megabytes " + std::to_string(options.megabytes) +
                    ": the stream-ordered rows hold the whole output in device and pinned host "
                    "memory, at most " + std::to_string(cuda::kTeaStreamMaxMegabytes) +
                    " MB; give --megabytes " + std::to_string(cuda::kTeaStreamMaxMegabytes) +
                    " or less");
    result.variants =
        run_variants(ctx, out, first_block, options.megabytes, [&options, total](unsigned done) {
            if (options.progress) options.progress(done, total);
        });
#ifdef LUCENT_HAVE_CUDA
    if (on_gpu) {
        cuda::TeaStreamInput stream;
        stream.megabytes = options.megabytes;
        stream.rounds = options.rounds;
        stream.fixed_key = zafar_tea_key();
        stream.generated_key = generate_tea_key(zafar_tea_key(), make_uint2(options.device, options.seed));
        result.stream = cuda::run_tea_stream_cuda(stream);
        check_stream_checksums(result);
    }
#else
    (void)on_gpu;
#endif
    report(result, options.json);
    return 0;
}

}  // namespace lucent::bench
