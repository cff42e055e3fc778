// libFuzzer target for the scene loaders (JSON, OBJ + MTL, PLY, glTF): any bytes must give a scene
// or a lucent::Error, never a crash, a hang or undefined behaviour. The extension of the
// temporary file picks the loader: the environment's LUCENT_FUZZ_EXTENSION (set by
// run_fuzzer.sh), so that one executable, built once, fuzzes all four.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "lucent/error.h"
#include "scene/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const std::string path = [] {
        const char* extension = std::getenv("LUCENT_FUZZ_EXTENSION");
        return "/tmp/lucent_fuzz_scene_" + std::to_string(::getpid()) +
               (extension ? extension : ".json");
    }();
    if (FILE* f = std::fopen(path.c_str(), "wb")) {
        std::fwrite(data, 1, size, f);
        std::fclose(f);
    }
    try {
        lucent::scene::Scene scene = lucent::scene::load_scene(path);
        for (const auto& mesh : scene.meshes)
            for (size_t t = 0; t < mesh.indices.size(); ++t) {
                const uint3 i = mesh.indices[t];
                if (i.x >= mesh.positions.size() || i.y >= mesh.positions.size() ||
                    i.z >= mesh.positions.size() || mesh.materials[t] >= scene.materials.size())
                    __builtin_trap();  // a loaded scene must be consistent
            }
        for (const auto& instance : scene.instances)
            if (instance.mesh >= scene.meshes.size()) __builtin_trap();
    } catch (const lucent::Error&) {
    }
    return 0;
}
