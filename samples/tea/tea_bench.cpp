#include "samples/tea/tea_bench.h"

#include <chrono>
#include <cstdio>

#include "samples/tea/tea_programs.h"

namespace lucent::samples {

namespace {
constexpr unsigned kBlocksPerMegabyte = (1u << 20) / sizeof(uint2);

struct VariantResult {
    double seconds = 0;
    unsigned checksum = 0;  // XOR of every output word, so the work cannot be skipped
};

VariantResult run_variant(Context& ctx, const std::shared_ptr<Buffer>& out, unsigned megabytes,
                          unsigned entry, const std::function<void(unsigned)>& progress) {
    VariantResult r;
    ctx.launch(entry, kBlocksPerMegabyte);  // compile (and JIT) before timing
    auto start = std::chrono::steady_clock::now();
    for (unsigned mb = 0; mb < megabytes; ++mb) {
        ctx["first_block"] = mb * kBlocksPerMegabyte;
        ctx.launch(entry, kBlocksPerMegabyte);
        const uint2* words = out->data<uint2>();  // the 1 MB reaches the host, as in the seed
        for (unsigned i = 0; i < kBlocksPerMegabyte; ++i) r.checksum ^= words[i].x ^ words[i].y;
        if (progress) progress(mb + 1);
    }
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return r;
}
}  // namespace

int run_tea_bench(const TeaBenchOptions& options) {
    Context ctx(ContextOptions{options.backend, options.threads});
    ctx.set_entry_point_count(2);
    ctx.set_ray_generation_program(0, ctx.create_program(LUCENT_PROGRAM(tea_fixed_key)));
    ctx.set_ray_generation_program(1, ctx.create_program(LUCENT_PROGRAM(tea_device_key)));
    auto out = ctx.create_buffer<uint2>(BufferType::kOutput, kBlocksPerMegabyte);
    ctx["out"] = out;
    ctx["rounds"] = options.rounds;
    ctx["first_block"] = 0u;
    ctx["key"] = generate_tea_key(zafar_tea_key(), make_uint2(options.device, options.seed));

    const unsigned total = 2 * options.megabytes;
    auto report_from = [&](unsigned offset) {
        return [&options, offset, total](unsigned done) {
            if (options.progress) options.progress(offset + done, total);
        };
    };
    const VariantResult fixed = run_variant(ctx, out, options.megabytes, 0, report_from(0));
    const VariantResult device =
        run_variant(ctx, out, options.megabytes, 1, report_from(options.megabytes));
    const double mb = options.megabytes;
    if (options.json) {
        std::printf(
            "{\"backend\": \"%s\", \"megabytes\": %u, \"rounds\": %u, "
            "\"fixed_key_mb_per_s\": %.1f, \"generated_key_mb_per_s\": %.1f, "
            "\"fixed_checksum\": \"%08x\", \"generated_checksum\": \"%08x\"}\n",
            ctx.backend_name().c_str(), options.megabytes, options.rounds, mb / fixed.seconds,
            mb / device.seconds, fixed.checksum, device.checksum);
        return 0;
    }
    if (!ctx.backend_notice().empty()) std::printf("note: %s\n", ctx.backend_notice().c_str());
    std::printf("tea: %u MB in 1 MB launches, %u rounds, on %s\n", options.megabytes,
                options.rounds, ctx.backend_name().c_str());
    std::printf("fixed key      %9.1f MB/s  (%.3f s, checksum %08x)\n", mb / fixed.seconds,
                fixed.seconds, fixed.checksum);
    std::printf("generated key  %9.1f MB/s  (%.3f s, checksum %08x; device %u, seed %u)\n",
                mb / device.seconds, device.seconds, device.checksum, options.device, options.seed);
    return 0;
}

}  // namespace lucent::samples
