#include "bench/gpu/gpu_session.h"

#include "lucent/error.h"

namespace lucent::cuda {

const DriverApi& require_bench_driver() {
    std::string why;
    const DriverApi* d = driver(&why);
    if (!d)
        throw Error("--backend cuda: no NVIDIA driver or GPU usable (" + why +
                    "); run with --backend cpu");
    return *d;
}

}  // namespace lucent::cuda
