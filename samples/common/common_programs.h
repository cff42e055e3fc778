// The device code the samples share, one program module that each sample's module includes:
// the mesh records and the attribute programs of scene::Scene triangles, the light layouts
// (lights.h), sampling (sampling.h), the pinhole camera in a buffer (camera.h) and the
// origins of secondary rays (ray_offset.h).
#pragma once

#include "lucent/device.h"
#include "samples/common/camera.h"
#include "samples/common/lights.h"
#include "samples/common/ray_offset.h"
#include "samples/common/sampling.h"

namespace sample_common {

/// The module of the shared programs (lucent/device/module.h).
LUCENT_MODULE(sample_common)

/// A triangle mesh's vertex data, for the attribute programs (variables "positions" and
/// "triangles" on each GeometryTriangles: samples/scene_setup.h's mesh_group sets them).
/// Read-only views (BufferView<const T>): the attribute programs only read them.
struct MeshRecord {
    lucent::BufferView<const float3> positions;
    lucent::BufferView<const uint3> triangles;
};
LUCENT_RECORD(MeshRecord, positions, triangles)

/// The same with the per-vertex texture coordinates ("uvs"; empty when the mesh has none).
struct TexturedMeshRecord {
    lucent::BufferView<const float3> positions;
    lucent::BufferView<const uint3> triangles;
    lucent::BufferView<const float2> uvs;
};
LUCENT_RECORD(TexturedMeshRecord, positions, triangles, uvs)

/// What a triangle hit gives the hit programs: the geometric normal (object space, not
/// normalised; it faces outwards by the triangle's winding).
struct MeshNormal {
    float3 geometric_normal;
};

/// The geometric normal and the interpolated texture coordinate ((0, 0) without uvs).
struct MeshNormalUv {
    float3 geometric_normal;
    float2 uv;
};

/// The diffuse map's colour at texture coordinate uv: what multiplies a material's Kd (a 1x1
/// white texel when it has no map, samples/scene_setup.h's DiffuseTextures). OBJ texture
/// coordinates start at the bottom of the image; texel row 0 is its top.
LUCENT_HD inline float3 diffuse_texel(const lucent::TextureView& map, float2 uv) {
    return make_float3(lucent::tex2D(map, make_float2(uv.x, 1.0f - uv.y)));
}

LUCENT_ATTRIBUTE(mesh_normal, sample_common::MeshRecord, sample_common::MeshNormal) {
    const uint3 t = rec.triangles[prim];
    attr.geometric_normal =
        cross(rec.positions[t.y] - rec.positions[t.x], rec.positions[t.z] - rec.positions[t.x]);
}

LUCENT_ATTRIBUTE(mesh_normal_uv, sample_common::TexturedMeshRecord, sample_common::MeshNormalUv) {
    const uint3 t = rec.triangles[prim];
    const float3 p0 = rec.positions[t.x], p1 = rec.positions[t.y], p2 = rec.positions[t.z];
    attr.geometric_normal = cross(p1 - p0, p2 - p0);
    attr.uv = make_float2(0.0f, 0.0f);
    if (rec.uvs.count() > 0) {
        const float w = 1.0f - barycentrics.x - barycentrics.y;
        attr.uv = w * rec.uvs[t.x] + barycentrics.x * rec.uvs[t.y] + barycentrics.y * rec.uvs[t.z];
    }
}

}  // namespace sample_common
