// The benchmarks' option checks. The CLI's parser checks its flags before a benchmark runs,
// but a C++ or Python program calling a benchmark (bench_*_json) has no parser in front of
// it, so each benchmark checks its options itself. Every message names the option both
// ways, as the call's field and as the CLI's flag ("repeat (--repeat)"), with the range it
// must lie in.
#pragma once

namespace lucent::bench {

/// Throws lucent::Error "<command>: <option> is <value>; it must lie in [low, high]".
void require_in_range(const char* command, const char* option, long long value, long long low,
                      long long high);

/// Throws lucent::Error unless the image is at least 1x1 and at most 65536x65536.
void require_image_size(const char* command, unsigned width, unsigned height);

}  // namespace lucent::bench
