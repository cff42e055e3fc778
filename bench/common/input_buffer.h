// A Context input buffer holding `values`: how the benchmarks hand their data to programs.
#pragma once

#include <memory>
#include <vector>

#include "lucent/context.h"

namespace lucent::bench {

template <class T>
std::shared_ptr<Buffer> input_buffer(Context& ctx, const std::vector<T>& values) {
    auto buffer = ctx.create_buffer<T>(BufferType::kInput, unsigned(values.size()));
    buffer->upload(values);
    return buffer;
}

}  // namespace lucent::bench
