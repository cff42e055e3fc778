#include "cuda/accel/gpu_bvh_builder.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "cuda/device/lucent_gpu/bvh_build.cuh"
#include "cuda/device/lucent_gpu/bvh_refit.cuh"
#include "cuda/device/lucent_gpu/bvh_sah_build.cuh"
#include "cuda/backend/driver_api.h"
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

unsigned blocks_for(size_t count, unsigned block) {
    return unsigned((count + block - 1) / block);
}

}  // namespace

struct GpuBvhBuilder::Impl {
    CUmodule module = nullptr;
    CUfunction reset = nullptr, bounds = nullptr, morton = nullptr, leaves = nullptr,
               hploc = nullptr, emit = nullptr, histogram = nullptr, scan = nullptr,
               scatter = nullptr, refit_triangles = nullptr, refit_nodes = nullptr;
    CUfunction sah[8] = {};  // by GpuSahPass
    CUevent start = nullptr, stop = nullptr;
    // Scratch, grown to the largest mesh seen.
    DeviceBuffer keys, keys_alt, order, order_alt, split_slots, clusters, node_lo, node_hi,
        node_children, node_inner, node_parent, histogram_buffer, counters, arrivals;
    DeviceBuffer host_positions, host_indices;  // uploads of the span overloads
    // Scratch of the binned-SAH build.
    DeviceBuffer prim_lo, prim_hi, prim_task, tasks[2], pool[2], node_range, sah_counters;

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

GpuBvhBuilder::GpuBvhBuilder(int sm) : m(std::make_unique<Impl>()) {
    CompileRequest req = embedded_request(
        "lucent_bvh_build.cu",
        "#include \"lucent_gpu/bvh_build.cuh\"\n#include \"lucent_gpu/bvh_refit.cuh\"\n"
        "#include \"lucent_gpu/bvh_sah_build.cuh\"\n",
        {"--std=c++17"}, sm);
    if (const char* debug = std::getenv("LUCENT_GPU_BUILD_DEBUG"); debug && *debug)
        req.options.push_back("-DLUCENT_BUILD_DEBUG=1");  // the kernels print what they do
    // Experiments: e.g. "-DLUCENT_PLOC_RADIUS=8 -DLUCENT_MORTON_CUBE=1".
    add_options_from_env(req, "LUCENT_GPU_BUILD_NVRTC_OPTIONS");
    const CompileResult compiled = compile_cubin(req);
    const DriverApi& d = api();
    check(d.cuModuleLoadData(&m->module, compiled.cubin.data()), "cuModuleLoadData (BVH builder)");
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
    const char* sah_names[8] = {"lucent_sah_reset",     "lucent_sah_init",  "lucent_sah_bin",
                                "lucent_sah_split",     "lucent_sah_partition",
                                "lucent_sah_count",     "lucent_sah_emit",  "lucent_sah_triangles"};
    for (int k = 0; k < 8; ++k) m->sah[k] = fn(sah_names[k]);
    check(d.cuEventCreate(&m->start, CU_EVENT_DEFAULT), "cuEventCreate");
    check(d.cuEventCreate(&m->stop, CU_EVENT_DEFAULT), "cuEventCreate");
}

GpuBvhBuilder::~GpuBvhBuilder() {
    if (const DriverApi* d = driver()) {  // errors while tearing down are not actionable
        if (m->start) d->cuEventDestroy(m->start);
        if (m->stop) d->cuEventDestroy(m->stop);
        if (m->module) d->cuModuleUnload(m->module);
    }
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
    reserve(out.nodes, sizeof(float4) * gpu::kGpuNodeFloat4s * out_nodes);
    reserve(out.triangles, sizeof(float4) * gpu::kGpuTriangleFloat4s * n);
    reserve(out.triangle_ids, 4 * size_t(n));
    reserve(out.parents, 4 * out_nodes);

    gpu::GpuBuildParams p{};
    p.positions = reinterpret_cast<const float3*>(static_cast<uintptr_t>(tris.positions));
    p.indices = reinterpret_cast<const uint3*>(static_cast<uintptr_t>(tris.indices));
    p.vertex_count = tris.vertex_count;
    p.triangle_count = n;
    p.max_leaf_size = unsigned(options.max_leaf_size);
    p.traversal_cost = options.traversal_cost;
    p.intersection_cost = options.intersection_cost;
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
    p.out_nodes = device_ptr<float4>(out.nodes);
    p.out_triangles = device_ptr<float4>(out.triangles);
    p.out_triangle_ids = device_ptr<unsigned>(out.triangle_ids);
    p.out_parents = device_ptr<unsigned>(out.parents);

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
    stats.leaf_count = stats.node_count + 1;
    float sah;
    std::memcpy(&sah, &counters[gpu::kCounterSah], sizeof sah);
    stats.sah_cost = sah;
    out.node_count = stats.node_count;
    out.triangle_count = n;
    return stats;
}

GpuBvhStats GpuBvhBuilder::Impl::build_sah(const DeviceTriangles& tris, GpuTriangleBvhDevice& out,
                                           const GpuBvhBuildOptions& options) {
    const unsigned n = tris.triangle_count;
    const size_t nodes = 2 * size_t(n) - 1, out_nodes = n > 1 ? n - 1 : 1;
    const size_t pool_words = gpu::gpu_sah_pool_words(n);
    if (pool_words > 0xffffffffu)
        throw Error("GPU BVH builder: " + std::to_string(n) +
                    " triangles are too many for the binned-SAH build; use H-PLOC");
    reserve(prim_lo, sizeof(float4) * n);
    reserve(prim_hi, sizeof(float4) * n);
    reserve(prim_task, 4 * size_t(n));
    reserve(order, 4 * size_t(n));
    for (int k = 0; k < 2; ++k) {
        reserve(tasks[k], sizeof(gpu::GpuSahTask) * (n / 2 + 1));
        reserve(pool[k], 4 * pool_words);
    }
    reserve(node_lo, sizeof(float4) * nodes);
    reserve(node_hi, sizeof(float4) * nodes);
    reserve(node_range, sizeof(uint2) * nodes);
    reserve(node_parent, 4 * nodes);
    reserve(node_inner, 4 * nodes);
    reserve(arrivals, 4 * nodes);
    reserve(sah_counters, 4 * gpu::kSahCounterCount);
    reserve(out.nodes, sizeof(float4) * gpu::kGpuNodeFloat4s * out_nodes);
    reserve(out.triangles, sizeof(float4) * gpu::kGpuTriangleFloat4s * n);
    reserve(out.triangle_ids, 4 * size_t(n));
    reserve(out.parents, 4 * out_nodes);

    gpu::GpuSahBuildParams p{};
    p.positions = reinterpret_cast<const float3*>(static_cast<uintptr_t>(tris.positions));
    p.indices = reinterpret_cast<const uint3*>(static_cast<uintptr_t>(tris.indices));
    p.vertex_count = tris.vertex_count;
    p.triangle_count = n;
    p.max_leaf_size = unsigned(options.max_leaf_size);
    p.traversal_cost = options.traversal_cost;
    p.intersection_cost = options.intersection_cost;
    p.pool_words = unsigned(pool_words);
    p.prim_lo = device_ptr<float4>(prim_lo);
    p.prim_hi = device_ptr<float4>(prim_hi);
    p.prim_task = device_ptr<unsigned>(prim_task);
    p.order = device_ptr<unsigned>(order);
    for (int k = 0; k < 2; ++k) {
        p.tasks[k] = device_ptr<gpu::GpuSahTask>(tasks[k]);
        p.pool[k] = device_ptr<unsigned>(pool[k]);
    }
    p.node_lo = device_ptr<float4>(node_lo);
    p.node_hi = device_ptr<float4>(node_hi);
    p.node_range = device_ptr<uint2>(node_range);
    p.node_parent = device_ptr<unsigned>(node_parent);
    p.node_inner = device_ptr<unsigned>(node_inner);
    p.node_arrivals = device_ptr<unsigned>(arrivals);
    p.counters = device_ptr<unsigned>(sah_counters);
    p.out_nodes = device_ptr<float4>(out.nodes);
    p.out_triangles = device_ptr<float4>(out.triangles);
    p.out_triangle_ids = device_ptr<unsigned>(out.triangle_ids);
    p.out_parents = device_ptr<unsigned>(out.parents);

    static const char* const kPassNames[8] = {
        "BVH build (SAH): reset",     "BVH build (SAH): boxes",  "BVH build (SAH): bins",
        "BVH build (SAH): split",     "BVH build (SAH): partition",
        "BVH build (SAH): counts",    "BVH build (SAH): layout", "BVH build (SAH): triangles"};
    check(api().cuEventRecord(start, nullptr), "cuEventRecord");
    gpu::gpu_sah_build_passes(
        n,
        [&](gpu::GpuSahPass pass, unsigned threads, unsigned level) {
            p.level = level;
            void* args[] = {&p};
            const unsigned block = pass == gpu::GpuSahPass::kReset ? 32u : 128u;
            launch(sah[int(pass)], blocks_for(threads, block), block, args,
                   kPassNames[int(pass)]);
        },
        [&](unsigned parity) {
            unsigned count = 0;
            check(api().cuMemcpyDtoH(&count, sah_counters.ptr() + 4 * (gpu::kSahTaskCount + parity),
                                     4),
                  "GPU BVH build: task count");
            return count;
        });
    GpuBvhStats stats;
    stats.builder = "binned SAH (GPU)";
    stats.build_ms = elapsed_ms();

    unsigned counters[gpu::kSahCounterCount];
    sah_counters.download(counters, sizeof counters);
    if (counters[gpu::kSahBadIndex] != gpu::kSahInvalid)
        throw Error("GPU BVH builder: triangle " + std::to_string(counters[gpu::kSahBadIndex]) +
                    " has a vertex index out of range (" + std::to_string(tris.vertex_count) +
                    " vertices)");
    if (counters[gpu::kSahFault] == gpu::kSahFaultDeepTree)
        throw GpuBvhTooDeep("GPU BVH builder: a tree deeper than the traversal stack (" +
                            std::to_string(gpu::kGpuStackSize) + ") for " + std::to_string(n) +
                            " triangles; build this mesh with the host SAH builder");
    if (counters[gpu::kSahFault] != gpu::kSahFaultNone)
        throw Error("GPU BVH builder: internal error " +
                    std::to_string(counters[gpu::kSahFault]) + " (GpuSahFault) for " +
                    std::to_string(n) + " triangles");
    stats.depth = counters[gpu::kSahDepth];
    stats.node_count = counters[gpu::kSahInner];
    if (stats.node_count > out_nodes || stats.depth + 2 >= (unsigned)gpu::kGpuStackSize)
        throw Error("GPU BVH builder: internal error, " + std::to_string(stats.node_count) +
                    " inner nodes, depth " + std::to_string(stats.depth) + " for " +
                    std::to_string(n) + " triangles");
    stats.leaf_count = stats.node_count + 1;
    float sah;
    std::memcpy(&sah, &counters[gpu::kSahCost], sizeof sah);
    stats.sah_cost = sah;
    out.node_count = stats.node_count;
    out.triangle_count = n;
    return stats;
}

GpuBvhStats GpuBvhBuilder::build(std::span<const float3> positions, std::span<const uint3> indices,
                                 GpuTriangleBvhDevice& out, const GpuBvhBuildOptions& options) {
    return build(m->upload(positions, indices), out, options);
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
