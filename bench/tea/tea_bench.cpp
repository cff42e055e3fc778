// Sebald's Table 2: TEA output in 1 MB launches, each read back, with the fixed key, the
// generated key and a plain copy taking turns.
#include "bench/tea/tea_bench.h"

#include <array>
#include <chrono>
#include <cstdio>
#include <vector>

#include "bench/common/report.h"
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

/// What `lucent bench tea` measured: fixed key, generated key, copy.
struct TeaResult {
    const TeaBenchOptions* options = nullptr;
    std::string backend, notice;
    std::array<VariantResult, 3> variants;
};

std::string hex8(unsigned value) {
    char buf[9];
    std::snprintf(buf, sizeof buf, "%08x", value);
    return buf;
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
                {"generated_checksum", hex8(device.checksum)}};
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
}

}  // namespace

int run_tea_bench(const TeaBenchOptions& options) {
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
    result.variants =
        run_variants(ctx, out, first_block, options.megabytes, [&options, total](unsigned done) {
            if (options.progress) options.progress(done, total);
        });
    report(result, options.json);
    return 0;
}

}  // namespace lucent::bench
