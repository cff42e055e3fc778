// Programs of programs_test: one or more of every program kind, each writing what it
// observed where the host can read it back.
#pragma once

#include "tests/programs/common.h"

namespace lucent_tests {
// Each test module in its own inline namespace: its own LUCENT_MODULE, while the tests
// still name its programs and types unqualified.
inline namespace program_kinds_module {
LUCENT_MODULE(test_program_kinds)

// ---- ray generation over 1D/2D/3D grids ------------------------------------------
struct IndexAndSize {
    uint3 index;
    uint3 size;
};

struct Index1DRecord {
    BufferView<IndexAndSize> output;
};
LUCENT_RECORD(Index1DRecord, output)
LUCENT_RAY_GENERATION(pk_write_index_1d, Index1DRecord) {
    rec.output[launch_index().x] = IndexAndSize{launch_index(), launch_size()};
}

struct Index2DRecord {
    BufferView<IndexAndSize> output;
};
LUCENT_RECORD(Index2DRecord, output)
LUCENT_RAY_GENERATION(pk_write_index_2d, Index2DRecord) {
    const uint3 i = launch_index();
    rec.output[make_uint2(i.x, i.y)] = IndexAndSize{i, launch_size()};
}

struct Index3DRecord {
    BufferView<IndexAndSize> output;
};
LUCENT_RECORD(Index3DRecord, output)
LUCENT_RAY_GENERATION(pk_write_index_3d, Index3DRecord) {
    rec.output[launch_index()] = IndexAndSize{launch_index(), launch_size()};
}

// ---- miss with a record ------------------------------------------------------------
struct BackgroundRecord {
    unsigned background_id;
};
LUCENT_RECORD(BackgroundRecord, background_id)
LUCENT_MISS(pk_miss_background, BackgroundRecord, TestPayload) {
    prd.hit = 0;
    prd.id = rec.background_id;
    prd.ray_tmax = current_ray().tmax;
}

// ---- spheres whose intersection reports a per-primitive material index -------------
struct MultiMaterialSphereRecord {
    BufferView<float4> spheres;
    BufferView<unsigned> sphere_materials;
};
LUCENT_RECORD(MultiMaterialSphereRecord, spheres, sphere_materials)
LUCENT_INTERSECTION(pk_sphere_intersect_material, MultiMaterialSphereRecord, SphereAttributes) {
    intersect_sphere(rec.spheres[prim], rec.sphere_materials[prim], attr);
}

// ---- a parallelogram (OptiX SDK's classic custom primitive) ------------------------
struct ParallelogramAttributes {
    float3 normal;
    float2 uv;  // position in the (v1, v2) frame, both in [0, 1] inside
};
struct ParallelogramRecord {
    float3 anchor;
    float3 v1;  // edge vectors
    float3 v2;
};
LUCENT_RECORD(ParallelogramRecord, anchor, v1, v2)
LUCENT_INTERSECTION(pk_parallelogram_intersect, ParallelogramRecord, ParallelogramAttributes) {
    const Ray& ray = current_ray();
    const float3 n = normalize(cross(rec.v1, rec.v2));
    const float dn = dot(ray.direction, n);
    if (fabsf(dn) < 1e-12f) return;
    const float t = dot(rec.anchor - ray.origin, n) / dn;
    const float3 p = ray.origin + t * ray.direction - rec.anchor;
    // Coordinates in the edge frame (edges are orthogonal in these tests).
    const float a = dot(p, rec.v1) / dot(rec.v1, rec.v1);
    const float b = dot(p, rec.v2) / dot(rec.v2, rec.v2);
    if (a < 0 || a > 1 || b < 0 || b > 1) return;
    if (potential_intersection(t)) {
        attr.normal = n;
        attr.uv = make_float2(a, b);
        report_intersection(0);
    }
}
LUCENT_BOUNDING_BOX(pk_parallelogram_bounds, ParallelogramRecord) {
    const float3 corners[4] = {rec.anchor, rec.anchor + rec.v1, rec.anchor + rec.v2,
                               rec.anchor + rec.v1 + rec.v2};
    box.lo = corners[0];
    box.hi = corners[0];
    for (const float3& c : corners) {
        box.lo = fminf(box.lo, c);
        box.hi = fmaxf(box.hi, c);
    }
}
LUCENT_CLOSEST_HIT(pk_parallelogram_hit, IdRecord, TestPayload, ParallelogramAttributes) {
    record_hit(rec, prd, attr.normal);
    prd.uv = attr.uv;
}

// ---- triangles with an attribute program: interpolated texture coordinates ---------
struct TexcoordAttributes {
    float2 texcoord;
    unsigned prim;
};
struct TexcoordRecord {
    BufferView<uint3> indices;
    BufferView<float2> texcoords;
};
LUCENT_RECORD(TexcoordRecord, indices, texcoords)
LUCENT_ATTRIBUTE(pk_texcoord_attributes, TexcoordRecord, TexcoordAttributes) {
    const uint3 tri = rec.indices[prim];
    const float u = barycentrics.x, v = barycentrics.y;
    attr.texcoord =
        rec.texcoords[tri.x] * (1.0f - u - v) + rec.texcoords[tri.y] * u + rec.texcoords[tri.z] * v;
    attr.prim = prim;
}
LUCENT_CLOSEST_HIT(pk_texcoord_hit, IdRecord, TestPayload, TexcoordAttributes) {
    record_hit(rec, prd, make_float3(0, 0, 1));
    prd.uv = attr.texcoord;
    prd.prim = attr.prim;
}

// ---- any hit ----------------------------------------------------------------------
LUCENT_ANY_HIT(pk_anyhit_ignore, NoRecord, TestPayload, TriangleAttributes) {
    prd.anyhit_count += 1;
    prd.anyhit_t = t_hit();
    ignore_intersection();
}
LUCENT_ANY_HIT(pk_anyhit_terminate, NoRecord, TestPayload, TriangleAttributes) {
    prd.anyhit_count += 1;
    prd.anyhit_t = t_hit();
    terminate_ray();
}
LUCENT_ANY_HIT(pk_anyhit_count, NoRecord, TestPayload, TriangleAttributes) {
    prd.anyhit_count += 1;
}

// ---- callables ---------------------------------------------------------------------
struct ScaleRecord {
    float factor;
};
LUCENT_RECORD(ScaleRecord, factor)
LUCENT_CALLABLE(pk_scale, ScaleRecord, float3, (float3 v)) {
    return v * rec.factor;
}

struct OffsetRecord {
    float3 offset;
};
LUCENT_RECORD(OffsetRecord, offset)
LUCENT_CALLABLE(pk_offset, OffsetRecord, float3, (float3 v)) {
    return v + rec.offset;
}

struct CallerRecord {
    Callable<float3(float3)> shade;
    BufferView<float3> output;
};
LUCENT_RECORD(CallerRecord, shade, output)
LUCENT_RAY_GENERATION(pk_call, CallerRecord) {
    const unsigned i = launch_index().x;
    rec.output[i] = rec.shade(make_float3(float(i), 1.0f, -2.0f));
}

// ---- recursion: bounce between two parallel mirrors --------------------------------
struct BounceRecord {
    Handle top;
    int bounces;
};
LUCENT_RECORD(BounceRecord, top, bounces)
LUCENT_CLOSEST_HIT(pk_bounce, BounceRecord, TestPayload, TriangleAttributes) {
    const Ray& ray = current_ray();
    prd.hit = 1;
    prd.path_length += t_hit();
    if (prd.depth >= rec.bounces) return;
    TestPayload child = make_test_payload();
    child.depth = prd.depth + 1;
    child.path_length = prd.path_length;
    const float3 p = ray.origin + t_hit() * ray.direction;
    trace(rec.top, make_ray(p, -ray.direction, 0, 1e-3f), child);
    prd.depth = child.depth;
    prd.path_length = child.path_length;
}

// ---- print -------------------------------------------------------------------------
LUCENT_RAY_GENERATION(pk_print_index, NoRecord) {
    print("lucent-print-test index=%u\n", launch_index().x);
}

// ---- textures ----------------------------------------------------------------------
struct TextureRecord {
    TextureView tex;
    BufferView<float2> uvs;
    BufferView<float4> output;
};
LUCENT_RECORD(TextureRecord, tex, uvs, output)
LUCENT_RAY_GENERATION(pk_sample_texture, TextureRecord) {
    const unsigned i = launch_index().x;
    rec.output[i] = tex2D(rec.tex, rec.uvs[i]);
}

// ---- rays with their own interval and type (a Ray stored in a buffer) --------------
struct RayListRecord {
    Handle top;
    BufferView<Ray> ray_list;
    BufferView<TestPayload> results;
};
LUCENT_RECORD(RayListRecord, top, ray_list, results)
LUCENT_RAY_GENERATION(pk_cast_rays, RayListRecord) {
    const unsigned i = launch_index().x;
    TestPayload p = make_test_payload();
    trace(rec.top, rec.ray_list[i], p);
    rec.results[i] = p;
}

// ---- any hit that looks at the candidate -------------------------------------------
struct IgnoreBeforeRecord {
    float ignore_before;
};
LUCENT_RECORD(IgnoreBeforeRecord, ignore_before)
/// Ignores candidates nearer than `ignore_before`: lets a ray skip a sphere's entry point.
LUCENT_ANY_HIT(pk_anyhit_ignore_near_sphere, IgnoreBeforeRecord, TestPayload, SphereAttributes) {
    prd.anyhit_count += 1;
    if (t_hit() < rec.ignore_before) ignore_intersection();
}

/// Alpha cut-out from the barycentrics the any-hit program receives: holes where u > 0.5.
LUCENT_ANY_HIT(pk_anyhit_cutout, NoRecord, TestPayload, TriangleAttributes) {
    prd.anyhit_count += 1;
    if (attr.barycentrics.x > 0.5f) ignore_intersection();
}

/// Cut-out from attribute-program attributes: holes where the texcoord's x > 5.
LUCENT_ANY_HIT(pk_anyhit_texcoord_cutout, NoRecord, TestPayload, TexcoordAttributes) {
    prd.anyhit_count += 1;
    if (attr.texcoord.x > 5.0f) ignore_intersection();
}

// ---- print from a closest hit --------------------------------------------------------
LUCENT_CLOSEST_HIT(pk_print_hit, IdRecord, TestPayload, TriangleAttributes) {
    record_hit(rec, prd, attr.geometric_normal);
    print("lucent-print-hit %u,%u\n", launch_index().x, launch_index().y);
}

LUCENT_RAY_GENERATION(pk_print_index_2d, NoRecord) {
    print("lucent-print-2d %u,%u\n", launch_index().x, launch_index().y);
}

/// Bounding box that prints: print() must be harmless outside a launch index.
LUCENT_BOUNDING_BOX(pk_printing_sphere_bounds, SphereRecord) {
    print("lucent-print-bounds %u\n", prim);
    const float4 s = rec.spheres[prim];
    box.lo = make_float3(s.x - s.w, s.y - s.w, s.z - s.w);
    box.hi = make_float3(s.x + s.w, s.y + s.w, s.z + s.w);
}

}  // namespace program_kinds_module
}  // namespace lucent_tests
