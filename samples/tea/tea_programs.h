// TEA random numbers as Lucent programs (Sebald §3.2, Table 2): one ray-generation launch
// fills a buffer; one program rolls Zafar et al.'s fixed key into the code, the other reads
// a per-device key (Figure 4) from its record, as the seed's modified generator does. A
// third copies a buffer in the same launches: the memory-bound baseline TEA is held to.
#pragma once

#include "lucent/device.h"

namespace tea_sample {

/// The module of this sample's programs (lucent/device/module.h).
LUCENT_MODULE(tea)

struct FixedKeyRecord {
    lucent::BufferView<uint2> out;
    unsigned rounds;
    lucent::BufferView<unsigned> first_block;  // [0]: counter of the launch's first block
};
LUCENT_RECORD(FixedKeyRecord, out, rounds, first_block)

struct DeviceKeyRecord {
    lucent::BufferView<uint2> out;
    unsigned rounds;
    lucent::BufferView<unsigned> first_block;
    uint4 key;  // generate_tea_key(initial key, (device, seed)) on the host
};
LUCENT_RECORD(DeviceKeyRecord, out, rounds, first_block, key)

struct CopyRecord {
    lucent::BufferView<uint2> out;
    lucent::BufferView<uint2> source;  // on the device already, as large as out
};
LUCENT_RECORD(CopyRecord, out, source)


LUCENT_RAY_GENERATION(tea_fixed_key, tea_sample::FixedKeyRecord) {
    const unsigned i = lucent::launch_index().x;
    rec.out[i] =
        lucent::tea(make_uint2(rec.first_block[0u] + i, 0u), lucent::zafar_tea_key(), rec.rounds);
}

LUCENT_RAY_GENERATION(tea_device_key, tea_sample::DeviceKeyRecord) {
    const unsigned i = lucent::launch_index().x;
    rec.out[i] = lucent::tea(make_uint2(rec.first_block[0u] + i, 0u), rec.key, rec.rounds);
}

LUCENT_RAY_GENERATION(tea_copy, tea_sample::CopyRecord) {
    const unsigned i = lucent::launch_index().x;
    rec.out[i] = rec.source[i];
}

}  // namespace tea_sample
