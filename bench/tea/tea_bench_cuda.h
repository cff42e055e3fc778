// `lucent bench tea --backend cuda`, stream-ordered: TEA output made in 1 MB launches queued
// one after another on a stream (no host round trip per launch), into device memory and with
// a read-back into pinned host memory that overlaps the next launches, each measured against
// the hardware's own rate for the same bytes (a device-to-device copy, a pinned
// device-to-host copy) in the same run. The header needs no CUDA headers; the function
// exists when LUCENT_HAVE_CUDA is defined.
#pragma once

#include <string>

#include "lucent/device/vector_math.h"

namespace lucent::cuda {

/// The largest output the stream-ordered rows hold (device memory and pinned host memory
/// of this size each).
constexpr unsigned kTeaStreamMaxMegabytes = 4096;

struct TeaStreamInput {
    unsigned megabytes = 2048;  // 1 MB launches per row
    unsigned rounds = 2;
    uint4 fixed_key{}, generated_key{};
    int repeat = 3;  // each row timed this often; the median is reported
};

/// One row: the median rate over the repeats, its spread, and the XOR of every output word
/// (0 for the copies, whose bytes are not TEA's).
struct TeaStreamRow {
    double mb_per_s = 0, min_mb_per_s = 0, max_mb_per_s = 0;
    unsigned checksum = 0;
};

struct TeaStreamResult {
    std::string device;
    int repeat = 0;
    // Into device memory; the baseline is a 1 MB device-to-device copy per launch.
    TeaStreamRow device_fixed, device_generated, device_copy;
    // The same, each megabyte then copied into pinned host memory on a second stream while
    // the next launches run; the baseline is a 1 MB pinned device-to-host copy per launch.
    TeaStreamRow readback_fixed, readback_generated, readback_copy;
};

/// Runs every row on device 0. Throws lucent::Error without a driver or GPU, or when
/// megabytes exceeds kTeaStreamMaxMegabytes.
TeaStreamResult run_tea_stream_cuda(const TeaStreamInput& input);

}  // namespace lucent::cuda
