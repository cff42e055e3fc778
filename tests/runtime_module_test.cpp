// Modules compiled at run time: Context::add_module with the text of a module that is not
// compiled into the program. The system's C++ compiler builds it into a shared library
// that this test executable (built with ENABLE_EXPORTS) lends its engine to; its programs
// then run on the CPU like compiled-in ones, and its types match the program's own
// (buffers of float3, triangle attributes) across the two binaries.
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "core/runtime_module.h"
#include "test_support.h"

namespace lucent_tests {
namespace {

namespace fs = std::filesystem;

/// A module this program does not contain: rays down -z at x = -0.5, -0.25, ..., hitting
/// the unit triangle of the test's scene or missing it; each writes (t * scale, primitive)
/// or (-2, 99) for a miss.
std::string shooter_text(const std::string& module, float miss_t = -2.0f) {
    return "#include \"lucent/device.h\"\n"
           "namespace " + module + " {\n"
           "LUCENT_MODULE(" + module + ")\n"
           "using namespace lucent;\n"
           "struct Payload { float t; unsigned prim; };\n"
           "struct Shooter { Handle scene; BufferView<float2> hits; float scale; };\n"
           "LUCENT_RECORD(Shooter, scene, hits, scale)\n"
           "LUCENT_RAY_GENERATION(shoot, Shooter) {\n"
           "    const uint3 i = launch_index();\n"
           "    Payload p{0.0f, 0u};\n"
           "    const float3 origin = make_float3(0.25f * float(i.x) - 0.5f, 0.1f, 1.0f);\n"
           "    trace(rec.scene, make_ray(origin, make_float3(0, 0, -1), 0, 0.0f), p);\n"
           "    rec.hits[i.x] = make_float2(p.t * rec.scale, float(p.prim));\n"
           "}\n"
           "LUCENT_CLOSEST_HIT(hit, NoRecord, Payload, TriangleAttributes) {\n"
           "    prd.t = t_hit();\n"
           "    prd.prim = primitive_index();\n"
           "}\n"
           "LUCENT_MISS(miss, NoRecord, Payload) {\n"
           "    prd.t = " + std::to_string(miss_t) + "f;\n"
           "    prd.prim = 99u;\n"
           "}\n"
           "}\n";
}

/// The kernel cache (and so the compiled modules) in a folder of this test's own.
struct PrivateCache {
    fs::path path;
    PrivateCache() {
        path = fs::temp_directory_path() / ("lucent_runtime_module_test_" + std::to_string(::getpid()));
        fs::remove_all(path);
        fs::create_directories(path);
        ::setenv("LUCENT_CACHE_DIR", path.c_str(), 1);
    }
    ~PrivateCache() {
        ::unsetenv("LUCENT_CACHE_DIR");
        fs::remove_all(path);
    }
    size_t libraries() const {
        size_t n = 0;
        for (auto& entry : fs::directory_iterator(path / "cpu-modules"))
            n += entry.path().extension() == ".so";
        return n;
    }
};

/// Launches `module`'s shooter: 5 rays at a triangle 1 unit below their origins, whose left
/// edge passes x = -0.38 and right edge x = 0.57 where they cross it.
std::vector<float2> run_shooter(Context& ctx, const ModuleInfo& module, float scale = 1.0f) {
    auto hit = ctx.create_program(module, "hit");
    ctx.set_ray_type(0, RayTypeDesc{"probe", hit->desc().payload});
    ctx.set_ray_generation_program(0, ctx.create_program(module, "shoot"));
    ctx.set_miss_program(0, ctx.create_program(module, "miss"));
    auto vertices = ctx.create_buffer<float3>(BufferType::kInput, 3);
    vertices->upload(std::vector<float3>{{-0.6f, -1, 0}, {1.5f, -1, 0}, {-0.2f, 1, 0}});
    auto triangle = ctx.create_geometry_triangles();
    triangle->set_vertices(vertices);
    auto material = ctx.create_material();
    material->set_closest_hit(0, hit);
    auto instance = ctx.create_geometry_instance();
    instance->set_geometry(triangle);
    instance->add_material(material);
    auto scene = ctx.create_geometry_group();
    scene->add_child(instance);
    auto hits = ctx.create_buffer<float2>(BufferType::kOutput, 5);
    ctx["scene"] = scene;
    ctx["hits"] = hits;
    ctx["scale"] = scale;
    ctx.launch(0, 5);
    const float2* data = hits->data<float2>();
    return {data, data + 5};
}

ContextOptions cpu_options() {
    ContextOptions options;
    options.backend = BackendKind::kCpu;
    options.threads = 2;
    return options;
}

TEST(RuntimeModules, ATextCompiledAtRunTimeRunsOnTheCpuWithTheProgramsTypes) {
    PrivateCache cache;
    Context ctx(cpu_options());
    const ModuleInfo& module =
        ctx.add_module(ModuleSource::from_text("shooter_a.h", shooter_text("runtime_shooter_a")));
    EXPECT_EQ(module.name(), "runtime_shooter_a");
    EXPECT_EQ(find_module("runtime_shooter_a"), &module);
    const std::vector<float2> hits = run_shooter(ctx, module, 2.0f);
    // x = -0.5 misses the triangle, the rest hit it at t = 1; the record's scale doubles both.
    ASSERT_EQ(hits.size(), 5u);
    EXPECT_FLOAT_EQ(hits[0].x, -4.0f);  // the miss program's -2, scaled too
    EXPECT_FLOAT_EQ(hits[0].y, 99.0f);
    for (int i = 1; i < 5; ++i) {
        EXPECT_NEAR(hits[i].x, 2.0f, 1e-6f) << "ray " << i;
        EXPECT_FLOAT_EQ(hits[i].y, 0.0f) << "ray " << i;
    }
    EXPECT_EQ(cache.libraries(), 1u);  // kept for the next process
}

TEST(RuntimeModules, TheSameTextAgainIsTheLoadedModuleAndADifferentOneIsRefused) {
    PrivateCache cache;
    Context first(cpu_options());
    const ModuleInfo& a =
        first.add_module(ModuleSource::from_text("shooter_b.h", shooter_text("runtime_shooter_b")));
    Context second(cpu_options());
    const ModuleInfo& b =
        second.add_module(ModuleSource::from_text("shooter_b.h", shooter_text("runtime_shooter_b")));
    EXPECT_EQ(&a, &b);
    EXPECT_FLOAT_EQ(run_shooter(second, b)[0].x, -2.0f);
    Context third(cpu_options());  // (a context that has the module refuses it itself)
    expect_error(
        [&] {
            third.add_module(ModuleSource::from_text("shooter_b2.h",
                                                      shooter_text("runtime_shooter_b", -3.0f)));
        },
        {"runtime_shooter_b", "shooter_b2.h", "different text", "another LUCENT_MODULE name"},
        "a second text under a loaded module's name");
}

TEST(RuntimeModules, CompileErrorsNameTheModulesFileAndLine) {
    PrivateCache cache;
    Context ctx(cpu_options());
    std::string text = shooter_text("runtime_broken");
    // Line 5 of the text becomes a line the compiler rejects.
    size_t line5 = 0;
    for (int i = 0; i < 4; ++i) line5 = text.find('\n', line5) + 1;
    text.insert(line5, "not_a_type broken_here;\n");
    const std::string message = expect_error(
        [&] { ctx.add_module(ModuleSource::from_text("broken_module.h", text)); },
        {"could not compile module 'runtime_broken'", "broken_module.h:5", "not_a_type"},
        "a module the compiler rejects");
    EXPECT_EQ(find_module("runtime_broken"), nullptr) << message;
}

TEST(RuntimeModules, WithoutACompilerTheErrorSaysWhatToInstall) {
    PrivateCache cache;
    ::setenv("LUCENT_CXX", "/nonexistent/c++", 1);
    Context ctx(cpu_options());
    expect_error(
        [&] {
            ctx.add_module(
                ModuleSource::from_text("shooter_c.h", shooter_text("runtime_shooter_c")));
        },
        {"/nonexistent/c++", "LUCENT_CXX", "apt install g++"}, "no C++ compiler");
    ::unsetenv("LUCENT_CXX");
    EXPECT_EQ(find_module("runtime_shooter_c"), nullptr);
}

TEST(RuntimeModules, TheCompilerCommandComesFromLucentCxxThenCxxThenPath) {
    ::setenv("LUCENT_CXX", "ccache g++", 1);
    EXPECT_EQ(core::module_compiler_command(), (std::vector<std::string>{"ccache", "g++"}));
    ::unsetenv("LUCENT_CXX");
    const char* cxx = std::getenv("CXX");
    const std::string saved = cxx ? cxx : "";
    ::setenv("CXX", "clang++", 1);
    EXPECT_EQ(core::module_compiler_command(), (std::vector<std::string>{"clang++"}));
    ::unsetenv("CXX");
    const std::vector<std::string> found = core::module_compiler_command();
    ASSERT_EQ(found.size(), 1u);
    EXPECT_TRUE(found[0].ends_with("c++") || found[0].ends_with("g++") ||
                found[0].ends_with("clang++"))
        << found[0];
    if (!saved.empty()) ::setenv("CXX", saved.c_str(), 1);
}

TEST(RuntimeModules, ARunTimeModuleJoinsTheMegakernelForTheGpu) {
#if LUCENT_HAVE_CUDA
    PrivateCache cache;
    ContextOptions options = cpu_options();
    options.jit_check_sm = 90;
    std::unique_ptr<Context> ctx;
    try {
        ctx = std::make_unique<Context>(options);
    } catch (const Error& e) {
        GTEST_SKIP() << "no NVRTC here: " << e.what();
    }
    const ModuleInfo& module =
        ctx->add_module(ModuleSource::from_text("shooter_d.h", shooter_text("runtime_shooter_d")));
    const std::vector<float2> hits = run_shooter(*ctx, module);
    EXPECT_FLOAT_EQ(hits[0].x, -2.0f);
    EXPECT_NEAR(hits[1].x, 1.0f, 1e-6f);  // and the megakernel compiled for sm_90
#else
    GTEST_SKIP() << "built without the CUDA backend";
#endif
}

}  // namespace
}  // namespace lucent_tests
