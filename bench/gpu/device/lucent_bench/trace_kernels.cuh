// Kernels of `lucent bench rays --backend cuda`: the ray sets of shared/BENCH.md and the
// two trace kernels that are timed (closest hit, any hit) over rays stored in memory.
//
// Trace kernels are persistent by default (Aila and Laine 2009, Sec. 3.3: one grid of
// warps that fetch rays from a global atomic counter until none are left), with the
// Kepler addendum's dynamic fetch: a lane whose ray is finished gets a new one as soon as
// fewer than LUCENT_GPU_DYNAMIC_FETCH_THRESHOLD lanes are still traversing. Compile with
// -DLUCENT_BENCH_PERSISTENT=0 for a plain grid of one thread per ray.
//
// Ray layout: rays[2i] = (origin, tmin), rays[2i + 1] = (direction, tmax).
// Closest results: hits[i] = (t bits, prim), t = -1 on a miss. Any-hit: occluded[i] = 0/1.
#pragma once

#include "lucent/device/types.h"
#include "lucent_gpu/ray_order.cuh"
#include "lucent_gpu/triangle_bvh.cuh"

#ifndef LUCENT_BENCH_PERSISTENT
#define LUCENT_BENCH_PERSISTENT 1
#endif
#ifndef LUCENT_BENCH_BLOCK
#define LUCENT_BENCH_BLOCK 128
#endif
#ifndef LUCENT_BENCH_MIN_BLOCKS
#define LUCENT_BENCH_MIN_BLOCKS 8  // 8 x 128 threads per SM: at most 64 registers
#endif

namespace lucent::gpu {

constexpr float kBenchPi = 3.14159265358979323846f;
constexpr float kBenchOffset = 1e-3f;  // secondary origins p + 1e-3 n (BENCH.md)

__device__ inline unsigned bench_hash(unsigned a) {
    a ^= a >> 16;
    a *= 0x7feb352du;
    a ^= a >> 15;
    a *= 0x846ca68bu;
    a ^= a >> 16;
    return a;
}

/// The next ray of each lane in `mask` (which must all call this): one atomic on the global
/// counter for the whole group, from its lowest lane (Aila-Laine Sec. 3.3).
__device__ inline unsigned bench_claim_rays(unsigned mask, unsigned* counter) {
    const unsigned lane = threadIdx.x & 31u;
    const int leader = __ffs(mask) - 1;
    unsigned base = 0;
    if ((int)lane == leader) base = atomicAdd(counter, (unsigned)__popc(mask));
    base = __shfl_sync(mask, base, leader);
    return base + (unsigned)__popc(mask & ((1u << lane) - 1u));
}

/// Traces rays[0, count) with query kQuery and writes each ray's result with store(i, tr).
template <int kQuery, class Store>
__device__ inline void bench_trace(const GpuTriangleBvhView& bvh, const float4* __restrict__ rays,
                                   unsigned count, unsigned* counter, Store&& store) {
    GpuNoFilter none;
#if LUCENT_BENCH_PERSISTENT
    GpuBvhStack stack;
    GpuBvhTraversal tr;
    tr.finish();
    unsigned ray = 0xffffffffu;  // the ray this lane traces, none yet
    for (;;) {
        const bool need = tr.done();
        const unsigned need_mask = __ballot_sync(__activemask(), need);
        if (need) {
            if (ray != 0xffffffffu) store(ray, tr);
            ray = bench_claim_rays(need_mask, counter);
            if (ray >= count) break;
            const float4 o = __ldg(rays + 2 * ray);
            const float4 d = __ldg(rays + 2 * ray + 1);
            tr.start(make_float3(o.x, o.y, o.z), make_float3(d.x, d.y, d.z), o.w, d.w, stack);
        }
        tr.run<kQuery, true>(bvh, none, stack);
    }
#else
    (void)counter;
    const unsigned ray = blockIdx.x * blockDim.x + threadIdx.x;
    if (ray >= count) return;
    GpuBvhStack stack;
    GpuBvhTraversal tr;
    const float4 o = __ldg(rays + 2 * ray);
    const float4 d = __ldg(rays + 2 * ray + 1);
    tr.start(make_float3(o.x, o.y, o.z), make_float3(d.x, d.y, d.z), o.w, d.w, stack);
    tr.run<kQuery, false>(bvh, none, stack);
    store(ray, tr);
#endif
}

}  // namespace lucent::gpu

/// Closest hit of every ray: hits[i] = (t or -1, triangle index).
extern "C" __global__ void __launch_bounds__(LUCENT_BENCH_BLOCK, LUCENT_BENCH_MIN_BLOCKS)
    lucent_bench_closest(lucent::gpu::GpuTriangleBvhView bvh, const float4* __restrict__ rays,
                         unsigned count, uint2* __restrict__ hits, unsigned* counter) {
    using namespace lucent::gpu;
    bench_trace<kGpuClosest>(bvh, rays, count, counter, [&](unsigned i, const GpuBvhTraversal& tr) {
        const bool h = tr.hit();
        hits[i] = make_uint2(__float_as_uint(h ? tr.tmax : -1.0f),
                             h ? bvh.triangle_ids[tr.hit_index] : 0u);
    });
}

