// libFuzzer target for the OBJ loader: any bytes must give a mesh or a lucent::Error, never
// a crash, a hang or undefined behaviour (built with ASan and UBSan by run_fuzzer.sh).
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "lucent/error.h"
#include "scene/obj_mesh.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    // The loader reads files: give it one per input, in memory-backed /tmp where possible.
    static const std::string path = "/tmp/lucent_fuzz_obj_" + std::to_string(::getpid()) + ".obj";
    if (FILE* f = std::fopen(path.c_str(), "wb")) {
        std::fwrite(data, 1, size, f);
        std::fclose(f);
    }
    try {
        lucent::scene::ObjMesh mesh = lucent::scene::load_obj_mesh(path);
        // A mesh that loads must be consistent.
        for (const uint3& t : mesh.indices)
            if (t.x >= mesh.positions.size() || t.y >= mesh.positions.size() ||
                t.z >= mesh.positions.size())
                __builtin_trap();
    } catch (const lucent::Error&) {
        // Bad input is reported, as it must be.
    }
    return 0;
}
