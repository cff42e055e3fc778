// One of two modules that both define a program named `closest_hit` (modules_test): each
// in its own namespace with its own LUCENT_MODULE, so one program holds both.
#pragma once

#include "tests/programs/common.h"

namespace twin_a {
LUCENT_MODULE(test_twin_a)

struct TwinRecord {
    unsigned id;
};
LUCENT_RECORD(TwinRecord, id)

/// Tells which module shaded the hit: 1000 + the material's id.
LUCENT_CLOSEST_HIT(closest_hit, TwinRecord, lucent_tests::TestPayload,
                   lucent::TriangleAttributes) {
    prd.hit = 1;
    prd.id = 1000u + rec.id;
    prd.t = lucent::t_hit();
}
}  // namespace twin_a
