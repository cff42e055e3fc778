#include "cuda/accel/gpu_bvh_builder.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <string>
#include <type_traits>
#include <vector>

#include "cuda/backend/driver_api.h"
#include "cuda/device/lucent_gpu/bvh_build.cuh"
#include "cuda/device/lucent_gpu/bvh_refit.cuh"
#include "cuda/device/lucent_gpu/bvh_sah_build.cuh"
#include "cuda/device/lucent_gpu/triangle_gather.cuh"
#include "cuda/jit/nvrtc_compiler.h"
#include "lucent/error.h"

namespace lucent::cuda {

namespace {

const DriverApi& api() {
    return require_driver("GPU BVH builder");
}

/// Grows `buffer` to at least `bytes` (keeps it when it is big enough).
void reserve(DeviceBuffer& buffer, size_t bytes) {
    if (buffer.size() < bytes) buffer.alloc(bytes);
}

template <class T>
T* device_ptr(const DeviceBuffer& b) {
    return const_cast<T*>(b.as<T>());
}

/// LUCENT_GPU_ACCEL_TIMES=1: the builder prints where a build's time goes (module, uploads,
/// launches, the GPU's own time), to stderr.
bool print_times() {
    static const bool on = [] {
        const char* v = std::getenv("LUCENT_GPU_ACCEL_TIMES");
        return v && *v && std::strcmp(v, "0") != 0;
    }();
    return on;
}

double ms_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

unsigned blocks_for(size_t count, unsigned block) {
    return unsigned((count + block - 1) / block);
}

/// Room for the layout of a tree over n >= 1 triangles (n - 1 inner nodes at most).
void reserve_layout(GpuTriangleBvhDevice& out, unsigned n) {
    const size_t out_nodes = n > 1 ? n - 1 : 1;
    reserve(out.nodes, sizeof(float4) * gpu::kGpuNodeFloat4s * out_nodes);
    reserve(out.triangles, sizeof(float4) * gpu::kGpuTriangleFloat4s * n);
    reserve(out.triangle_ids, 4 * size_t(n));
    reserve(out.parents, 4 * out_nodes);
}

/// Places the binned-SAH build's scratch arrays for n triangles in `p`, carved out of one
/// allocation at `base` (a first build would otherwise pay for twenty allocations); returns
/// the bytes they take (with base 0: the size to allocate).
size_t carve_sah_scratch(gpu::GpuSahBuildParams& p, unsigned n, const gpu::GpuSahScratch& scratch,
                         CUdeviceptr base) {
    const size_t nodes = 2 * size_t(n) - 1;
    size_t at = 0;
    const auto take = [&](auto*& array, size_t count) {
        using T = std::remove_reference_t<decltype(*array)>;
        array = reinterpret_cast<T*>(base + at);
        at += (sizeof(T) * count + 255) & ~size_t(255);
    };
    take(p.prim_lo, n);
    take(p.prim_hi, n);
    take(p.order, n);
    for (int k = 0; k < 2; ++k) {
        take(p.work[k], n);
        take(p.place_task[k], n);
        take(p.tasks[k], scratch.task_capacity);
        take(p.bins[k], scratch.bin_words);
    }
    take(p.small, scratch.small_capacity);
    take(p.node_lo, nodes);
    take(p.node_hi, nodes);
    take(p.node_range, nodes);
    take(p.node_parent, nodes);
    take(p.node_inner, nodes);
    take(p.node_arrivals, nodes);
    take(p.counters, gpu::kSahCounterCount);
    return at;
}

/// The inputs and outputs both algorithms' parameters have (gpu::GpuBuildParams,
/// gpu::GpuSahBuildParams).
template <class Params>
void set_common_params(Params& p, const DeviceTriangles& tris, const GpuBvhBuildOptions& options,
                       const GpuTriangleBvhDevice& out) {
    p.positions = reinterpret_cast<const float3*>(static_cast<uintptr_t>(tris.positions));
    p.indices = reinterpret_cast<const uint3*>(static_cast<uintptr_t>(tris.indices));
    p.vertex_count = tris.vertex_count;
    p.triangle_count = tris.triangle_count;
    p.max_leaf_size = unsigned(options.max_leaf_size);
    p.traversal_cost = options.traversal_cost;
    p.intersection_cost = options.intersection_cost;
    p.out_nodes = device_ptr<float4>(out.nodes);
    p.out_triangles = device_ptr<float4>(out.triangles);
    p.out_triangle_ids = device_ptr<unsigned>(out.triangle_ids);
    p.out_parents = device_ptr<unsigned>(out.parents);
}

/// Triangles a small task of the binned-SAH build may hold (LUCENT_GPU_SAH_SMALL, for
/// experiments; gpu::kSahSmallDefault otherwise).
unsigned sah_small_limit() {
    const char* v = std::getenv("LUCENT_GPU_SAH_SMALL");
    if (!v || !*v) return gpu::kSahSmallDefault;
    char* end = nullptr;
    const unsigned long limit = std::strtoul(v, &end, 10);
    if (*end || limit < gpu::kSahSmallMin || limit > gpu::kSahSmallMax)
        throw Error(std::string("LUCENT_GPU_SAH_SMALL=") + v + ": expected " +
                    std::to_string(gpu::kSahSmallMin) + ".." + std::to_string(gpu::kSahSmallMax));
    return unsigned(limit);
}

/// What both algorithms' builds end with, once their node count is checked: the leaves (a
/// binary tree has one more than inner nodes), the SAH cost the kernels left as float bits,
/// and the layout's sizes.
GpuBvhStats finish_build(GpuBvhStats stats, unsigned sah_bits, unsigned triangles,
                         GpuTriangleBvhDevice& out) {
    stats.leaf_count = stats.node_count + 1;
    float sah;
    std::memcpy(&sah, &sah_bits, sizeof sah);
    stats.sah_cost = sah;
    out.node_count = stats.node_count;
    out.triangle_count = triangles;
    return stats;
}

}  // namespace

struct GpuBvhBuilder::Impl {
    CUmodule module = nullptr;
    CUfunction reset = nullptr, bounds = nullptr, morton = nullptr, leaves = nullptr,
               hploc = nullptr, emit = nullptr, histogram = nullptr, scan = nullptr,
               scatter = nullptr, refit_triangles = nullptr, refit_nodes = nullptr,
               gather = nullptr;
    CUfunction sah[int(gpu::GpuSahPass::kPassCount)] = {};
    CUevent start = nullptr, stop = nullptr;
    CUevent phase[2] = {};  // LUCENT_GPU_ACCEL_TIMES: after the big levels, after the small tasks
    // Scratch, grown to the largest mesh seen.
    DeviceBuffer keys, keys_alt, order, order_alt, split_slots, clusters, node_lo, node_hi,
        node_children, node_inner, node_parent, histogram_buffer, counters, arrivals;
    DeviceBuffer host_positions, host_indices;  // uploads of the span overloads
    // gather(): the piece table, then the mesh's positions and indices (one allocation).
    DeviceBuffer gather_scratch;
    // Scratch of the binned-SAH build.
    DeviceBuffer sah_scratch;  // one allocation, carved into the arrays (carve_sah_scratch)
    // A layout allocated ahead by prepare(), taken by the first build it is big enough for.
    GpuTriangleBvhDevice spare_layout;

