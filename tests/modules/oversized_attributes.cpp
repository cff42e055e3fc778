// Must not compile: an intersection program whose attribute type is larger than the engine's
// attribute space. The test (device_api.oversized_attributes) expects the compiler's message
// to name the limit and the fix.
#include "lucent/device.h"

namespace oversized {
LUCENT_MODULE(oversized)
struct HugeAttributes {
    float values[65];  // 260 bytes: one float over lucent::kMaxAttributeBytes
};
LUCENT_INTERSECTION(intersect, lucent::NoRecord, HugeAttributes) {
    if (lucent::potential_intersection(1.0f)) lucent::report_intersection(0);
}
}  // namespace oversized
