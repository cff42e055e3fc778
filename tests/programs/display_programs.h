// Programs of display_test: a launch that copies chosen linear values into its output, so
// the output's newest copy is where the launch ran (on a GPU: device memory).
#pragma once

#include "tests/programs/common.h"

namespace lucent_tests {
// Each test module in its own inline namespace: its own LUCENT_MODULE, while the tests
// still name its programs and types unqualified.
inline namespace display_module {
LUCENT_MODULE(test_display)

struct CopyImageRecord {
    BufferView<float4> source;  // 2D, the launch's size
    BufferView<float4> image;   // 2D output
};
LUCENT_RECORD(CopyImageRecord, source, image)
LUCENT_RAY_GENERATION(dt_copy_image, CopyImageRecord) {
    const uint3 i = launch_index();
    rec.image[make_uint2(i.x, i.y)] = rec.source[make_uint2(i.x, i.y)];
}

}  // namespace display_module
}  // namespace lucent_tests
