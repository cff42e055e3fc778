#include "bench/gpu/bench_sources.h"

#include <utility>

namespace lucent::cuda {

CompileRequest bench_kernel_request(std::string name, std::string source,
                                    std::vector<std::string> options, int sm) {
    CompileRequest request =
        embedded_request(std::move(name), std::move(source), std::move(options), sm);
    for (const EmbeddedSource& s : bench_embedded_sources())
        request.headers.emplace_back(std::string(s.name), std::string(s.text));
    return request;
}

}  // namespace lucent::cuda