    void launch(CUfunction f, unsigned grid, unsigned block, void** args, const char* what) {
        if (grid == 0) return;
        check(api().cuLaunchKernel(f, grid, 1, 1, block, 1, 1, 0, nullptr, args, nullptr), what);
        if (trace) {  // LUCENT_GPU_BUILD_TRACE: each kernel alone, named, for debugging
            std::fprintf(stderr, "lucent: %s (%u blocks of %u) ...", what, grid, block);
            check(api().cuCtxSynchronize(), what);
            std::fprintf(stderr, " done\n");
        }
    }
    const bool trace = std::getenv("LUCENT_GPU_BUILD_TRACE") != nullptr;
    double elapsed_ms() {
        check(api().cuEventRecord(stop, nullptr), "cuEventRecord");
        check(api().cuEventSynchronize(stop), "GPU BVH build");
        float ms = 0;
        check(api().cuEventElapsedTime(&ms, start, stop), "cuEventElapsedTime");
        return ms;
    }
    void sort(unsigned n);
    /// Room for the layout of a tree over n triangles in `out`: the spare layout when `out`
    /// has none yet and the spare is big enough, else its own buffers grown.
    void reserve_out(GpuTriangleBvhDevice& out, unsigned n) {
        if (out.nodes.empty() && !spare_layout.nodes.empty() &&
            spare_layout.triangle_ids.size() >= 4 * size_t(n))
            out = std::move(spare_layout);
        reserve_layout(out, n);
    }
    GpuBvhStats build_sah(const DeviceTriangles& tris, GpuTriangleBvhDevice& out,
                          const GpuBvhBuildOptions& options);
    /// Copies host triangles to the device (host_positions, host_indices).
    DeviceTriangles upload(std::span<const float3> positions, std::span<const uint3> indices) {
        return upload_triangles(positions, indices, host_positions, host_indices);
    }
};

DeviceTriangles upload_triangles(std::span<const float3> positions, std::span<const uint3> indices,
                                 DeviceBuffer& positions_out, DeviceBuffer& indices_out) {
    positions_out.upload(positions);
    indices_out.upload(indices);
    DeviceTriangles tris;
    tris.positions = positions_out.ptr();
    tris.vertex_count = unsigned(positions.size());
    tris.indices = indices.empty() ? 0 : indices_out.ptr();
    tris.triangle_count = unsigned(indices.empty() ? positions.size() / 3 : indices.size());
    return tris;
}

CompileRequest bvh_builder_request(int sm) {
    CompileRequest req = embedded_request(
        "lucent_bvh_build.cu",
        "#include \"lucent_gpu/bvh_build.cuh\"\n#include \"lucent_gpu/bvh_refit.cuh\"\n"
        "#include \"lucent_gpu/bvh_sah_build.cuh\"\n#include \"lucent_gpu/triangle_gather.cuh\"\n",
        {"--std=c++17"}, sm);
    if (const char* debug = std::getenv("LUCENT_GPU_BUILD_DEBUG"); debug && *debug)
        req.options.push_back("-DLUCENT_BUILD_DEBUG=1");  // the kernels print what they do
    // Experiments: e.g. "-DLUCENT_PLOC_RADIUS=8 -DLUCENT_MORTON_CUBE=1".
    add_options_from_env(req, "LUCENT_GPU_BUILD_NVRTC_OPTIONS");
    return req;
}

GpuBvhBuilder::GpuBvhBuilder(int sm) : m(std::make_unique<Impl>()) {
    const auto t0 = std::chrono::steady_clock::now();
    const CompileResult compiled = compile_cubin(bvh_builder_request(sm));
    const DriverApi& d = api();
    const double compile_ms = ms_since(t0);
    check(d.cuModuleLoadData(&m->module, compiled.cubin.data()), "cuModuleLoadData (BVH builder)");
    if (print_times())
        std::fprintf(stderr, "lucent: GPU BVH builder: module %.3f ms (%s), loaded in %.3f ms\n",
                     compile_ms, compiled.from_cache ? "kernel cache" : "NVRTC",
                     ms_since(t0) - compile_ms);
    auto fn = [&](const char* name) {
        CUfunction f = nullptr;
        check(d.cuModuleGetFunction(&f, m->module, name), name);
        return f;
    };
    m->reset = fn("lucent_build_reset");
    m->bounds = fn("lucent_build_bounds");
    m->morton = fn("lucent_build_morton");
    m->leaves = fn("lucent_build_leaves");
    m->hploc = fn("lucent_build_hploc");
    m->emit = fn("lucent_build_emit");
    m->histogram = fn("lucent_radix_histogram");
    m->scan = fn("lucent_radix_scan");
    m->scatter = fn("lucent_radix_scatter");
    m->refit_triangles = fn("lucent_refit_triangles");
    m->refit_nodes = fn("lucent_refit_nodes");
    m->gather = fn("lucent_gather_triangles");
    const char* sah_names[] = {"lucent_sah_reset", "lucent_sah_init",      "lucent_sah_bin",
                               "lucent_sah_split", "lucent_sah_partition", "lucent_sah_small",
                               "lucent_sah_count", "lucent_sah_emit",      "lucent_sah_triangles"};
    static_assert(std::size(sah_names) == size_t(gpu::GpuSahPass::kPassCount));
    for (size_t k = 0; k < std::size(sah_names); ++k) m->sah[k] = fn(sah_names[k]);
    check(d.cuEventCreate(&m->start, CU_EVENT_DEFAULT), "cuEventCreate");
    check(d.cuEventCreate(&m->stop, CU_EVENT_DEFAULT), "cuEventCreate");
    for (CUevent& e : m->phase) check(d.cuEventCreate(&e, CU_EVENT_DEFAULT), "cuEventCreate");
}

GpuBvhBuilder::~GpuBvhBuilder() {
    if (const DriverApi* d = driver()) {  // errors while tearing down are not actionable
        if (m->start) d->cuEventDestroy(m->start);
        if (m->stop) d->cuEventDestroy(m->stop);
        for (CUevent e : m->phase)
            if (e) d->cuEventDestroy(e);
        if (m->module) d->cuModuleUnload(m->module);
    }
}

void GpuBvhBuilder::prepare(unsigned triangles) {
    if (triangles == 0) return;
    gpu::GpuSahBuildParams p{};
    const gpu::GpuSahScratch scratch = gpu::gpu_sah_scratch(triangles, sah_small_limit());
    reserve(m->sah_scratch, carve_sah_scratch(p, triangles, scratch, 0));
    reserve_layout(m->spare_layout, triangles);
}

/// Sorts (keys, order) by key in four 8-bit passes; the result ends where it started.
void GpuBvhBuilder::Impl::sort(unsigned n) {
    unsigned tiles = blocks_for(n, gpu::kSortTile);
    unsigned hist_count = 256 * tiles;
    CUdeviceptr hist = histogram_buffer.ptr();
    CUdeviceptr k_in = keys.ptr(), v_in = order.ptr(), k_out = keys_alt.ptr(),
                v_out = order_alt.ptr();
    for (unsigned shift = 0; shift < 32; shift += 8) {
        void* h_args[] = {&k_in, &n, &shift, &hist, &tiles};
        launch(histogram, tiles, gpu::kSortThreads, h_args, "radix histogram");
        void* s_args[] = {&hist, &hist_count};
        launch(scan, 1, gpu::kSortScanThreads, s_args, "radix scan");
        void* x_args[] = {&k_in, &v_in, &k_out, &v_out, &n, &shift, &hist, &tiles};
        launch(scatter, tiles, gpu::kSortThreads, x_args, "radix scatter");
        std::swap(k_in, k_out);
        std::swap(v_in, v_out);
    }
}

GpuBvhStats GpuBvhBuilder::build(const DeviceTriangles& tris, GpuTriangleBvhDevice& out,
                                 const GpuBvhBuildOptions& options) {
    const unsigned n = tris.triangle_count;
    if (options.max_leaf_size < 1 || options.max_leaf_size > gpu::kGpuMaxLeafSize)
        throw Error("GPU BVH builder: max_leaf_size must be 1.." +
                    std::to_string(gpu::kGpuMaxLeafSize));
    if (n > gpu::kGpuLeafFirstMask)
        throw Error("GPU BVH builder: " + std::to_string(n) +
                    " triangles, the layout holds at most " +
                    std::to_string(gpu::kGpuLeafFirstMask));
    GpuBvhStats stats;
    stats.builder = "H-PLOC (GPU)";
    if (n == 0) {  // the host layout of an empty mesh: a root with two empty boxes
        GpuTriangleBvh empty = build_gpu_triangle_bvh({}, {});
        upload_gpu_triangle_bvh(empty, out);
        stats.node_count = 1;
        stats.builder = "GPU";
        return stats;
    }
    if (options.gpu_algorithm == GpuBuildAlgorithm::kBinnedSah)
        return m->build_sah(tris, out, options);
    Impl& s = *m;
    const size_t nodes = 2 * size_t(n) - 1;
    const size_t out_nodes = n > 1 ? n - 1 : 1;  // inner nodes at most
    reserve(s.keys, 4 * size_t(n));
    reserve(s.keys_alt, 4 * size_t(n));
    reserve(s.order, 4 * size_t(n));
    reserve(s.order_alt, 4 * size_t(n));
    reserve(s.split_slots, 4 * size_t(n));
    reserve(s.clusters, 4 * size_t(n));
    reserve(s.node_lo, sizeof(float4) * nodes);
    reserve(s.node_hi, sizeof(float4) * nodes);
    reserve(s.node_children, sizeof(int2) * nodes);
    reserve(s.node_inner, 4 * nodes);
    reserve(s.node_parent, 4 * nodes);
    reserve(s.histogram_buffer, 4 * 256 * size_t(blocks_for(n, gpu::kSortTile)));
    reserve(s.counters, 4 * gpu::kCounterCount);
    s.reserve_out(out, n);

    gpu::GpuBuildParams p{};
    set_common_params(p, tris, options, out);
    p.keys = device_ptr<unsigned>(s.keys);
    p.order = device_ptr<unsigned>(s.order);
    p.split_slots = device_ptr<unsigned>(s.split_slots);
    p.clusters = device_ptr<unsigned>(s.clusters);
    p.node_lo = device_ptr<float4>(s.node_lo);
    p.node_hi = device_ptr<float4>(s.node_hi);
    p.node_children = device_ptr<int2>(s.node_children);
    p.node_inner = device_ptr<unsigned>(s.node_inner);
    p.node_parent = device_ptr<unsigned>(s.node_parent);
    p.counters = device_ptr<unsigned>(s.counters);

    void* args[] = {&p};
    check(api().cuEventRecord(s.start, nullptr), "cuEventRecord");
    s.launch(s.reset, 1, 32, args, "BVH build: reset");
    s.launch(s.bounds, blocks_for(n, 256), 256, args, "BVH build: bounds");
    s.launch(s.morton, blocks_for(n, 256), 256, args, "BVH build: Morton codes");
    s.sort(n);
    s.launch(s.leaves, blocks_for(n, 256), 256, args, "BVH build: leaves");
    s.launch(s.hploc, blocks_for(n, 64), 64, args, "BVH build: H-PLOC");
    s.launch(s.emit, blocks_for(n, 128), 128, args, "BVH build: layout");
    stats.build_ms = s.elapsed_ms();

    unsigned counters[gpu::kCounterCount];
    s.counters.download(counters, sizeof counters);
    if (counters[gpu::kCounterBadIndex] != gpu::kBuildInvalid)
        throw Error("GPU BVH builder: triangle " + std::to_string(counters[gpu::kCounterBadIndex]) +
                    " has a vertex index out of range (" + std::to_string(tris.vertex_count) +
                    " vertices)");
    const auto too_deep = [&](const std::string& depth) {
        return GpuBvhTooDeep(
            "GPU BVH builder: a tree " + depth + " levels deep for " + std::to_string(n) +
            " triangles, more than the traversal stack holds (" +
            std::to_string(gpu::kGpuStackSize) + "); build this mesh with the host SAH builder");
    };
    if (counters[gpu::kCounterFault] == gpu::kFaultDeepTree) throw too_deep("at least 64");
    if (counters[gpu::kCounterFault] != gpu::kFaultNone)
        throw Error("GPU BVH builder: internal error " +
                    std::to_string(counters[gpu::kCounterFault]) + " (GpuBuildFault) for " +
                    std::to_string(n) + " triangles; build this mesh with the host SAH builder");
    if (n > 1 && (counters[gpu::kCounterNextNode] != 2 * n - 1 ||
                  counters[gpu::kCounterRoot] == gpu::kBuildInvalid))
        throw Error("GPU BVH builder: internal error, " +
                    std::to_string(counters[gpu::kCounterNextNode] - n) + " inner nodes made for " +
                    std::to_string(n) + " triangles");
    stats.depth = counters[gpu::kCounterDepth];
    if (stats.depth + 2 >= (unsigned)gpu::kGpuStackSize)
        throw too_deep(std::to_string(stats.depth));
    stats.node_count = counters[gpu::kCounterInner];
    if (stats.node_count > out_nodes)
        throw Error("GPU BVH builder: internal error, " + std::to_string(stats.node_count) +
                    " inner nodes emitted for " + std::to_string(n) + " triangles");
    return finish_build(stats, counters[gpu::kCounterSah], n, out);
}

GpuBvhStats GpuBvhBuilder::Impl::build_sah(const DeviceTriangles& tris, GpuTriangleBvhDevice& out,
                                           const GpuBvhBuildOptions& options) {
    const unsigned n = tris.triangle_count;
    const size_t out_nodes = n > 1 ? n - 1 : 1;
    const auto reserved = std::chrono::steady_clock::now();
    const unsigned small_limit = sah_small_limit();
    const gpu::GpuSahScratch scratch = gpu::gpu_sah_scratch(n, small_limit);
    reserve_out(out, n);

    gpu::GpuSahBuildParams p{};
    set_common_params(p, tris, options, out);
    p.small_limit = small_limit;
    p.task_capacity = unsigned(scratch.task_capacity);
    p.small_capacity = unsigned(scratch.small_capacity);
    reserve(sah_scratch, carve_sah_scratch(p, n, scratch, 0));
    carve_sah_scratch(p, n, scratch, sah_scratch.ptr());
    if (print_times())
        std::fprintf(stderr, "lucent: GPU BVH build: device memory (scratch, layout) %.3f ms\n",
                     ms_since(reserved));
    const CUdeviceptr counters_ptr = reinterpret_cast<uintptr_t>(p.counters);

    static const char* const kPassNames[] = {
        "BVH build (SAH): reset",  "BVH build (SAH): boxes",     "BVH build (SAH): bins",
        "BVH build (SAH): split",  "BVH build (SAH): partition", "BVH build (SAH): small tasks",
        "BVH build (SAH): counts", "BVH build (SAH): layout",    "BVH build (SAH): triangles"};
    const auto t0 = std::chrono::steady_clock::now();
    unsigned levels = 0;
    check(api().cuEventRecord(start, nullptr), "cuEventRecord");
    gpu::gpu_sah_build_passes(
        n, small_limit,
        [&](gpu::GpuSahPass pass, unsigned level) {
            if (print_times() && pass == gpu::GpuSahPass::kSmall)
                check(api().cuEventRecord(phase[0], nullptr), "cuEventRecord");
            if (print_times() && pass == gpu::GpuSahPass::kCount)
                check(api().cuEventRecord(phase[1], nullptr), "cuEventRecord");
            if (pass == gpu::GpuSahPass::kBin) levels = level + 1;
            p.level = level;
            void* args[] = {&p};
            const gpu::GpuSahShape shape = gpu::gpu_sah_shape(pass, n, small_limit);
            launch(sah[int(pass)], shape.blocks, shape.threads, args, kPassNames[int(pass)]);
        },
        [&](unsigned parity) {
            unsigned count = 0;
            check(api().cuMemcpyDtoH(&count, counters_ptr + 4 * (gpu::kSahTaskCount + parity), 4),
                  "GPU BVH build: task count");
            return count;
        });
    GpuBvhStats stats;
    stats.builder = "binned SAH (GPU)";
    stats.build_ms = elapsed_ms();
    if (print_times()) {
        float big = 0, small_ms = 0;
        check(api().cuEventElapsedTime(&big, start, phase[0]), "cuEventElapsedTime");
        check(api().cuEventElapsedTime(&small_ms, phase[0], phase[1]), "cuEventElapsedTime");
        std::fprintf(stderr,
                     "lucent: GPU BVH build (binned SAH) of %u triangles: %.3f ms on the host; "
                     "GPU %.3f ms: boxes and %u levels of big tasks %.3f ms, small tasks (up to "
                     "%u triangles) %.3f ms, layout %.3f ms\n",
                     n, ms_since(t0), stats.build_ms, levels, big, small_limit, small_ms,
                     stats.build_ms - big - small_ms);
    }

    unsigned counters[gpu::kSahCounterCount];
    check(api().cuMemcpyDtoH(counters, counters_ptr, sizeof counters), "GPU BVH build: counters");
    if (counters[gpu::kSahBadIndex] != gpu::kSahInvalid)
        throw Error("GPU BVH builder: triangle " + std::to_string(counters[gpu::kSahBadIndex]) +
                    " has a vertex index out of range (" + std::to_string(tris.vertex_count) +
                    " vertices)");
    if (counters[gpu::kSahFault] == gpu::kSahFaultDeepTree)
        throw GpuBvhTooDeep("GPU BVH builder: a tree deeper than the traversal stack (" +
                            std::to_string(gpu::kGpuStackSize) + ") for " + std::to_string(n) +
                            " triangles; build this mesh with the host SAH builder");
    if (counters[gpu::kSahFault] != gpu::kSahFaultNone)
        throw Error("GPU BVH builder: internal error " + std::to_string(counters[gpu::kSahFault]) +
                    " (GpuSahFault) for " + std::to_string(n) + " triangles");
    stats.depth = counters[gpu::kSahDepth];
    stats.node_count = counters[gpu::kSahInner];
    if (stats.node_count > out_nodes || stats.depth + 2 >= (unsigned)gpu::kGpuStackSize)
        throw Error("GPU BVH builder: internal error, " + std::to_string(stats.node_count) +
                    " inner nodes, depth " + std::to_string(stats.depth) + " for " +
                    std::to_string(n) + " triangles");
    return finish_build(stats, counters[gpu::kSahCost], n, out);
}

GpuBvhStats GpuBvhBuilder::build(std::span<const float3> positions, std::span<const uint3> indices,
                                 GpuTriangleBvhDevice& out, const GpuBvhBuildOptions& options) {
    const auto t0 = std::chrono::steady_clock::now();
    const DeviceTriangles tris = m->upload(positions, indices);
    if (print_times())
        std::fprintf(stderr, "lucent: GPU BVH build: upload of %u triangles %.3f ms\n",
                     tris.triangle_count, ms_since(t0));
    return build(tris, out, options);
}

DeviceTriangles GpuBvhBuilder::gather(std::span<const DeviceTriangles> pieces) {
    if (pieces.empty()) return {};
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<gpu::GpuTrianglePiece> table;
    table.reserve(pieces.size());
    size_t vertices = 0, triangles = 0;
    for (const DeviceTriangles& piece : pieces) {
        table.push_back({reinterpret_cast<const float3*>(static_cast<uintptr_t>(piece.positions)),
                         reinterpret_cast<const uint3*>(static_cast<uintptr_t>(piece.indices)),
                         unsigned(vertices), piece.vertex_count, unsigned(triangles),
                         piece.triangle_count});
        vertices += piece.vertex_count;
        triangles += piece.triangle_count;
    }
    if (vertices > 0xffffffffu || triangles > 0xffffffffu)
        throw Error("GPU BVH builder: " + std::to_string(triangles) + " triangles over " +
                    std::to_string(vertices) +
                    " vertices in one GeometryGroup; split it into groups of fewer than 2^32");
    Impl& s = *m;
    const auto aligned = [](size_t bytes) { return (bytes + 255) & ~size_t(255); };
    const size_t table_bytes = aligned(table.size() * sizeof(gpu::GpuTrianglePiece));
    const size_t positions_bytes = aligned(vertices * sizeof(float3));
    reserve(s.gather_scratch, table_bytes + positions_bytes + triangles * sizeof(uint3));
    const CUdeviceptr base = s.gather_scratch.ptr();
    check(api().cuMemcpyHtoD(base, table.data(), table.size() * sizeof(gpu::GpuTrianglePiece)),
          "GPU BVH builder: the gather's piece table");
    gpu::GpuGatherParams p{};
    p.pieces = reinterpret_cast<const gpu::GpuTrianglePiece*>(static_cast<uintptr_t>(base));
    p.piece_count = unsigned(table.size());
    p.vertex_total = unsigned(vertices);
    p.triangle_total = unsigned(triangles);
    p.positions = reinterpret_cast<float3*>(static_cast<uintptr_t>(base + table_bytes));
    p.indices =
        reinterpret_cast<uint3*>(static_cast<uintptr_t>(base + table_bytes + positions_bytes));
    void* args[] = {&p};
    s.launch(s.gather, blocks_for(std::max(vertices, triangles), 256), 256, args,
             "gather the instances' triangles");
    if (print_times())
        std::fprintf(stderr, "lucent: GPU BVH build: %zu instances' triangles gathered, %.3f ms\n",
                     pieces.size(), ms_since(t0));
    DeviceTriangles mesh;
    mesh.positions = base + table_bytes;
    mesh.vertex_count = unsigned(vertices);
    mesh.indices = base + table_bytes + positions_bytes;
    mesh.triangle_count = unsigned(triangles);
    return mesh;
}

double GpuBvhBuilder::refit(const DeviceTriangles& tris, GpuTriangleBvhDevice& bvh) {
    if (tris.triangle_count != bvh.triangle_count)
        throw Error("GPU BVH refit: " + std::to_string(tris.triangle_count) +
                    " triangles given, the BVH was built over " +
                    std::to_string(bvh.triangle_count) + "; rebuild it instead");
    Impl& s = *m;
    reserve(s.arrivals, 4 * std::max<size_t>(bvh.node_count, 1));
    gpu::GpuRefitParams p{};
    p.positions = reinterpret_cast<const float3*>(static_cast<uintptr_t>(tris.positions));
    p.indices = reinterpret_cast<const uint3*>(static_cast<uintptr_t>(tris.indices));
    p.vertex_count = tris.vertex_count;
    p.triangle_count = tris.triangle_count;
    p.node_count = unsigned(bvh.node_count);
    p.nodes = device_ptr<float4>(bvh.nodes);
    p.triangles = device_ptr<float4>(bvh.triangles);
    p.triangle_ids = bvh.triangle_ids.as<unsigned>();
    p.parents = bvh.parents.as<unsigned>();
    p.arrivals = device_ptr<unsigned>(s.arrivals);
    void* args[] = {&p};
    check(api().cuEventRecord(s.start, nullptr), "cuEventRecord");
    check(api().cuMemsetD32Async(s.arrivals.ptr(), 0, std::max<size_t>(bvh.node_count, 1), nullptr),
          "cuMemsetD32Async");
    s.launch(s.refit_triangles, blocks_for(tris.triangle_count, 256), 256, args,
             "BVH refit: triangles");
    s.launch(s.refit_nodes, blocks_for(bvh.node_count, 128), 128, args, "BVH refit: boxes");
    return s.elapsed_ms();
}

double GpuBvhBuilder::refit(std::span<const float3> positions, std::span<const uint3> indices,
                            GpuTriangleBvhDevice& bvh) {
    for (size_t i = 0; i < indices.size(); ++i) {
        const uint3 t = indices[i];
        if (t.x >= positions.size() || t.y >= positions.size() || t.z >= positions.size())
            throw Error("GPU BVH refit: triangle " + std::to_string(i) +
                        " has a vertex index out of range");
    }
    return refit(m->upload(positions, indices), bvh);
}

}  // namespace lucent::cuda