/// Any hit of every ray: occluded[i] = 1 when something lies in (tmin, tmax).
extern "C" __global__ void __launch_bounds__(LUCENT_BENCH_BLOCK, LUCENT_BENCH_MIN_BLOCKS)
    lucent_bench_any(lucent::gpu::GpuTriangleBvhView bvh, const float4* __restrict__ rays,
                     unsigned count, unsigned char* __restrict__ occluded, unsigned* counter) {
    using namespace lucent::gpu;
    bench_trace<kGpuAny>(bvh, rays, count, counter, [&](unsigned i, const GpuBvhTraversal& tr) {
        occluded[i] = tr.hit() ? 1 : 0;
    });
}

/// Primary rays of BENCH.md, pixel y * width + x, y = 0 the top row. fwd, right, up2,
/// t = tan(fov / 2) and a = W / H come from the host (computed once, as the CPU bench does).
/// Ray i is pixel i, or with `tiled` the pixel gpu_tiled_pixel(i) (ray_order.cuh).
extern "C" __global__ void lucent_bench_primary_rays(float ex, float ey, float ez, float fx,
                                                     float fy, float fz, float rx, float ry,
                                                     float rz, float ux, float uy, float uz,
                                                     float t, float a, unsigned width,
                                                     unsigned height, unsigned tiled,
                                                     float4* rays) {
    const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= width * height) return;
    const unsigned pixel = tiled ? lucent::gpu::gpu_tiled_pixel(i, width, height) : i;
    const unsigned x = pixel % width, y = pixel / width;
    const float w = (float)width, h = (float)height;
    const float u = (2 * (x + 0.5f) / w - 1) * t * a;
    const float v = (1 - 2 * (y + 0.5f) / h) * t;
    const float3 fwd = make_float3(fx, fy, fz), right = make_float3(rx, ry, rz),
                 up2 = make_float3(ux, uy, uz);
    const float3 d = normalize(fwd + u * right + v * up2);
    rays[2 * i] = make_float4(ex, ey, ez, 0.0f);
    rays[2 * i + 1] = make_float4(d.x, d.y, d.z, lucent::kInfinity);
}

/// Shadow and diffuse rays of BENCH.md from the primary hits. slot[i] is the index of
/// primary ray i's secondary rays among the hits (an exclusive prefix sum over the rays
/// that hit, so they keep the primary order); tris_by_prim holds 3 float4 per triangle,
/// input order. The diffuse hash takes the pixel index, as in BENCH.md.
extern "C" __global__ void lucent_bench_secondary_rays(const float4* __restrict__ primary,
                                                       const uint2* __restrict__ hits,
                                                       const unsigned* __restrict__ slot,
                                                       const float4* __restrict__ tris_by_prim,
                                                       unsigned width, unsigned height,
                                                       unsigned tiled, float lx, float ly, float lz,
                                                       float4* shadow, float4* diffuse) {
    using namespace lucent::gpu;
    const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= width * height) return;
    const unsigned pixel = tiled ? gpu_tiled_pixel(i, width, height) : i;
    const uint2 hit = hits[i];
    const float t = __uint_as_float(hit.x);
    if (t < 0.0f) return;
    const float4 o4 = primary[2 * i], d4 = primary[2 * i + 1];
    const float3 d = make_float3(d4.x, d4.y, d4.z);
    const float3 p = make_float3(o4.x, o4.y, o4.z) + t * d;
    const float4 a = tris_by_prim[3 * hit.y], b = tris_by_prim[3 * hit.y + 1],
                 c = tris_by_prim[3 * hit.y + 2];
    const float3 v0 = make_float3(a.x, a.y, a.z);
    float3 n = normalize(cross(make_float3(b.x, b.y, b.z) - v0, make_float3(c.x, c.y, c.z) - v0));
    if (dot(n, d) > 0.0f) n = -n;
    const float3 o = p + kBenchOffset * n;
    const float3 to_light = make_float3(lx, ly, lz) - o;
    const float dist = length(to_light);
    const float3 ld = to_light / dist;
    const unsigned s = slot[i];
    shadow[2 * s] = make_float4(o.x, o.y, o.z, 0.0f);
    shadow[2 * s + 1] = make_float4(ld.x, ld.y, ld.z, dist);

    const unsigned h1 = bench_hash(2 * pixel + 1), h2 = bench_hash(h1);
    const float u1 = (float)(h1 >> 8) / 16777216.0f, u2 = (float)(h2 >> 8) / 16777216.0f;
    const float r = sqrtf(u1), phi = 2 * kBenchPi * u2;
    const float3 tt =
        normalize(cross(n, fabsf(n.x) > 0.5f ? make_float3(0, 1, 0) : make_float3(1, 0, 0)));
    const float3 bb = cross(n, tt);
    const float3 dir =
        normalize(tt * (r * cosf(phi)) + bb * (r * sinf(phi)) + n * sqrtf(fmaxf(0.0f, 1 - u1)));
    diffuse[2 * s] = make_float4(o.x, o.y, o.z, 0.0f);
    diffuse[2 * s + 1] = make_float4(dir.x, dir.y, dir.z, lucent::kInfinity);
}
