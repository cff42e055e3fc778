// Programs of multi_device_test: a per-index pattern that traces a sphere, an
// accumulation that reads what it wrote before, the per-device TEA key, a write into a
// buffer that is not launch-shaped, and a pass that reads its neighbours.
#pragma once

#include "tests/programs/common.h"

namespace lucent_tests {
// Each test module in its own inline namespace: its own LUCENT_MODULE, while the tests
// still name its programs and types unqualified.
inline namespace multi_device_module {
LUCENT_MODULE(test_multi_device)

struct PatternRecord {
    Handle top;
    BufferView<float4> image;  // launch-shaped (1D, 2D or 3D like the launch)
    unsigned dims;             // of the launch: 1, 2 or 3
    unsigned repeats;          // traces per index (more: a longer launch)
};
LUCENT_RECORD(PatternRecord, top, image, dims, repeats)
/// Traces a ray through each launch index at a sphere; stores the hit t, the launch index
/// and a hash, so every element depends on the index that wrote it.
LUCENT_RAY_GENERATION(md_pattern, PatternRecord) {
    const uint3 i = launch_index(), n = launch_size();
    const float u = (float(i.x) + 0.5f) / float(n.x) * 2.0f - 1.0f;
    const float v = (float(i.y) + 0.5f) / float(n.y) * 2.0f - 1.0f;
    TestPayload p = make_test_payload();
    for (unsigned r = 0; r < rec.repeats; ++r) {
        p = make_test_payload();
        trace(rec.top, make_ray(make_float3(u, v, -5.0f), make_float3(0, 0, 1), 0, 1e-4f), p);
    }
    const unsigned hash = tea<4>(make_uint2(i.x, i.y * 4096u + i.z), zafar_tea_key()).x;
    const float4 value = make_float4(p.hit > 0 ? p.t : -1.0f, float(i.x), float(i.y + 1000u * i.z),
                                     float(hash >> 8));
    if (rec.dims == 1) rec.image[i.x] = value;
    else if (rec.dims == 2) rec.image[make_uint2(i.x, i.y)] = value;
    else rec.image[i] = value;
}

struct AccumulateRecord {
    BufferView<float> sum;  // input-output, 2D: each launch adds its round to what is there
    unsigned round;
};
LUCENT_RECORD(AccumulateRecord, sum, round)
LUCENT_RAY_GENERATION(md_accumulate, AccumulateRecord) {
    const uint2 i = make_uint2(launch_index().x, launch_index().y);
    rec.sum[i] = rec.sum[i] * 0.5f + float(rec.round * 7u + i.x * 3u + i.y);
}

struct NeighbourRecord {
    BufferView<float> source;  // written by md_accumulate in the launch before
    BufferView<float> blurred;
};
LUCENT_RECORD(NeighbourRecord, source, blurred)
/// The mean of the 3x3 neighbourhood: reads pixels other devices wrote.
LUCENT_RAY_GENERATION(md_blur, NeighbourRecord) {
    const uint3 i = launch_index(), n = launch_size();
    float total = 0;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            int x = int(i.x) + dx, y = int(i.y) + dy;
            x = x < 0 ? 0 : x >= int(n.x) ? int(n.x) - 1 : x;
            y = y < 0 ? 0 : y >= int(n.y) ? int(n.y) - 1 : y;
            total += rec.source[make_uint2(unsigned(x), unsigned(y))];
        }
    rec.blurred[make_uint2(i.x, i.y)] = total / 9.0f;
}

struct KeyRecord {
    BufferView<uint4> keys;  // 2D
};
LUCENT_RECORD(KeyRecord, keys)
LUCENT_RAY_GENERATION(md_device_key, KeyRecord) {
    rec.keys[make_uint2(launch_index().x, launch_index().y)] = device_tea_key();
}

struct LastRowRecord {
    BufferView<float> last_row;  // 1D, one element per column: not launch-shaped
};
LUCENT_RECORD(LastRowRecord, last_row)
/// The indices of the last row write a buffer the shape of no launch: such a launch must
/// run whole on one device, and its buffer reach every device.
LUCENT_RAY_GENERATION(md_last_row, LastRowRecord) {
    const uint3 i = launch_index(), n = launch_size();
    if (i.y + 1 == n.y) rec.last_row[i.x] = float(i.x * 3u + 1u);
}

struct SpreadRecord {
    BufferView<const float> last_row;  // what md_last_row wrote; only read here
    BufferView<float> spread;    // 2D
};
LUCENT_RECORD(SpreadRecord, last_row, spread)
LUCENT_RAY_GENERATION(md_spread, SpreadRecord) {
    const uint3 i = launch_index();
    rec.spread[make_uint2(i.x, i.y)] = rec.last_row[i.x] + float(i.y);
}

struct RaiseRecord {
    BufferView<unsigned> done;  // 2D
};
LUCENT_RECORD(RaiseRecord, done)
/// Raises a user exception on every 37th row at x = 5.
LUCENT_RAY_GENERATION(md_raise, RaiseRecord) {
    const uint3 i = launch_index();
    if (i.y % 37u == 36u && i.x == 5u) throw_exception(kUserExceptionBase + 3, i.y);
    rec.done[make_uint2(i.x, i.y)] = 1u;
}

}  // namespace multi_device_module
}  // namespace lucent_tests
