// Must not compile: ignore_intersection() in a closest-hit program (it ends an any-hit
// program only). The test (device_api.end_any_hit_outside_any_hit) expects the compiler's
// message to say where to call it.
#include "lucent/device.h"

namespace stray {
LUCENT_MODULE(stray)
struct Payload {
    int hit;
};
LUCENT_CLOSEST_HIT(shade, lucent::NoRecord, Payload, lucent::TriangleAttributes) {
    prd.hit = 1;
    ignore_intersection();
}
}  // namespace stray
