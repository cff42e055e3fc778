// Program modules: each program belongs to the module its namespace declares, contexts
// find programs through their modules, module texts come from lucent_add_programs or from
// the caller at run time, and every misuse says which module, file and fix.
#include <filesystem>
#include <fstream>

#include "test_support.h"
#include "tests/modules/undeclared_occlusion_programs.h"
#include "tests/modules/undeclared_ray_flags_programs.h"
#include "tests/modules/unembedded_programs.h"
#include "tests/programs/occlusion_programs.h"
#include "tests/programs/twin_a_programs.h"
#include "tests/programs/twin_b_programs.h"

namespace lucent_tests {
namespace {

namespace fs = std::filesystem;

const std::string kUnembeddedPath = std::string(LUCENT_TESTS_DIR) + "/modules/unembedded_programs.h";

std::string read_file(const std::string& path) {
    std::ifstream in(path);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

/// A fresh directory under the system's temporary one, removed at the end of the test.
struct TempDir {
    fs::path path;
    TempDir() {
        path = fs::temp_directory_path() /
               ("lucent_modules_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
                "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(path);
        fs::create_directories(path);
    }
    ~TempDir() { fs::remove_all(path); }
    std::string write(const std::string& name, const std::string& text) const {
        fs::path file = path / name;
        fs::create_directories(file.parent_path());
        std::ofstream(file) << text;
        return file.string();
    }
};

/// Whether this build can compile megakernels here (the CUDA backend and NVRTC).
bool can_jit_check() {
#if LUCENT_HAVE_CUDA
    try {
        ContextOptions options;
        options.backend = BackendKind::kCpu;
        options.jit_check_sm = 90;
        Context ctx(options);
        return true;
    } catch (const Error&) {
        return false;
    }
#else
    return false;
#endif
}

ContextOptions jit_check_options() {
    ContextOptions options;
    options.backend = BackendKind::kCpu;
    options.threads = 2;
    options.jit_check_sm = 90;
    return options;
}

/// Launches unembedded::fill over 4 indices; returns what it wrote.
std::vector<unsigned> run_fill(Context& ctx) {
    ctx.set_entry_point_count(1);
    auto fill = ctx.create_program(LUCENT_PROGRAM(unembedded::fill));
    auto out = ctx.create_buffer<unsigned>(BufferType::kOutput, 4);
    (*fill)["out"] = out;
    ctx.set_ray_generation_program(0, fill);
    ctx.launch(0, 4);
    return read_buffer<unsigned>(*out);
}

TEST(Modules, EachProgramBelongsToTheModuleItsNamespaceDeclares) {
    const ProgramDesc& a = LUCENT_PROGRAM(twin_a::closest_hit);
    const ProgramDesc& b = LUCENT_PROGRAM(twin_b::closest_hit);
    EXPECT_NE(&a, &b);
    EXPECT_EQ(a.name, "closest_hit");
    EXPECT_EQ(b.name, "closest_hit");
    ASSERT_NE(a.module, nullptr);
    ASSERT_NE(b.module, nullptr);
    EXPECT_EQ(a.module->name(), "test_twin_a");
    EXPECT_EQ(b.module->name(), "test_twin_b");
    EXPECT_EQ(find_module("test_twin_a"), a.module);
    EXPECT_EQ(a.module->find("closest_hit"), &a);
    EXPECT_EQ(a.module->programs().size(), 1u);
    // What the GPU's generator needs comes from the declarations.
    EXPECT_FALSE(a.module->uses(kUsesOccluded));
    EXPECT_TRUE(find_module("test_occlusion")->uses(kUsesOccluded));
}

TEST(Modules, TwoModulesDefiningOneNameRunSideBySideAndAreNamedByModule) {
    Context ctx(test_context_options());
    const ModuleInfo& module_a = ctx.add_module("test_twin_a");
    const ModuleInfo& module_b = ctx.add_module("test_twin_b");
    expect_error([&] { ctx.create_program("closest_hit"); },
                 {"closest_hit", "test_twin_a", "test_twin_b", "create_program(module, name)"},
                 "an ambiguous name");

    ctx.set_entry_point_count(1);
    ctx.set_ray_type<TestPayload>(0, "radiance");
    ctx.set_miss_program(0, program(ctx, LUCENT_PROGRAM(common_miss)));
    auto caster = program(ctx, LUCENT_PROGRAM(common_cast));
    ctx.set_ray_generation_program(0, caster);
    // Left square shaded by module a's closest_hit, right square by module b's.
    auto left = make_instance(ctx, make_triangles(ctx, square_at(5, -10, 0)),
                              make_material(ctx, ctx.create_program(module_a, "closest_hit"), 3));
    auto right = make_instance(ctx, make_triangles(ctx, square_at(5, 0, 10)),
                               make_material(ctx, ctx.create_program(module_b, "closest_hit"), 4));
    (*caster)["top"] = make_geometry_group(ctx, {left, right});
    (*caster)["rays"] = input_buffer(ctx, std::vector<CastRay>{
                                              cast_ray(make_float3(-5, 0, 0), make_float3(0, 0, 1)),
                                              cast_ray(make_float3(5, 0, 0), make_float3(0, 0, 1)),
                                          });
    auto results = ctx.create_buffer<TestPayload>(BufferType::kOutput, 2);
    (*caster)["results"] = results;
    ctx.launch(0, 2);
    const auto got = read_buffer<TestPayload>(*results);
    EXPECT_EQ(got[0].id, 1003u);
    EXPECT_EQ(got[1].id, 2004u);
    EXPECT_NEAR(got[0].t, 5.0f, kEps);
    EXPECT_NEAR(got[1].t, 5.0f, kEps);
}

TEST(Modules, ContextsFindProgramsOnlyInTheirModules) {
    Context ctx;
    expect_error([&] { ctx.add_module("no_such_module"); },
                 {"no_such_module", "test_twin_a", "include"}, "an unknown module");
    expect_error([&] { ctx.create_program("fill"); }, {"fill", "add_module"},
                 "a name before any module");
    const ModuleInfo& module = ctx.add_module("test_unembedded");
    EXPECT_EQ(ctx.create_program("fill")->kind(), ProgramKind::kRayGeneration);
    expect_error([&] { ctx.create_program(module, "no_such_program"); },
                 {"test_unembedded", "no_such_program", "fill"}, "an unknown program");
    // Creating a program from its description adds its module.
    Context other;
    other.create_program(LUCENT_PROGRAM(twin_b::closest_hit));
    ASSERT_EQ(other.added_modules().size(), 1u);
    EXPECT_EQ(other.added_modules()[0]->name(), "test_twin_b");
}

void not_a_program() {}

TEST(Modules, LucentProgramOfAPlainFunctionSaysWhatAProgramIs) {
    expect_error([] { LUCENT_PROGRAM(not_a_program); }, {"not_a_program", "LUCENT_MODULE"},
                 "a plain function");
}

TEST(Modules, EmbeddedTextsAreTheModulesHeaderAndItsIncludes) {
    const ModuleSource* twin = embedded_module_source("test_twin_a");
    ASSERT_NE(twin, nullptr);
    EXPECT_EQ(twin->module, "test_twin_a");
    EXPECT_EQ(fs::path(twin->main).filename(), "twin_a_programs.h");
    ASSERT_EQ(twin->files.size(), 2u);  // itself and tests/programs/common.h
    EXPECT_EQ(fs::path(twin->files[1].first).filename(), "common.h");
    // Its include is rewritten to the absolute name NVRTC is given.
    EXPECT_NE(twin->files[0].second.find("#include \"" + twin->files[1].first + "\""),
              std::string::npos);
    // The library embeds no program module of its own: a module linked without
    // lucent_add_programs has no text.
    EXPECT_EQ(embedded_module_source("test_unembedded"), nullptr);
}

TEST(Modules, SourceFromFileFollowsRelativeIncludesAndNamesWhatIsMissing) {
    TempDir dir;
    dir.write("other.h", "// other\n");
    dir.write("sub/helper.h", "#pragma once\n#include \"../other.h\"\n");
    const std::string main =
        dir.write("main.h",
                  "#include \"lucent/device.h\"\n#include \"sub/helper.h\"\nnamespace m {\n"
                  "LUCENT_MODULE(from_disk, lucent::kUsesOccluded)\n}\n");
    const ModuleSource source = ModuleSource::from_file(main);
    EXPECT_EQ(source.module, "from_disk");
    ASSERT_EQ(source.files.size(), 3u);
    EXPECT_EQ(source.main, fs::path(main).lexically_normal().string());
    // Lucent's headers stay as they are; the module's own are rewritten to absolute names.
    EXPECT_NE(source.files[0].second.find("#include \"lucent/device.h\""), std::string::npos);
    const std::string helper = (dir.path / "sub/helper.h").lexically_normal().string();
    EXPECT_NE(source.files[0].second.find("#include \"" + helper + "\""), std::string::npos);
    EXPECT_EQ(source.files[2].first, (dir.path / "other.h").lexically_normal().string());

    const std::string missing = dir.write("missing.h", "namespace m {\nLUCENT_MODULE(x)\n}\n"
                                                       "#include \"nowhere.h\"\n");
    expect_error([&] { ModuleSource::from_file(missing); }, {"missing.h:4", "nowhere.h"},
                 "an include that is not there");
    const std::string undeclared = dir.write("undeclared.h", "// no module here\n");
    expect_error([&] { ModuleSource::from_file(undeclared); },
                 {"undeclared.h", "LUCENT_MODULE(name)"}, "a header without a module");
    const std::string twice =
        dir.write("twice.h", "LUCENT_MODULE(one)\nLUCENT_MODULE(two)\n");
    expect_error([&] { ModuleSource::from_file(twice); }, {"twice.h:2", "one", "line 1"},
                 "two modules in one header");
    expect_error([&] { ModuleSource::from_file((dir.path / "absent.h").string()); },
                 {"absent.h"}, "a file that is not there");
}

TEST(Modules, RunTimeTextMustMatchTheTextTheProgramEmbeds) {
    Context ctx;
    const ModuleSource* embedded = embedded_module_source("test_twin_a");
    ASSERT_NE(embedded, nullptr);
    ModuleSource changed = *embedded;
    changed.files[0].second += "// changed\n";
    changed.main = "/elsewhere/twin_a_programs.h";
    expect_error([&] { ctx.add_module(changed); },
                 {"test_twin_a", "/elsewhere/twin_a_programs.h", embedded->main}, "another text");
    // The same text is accepted.
    EXPECT_EQ(ctx.add_module(*embedded).name(), "test_twin_a");
    // A module whose C++ side is not in this program is compiled at run time, which needs
    // a program that exports its symbols; this one does not, and the error says so.
    TempDir dir;
    const std::string stranger = dir.write("stranger.h", "namespace s {\nLUCENT_MODULE(stranger)\n}\n");
    expect_error([&] { ctx.add_module(ModuleSource::from_file(stranger)); },
                 {"stranger", "stranger.h", "ENABLE_EXPORTS", "include"},
                 "a module not compiled in");
}

/// The suites' backend; on the CPU with the JIT check, so the megakernel is made either way.
ContextOptions megakernel_options() {
    ContextOptions options = test_context_options();
    if (options.backend == BackendKind::kCpu) options.jit_check_sm = 90;
    return options;
}

TEST(Modules, AModuleWithoutTextRunsOnTheCpuAndTheJitSaysHowToGiveIt) {
    ContextOptions cpu_only;
    cpu_only.backend = BackendKind::kCpu;
    Context cpu(cpu_only);
    EXPECT_EQ(run_fill(cpu), (std::vector<unsigned>{1, 8, 15, 22}));
    if (test_backend() == BackendKind::kCpu && !can_jit_check())
        GTEST_SKIP() << "no CUDA backend or NVRTC here";

    Context ctx(megakernel_options());
    expect_error([&] { run_fill(ctx); },
                 {"fill", "test_unembedded", "unembedded_programs.h", "lucent_add_programs",
                  "ModuleSource::from_file"},
                 "the JIT without the module's text");
    // Given at run time, the module compiles into the megakernel (and runs, on the GPU).
    Context given(megakernel_options());
    given.add_module(ModuleSource::from_file(kUnembeddedPath));
    EXPECT_EQ(run_fill(given), (std::vector<unsigned>{1, 8, 15, 22}));
}

TEST(Modules, NvrtcErrorsNameTheModulesFileAndLine) {
    if (!can_jit_check()) GTEST_SKIP() << "no CUDA backend or NVRTC here";
    TempDir dir;
    // The module's text with a line only the GPU compile sees, at line 3.
    std::string text = read_file(kUnembeddedPath);
    size_t second_line = text.find('\n', text.find('\n') + 1) + 1;
    text.insert(second_line, "#if LUCENT_GPU_CODE\nnot_a_type broken_here;\n#endif\n");
    const std::string path = dir.write("broken_programs.h", text);
    Context ctx(jit_check_options());
    ctx.add_module(ModuleSource::from_file(path));
    expect_error([&] { run_fill(ctx); }, {"broken_programs.h(4)", "not_a_type"},
                 "an NVRTC error");
}

ContextOptions cpu_only_options() {
    ContextOptions options;
    options.backend = BackendKind::kCpu;
    return options;
}

/// A one-index launch of `probe` (a ray generation with `top` and `out`) over a square at
/// z = 5: the scene of the tests of undeclared device-API features.
struct ProbeScene {
    std::shared_ptr<Material> material;
    std::shared_ptr<Buffer> out;
};
ProbeScene set_up_probe(Context& ctx, const ProgramDesc& probe_desc) {
    ctx.set_entry_point_count(1);
    ctx.set_ray_type<TestPayload>(0, "radiance");
    auto probe = ctx.create_program(probe_desc);
    ProbeScene scene;
    scene.out = ctx.create_buffer<unsigned>(BufferType::kOutput, 1);
    (*probe)["out"] = scene.out;
    scene.material = make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 1);
    (*probe)["top"] = make_geometry_group(
        ctx, {make_instance(ctx, make_triangles(ctx, square_at(5)), scene.material)});
    ctx.set_ray_generation_program(0, probe);
    return scene;
}

TEST(Modules, OccludedWithoutItsDeclarationIsRefusedOnTheCpuToo) {
    Context ctx(cpu_only_options());
    const ProbeScene probe = set_up_probe(ctx, LUCENT_PROGRAM(undeclared_occlusion::shadow_probe));
    expect_error([&] { ctx.launch(0, 1); }, {"occluded()", "kUsesOccluded"},
                 "occluded() from an undeclared module on the CPU");
    // Once a bound module declares it (the megakernel-wide rule the GPU follows), the call
    // runs: the square blocks the probe.
    probe.material->set_any_hit(0, program(ctx, LUCENT_PROGRAM(occlusion_ignore_all)));
    ctx.launch(0, 1);
    EXPECT_EQ(read_buffer<unsigned>(*probe.out)[0], 1u);
}

TEST(Modules, OccludedWithoutItsDeclarationDoesNotCompileForTheGpu) {
    if (!can_jit_check()) GTEST_SKIP() << "no CUDA backend or NVRTC here";
    TempDir dir;
    std::string text = read_file(kUnembeddedPath);
    const std::string body = "rec.out[i] = 7u * i + 1u;";
    ASSERT_NE(text.find(body), std::string::npos);
    text.replace(text.find(body), body.size(),
                 "rec.out[i] = lucent::occluded(lucent::Handle{}, lucent::Ray{}) ? 1u : 0u;");
    const std::string path = dir.write("undeclared_occlusion.h", text);
    Context ctx(jit_check_options());
    ctx.add_module(ModuleSource::from_file(path));
    expect_error([&] { run_fill(ctx); }, {"kUsesOccluded"}, "occluded() not declared");
}

TEST(Modules, RayFlagsWithoutTheirDeclarationAreRefusedOnTheCpuToo) {
    Context ctx(cpu_only_options());
    set_up_probe(ctx, LUCENT_PROGRAM(undeclared_ray_flags::culling_probe));
    expect_error([&] { ctx.launch(0, 1); }, {"ray flags", "kUsesRayFlags"},
                 "ray flags from an undeclared module on the CPU");
}

TEST(Modules, RayFlagsWithoutTheirDeclarationDoNotCompileForTheGpu) {
    if (!can_jit_check()) GTEST_SKIP() << "no CUDA backend or NVRTC here";
    Context ctx(jit_check_options());
    ctx.add_module(ModuleSource::from_file(std::string(LUCENT_TESTS_DIR) +
                                           "/modules/undeclared_ray_flags_programs.h"));
    set_up_probe(ctx, LUCENT_PROGRAM(undeclared_ray_flags::culling_probe));
    expect_error([&] { ctx.launch(0, 1); }, {"kUsesRayFlags"}, "ray flags not declared");
}

}  // namespace
}  // namespace lucent_tests
