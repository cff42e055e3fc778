// TEA random numbers as Lucent programs (Sebald §3.2, Table 2): one ray-generation launch
// fills a buffer; one program rolls Zafar et al.'s fixed key into the code, the other reads
// a per-device key (Figure 4) from its record, as the seed's modified generator does.
#pragma once

#include "lucent/device.h"

namespace tea_sample {

struct FixedKeyRecord {
    lucent::BufferView<uint2> out;
    unsigned rounds;
    unsigned first_block;  // counter of the launch's first block
};
LUCENT_RECORD(FixedKeyRecord, out, rounds, first_block)

struct DeviceKeyRecord {
    lucent::BufferView<uint2> out;
    unsigned rounds;
    unsigned first_block;
    uint4 key;  // generate_tea_key(initial key, (device, seed)) on the host
};
LUCENT_RECORD(DeviceKeyRecord, out, rounds, first_block, key)

}  // namespace tea_sample

LUCENT_RAY_GENERATION(tea_fixed_key, tea_sample::FixedKeyRecord) {
    const unsigned i = lucent::launch_index().x;
    rec.out[i] =
        lucent::tea(make_uint2(rec.first_block + i, 0u), lucent::zafar_tea_key(), rec.rounds);
}

LUCENT_RAY_GENERATION(tea_device_key, tea_sample::DeviceKeyRecord) {
    const unsigned i = lucent::launch_index().x;
    rec.out[i] = lucent::tea(make_uint2(rec.first_block + i, 0u), rec.key, rec.rounds);
}
