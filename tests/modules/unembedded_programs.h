// A module that modules_test includes but does not embed (no lucent_add_programs): it runs
// on the CPU, and the GPU's JIT needs its text given at run time.
#pragma once

#include "lucent/device.h"

namespace unembedded {
LUCENT_MODULE(test_unembedded)

struct FillRecord {
    lucent::BufferView<unsigned> out;
};
LUCENT_RECORD(FillRecord, out)

LUCENT_RAY_GENERATION(fill, FillRecord) {
    const unsigned i = lucent::launch_index().x;
    rec.out[i] = 7u * i + 1u;
}
}  // namespace unembedded
