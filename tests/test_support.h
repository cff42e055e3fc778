// Host-side helpers shared by the behavioural tests: a CPU context with the shared
// caster/miss programs, builders for spheres, triangles and materials, error matchers.
#pragma once

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <functional>
#include <initializer_list>
#include <string>
#include <vector>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "lucent.h"
#include "tests/programs/common.h"

namespace lucent_tests {

/// Tolerance of the value checks on positions, normals and colours.
constexpr float kEps = 1e-4f;

#define EXPECT_FLOAT3_NEAR(a, b, eps)        \
    do {                                     \
        const float3 a_ = (a), b_ = (b);     \
        EXPECT_NEAR(a_.x, b_.x, eps) << "x"; \
        EXPECT_NEAR(a_.y, b_.y, eps) << "y"; \
        EXPECT_NEAR(a_.z, b_.z, eps) << "z"; \
    } while (0)

/// The backend the suites run on: the CPU, so values never depend on what `auto` finds;
/// LUCENT_TEST_BACKEND=cuda runs the same suites on the GPU (CPU/GPU parity runs).
inline BackendKind test_backend() {
    const char* env = std::getenv("LUCENT_TEST_BACKEND");
    return env && std::string(env) == "cuda" ? BackendKind::kCuda : BackendKind::kCpu;
}

inline ContextOptions test_context_options() {
    ContextOptions options;
    options.backend = test_backend();
    options.threads = 2;
    // LUCENT_TEST_JIT_CHECK=90: also compile each test scene's CUDA megakernel (slow).
    if (const char* sm = std::getenv("LUCENT_TEST_JIT_CHECK")) options.jit_check_sm = std::atoi(sm);
    // LUCENT_TEST_DEVICES=0,0 (or cpu,0, ...): every suite through the multi-device path,
    // in pieces of two rows.
    if (const char* devices = std::getenv("LUCENT_TEST_DEVICES")) {
        options.devices = parse_device_list(devices);
        options.piece_rows = 2;
    }
    return options;
}

inline std::string lowercase(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return s;
}

/// Runs `fn`, expects a lucent::Error whose message contains every word of `words`
/// (case-insensitive: we assert on meaning, not capitalisation). Returns the message.
inline std::string expect_error(const std::function<void()>& fn,
                                std::initializer_list<std::string> words, const char* what = "") {
    try {
        fn();
    } catch (const Error& e) {
        const std::string message = e.what();
        for (const std::string& word : words)
            EXPECT_THAT(lowercase(message), testing::HasSubstr(lowercase(word)))
                << what << ": the error should mention \"" << word << "\"";
        return message;
    } catch (const std::exception& e) {
        ADD_FAILURE() << what << ": expected lucent::Error, got another exception: " << e.what();
        return {};
    }
    ADD_FAILURE() << what << ": expected lucent::Error, nothing was thrown";
    return {};
}

/// True when `message` (case-insensitively) contains at least one of `words`.
inline bool mentions_any(const std::string& message, std::initializer_list<std::string> words) {
    const std::string lower = lowercase(message);
    for (const std::string& w : words)
        if (lower.find(lowercase(w)) != std::string::npos) return true;
    return false;
}

inline std::shared_ptr<Program> program(Context& ctx, const ProgramDesc& desc) {
    return ctx.create_program(desc);
}

template <class T>
std::shared_ptr<Buffer> input_buffer(Context& ctx, const std::vector<T>& values) {
    auto buffer = ctx.create_buffer<T>(BufferType::kInput, unsigned(values.size()));
    buffer->upload(values);
    return buffer;
}

template <class T>
std::vector<T> read_buffer(const Buffer& buffer) {
    const T* data = buffer.data<T>();
    return std::vector<T>(data, data + buffer.count());
}

/// A Geometry of spheres (centre xyz, radius w) with the shared sphere programs.
inline std::shared_ptr<Geometry> make_spheres(Context& ctx, const std::vector<float4>& spheres) {
    auto geometry = ctx.create_geometry();
    geometry->set_primitive_count(unsigned(spheres.size()));
    geometry->set_bounding_box_program(program(ctx, LUCENT_PROGRAM(common_sphere_bounds)));
    geometry->set_intersection_program(program(ctx, LUCENT_PROGRAM(common_sphere_intersect)));
    (*geometry)["spheres"] = input_buffer(ctx, spheres);
    return geometry;
}

/// Built-in triangles from float3 vertices and optional uint3 indices.
inline std::shared_ptr<GeometryTriangles> make_triangles(Context& ctx,
                                                         const std::vector<float3>& vertices,
                                                         const std::vector<uint3>& indices = {}) {
    auto triangles = ctx.create_geometry_triangles();
    triangles->set_vertices(input_buffer(ctx, vertices));
    if (!indices.empty()) triangles->set_indices(input_buffer(ctx, indices));
    return triangles;
}

/// A square [x0,x1]x[y0,y1] at depth z, as two triangles facing -z.
inline std::vector<float3> square_at(float z, float x0 = -10, float x1 = 10, float y0 = -10,
                                     float y1 = 10) {
    return {make_float3(x0, y0, z), make_float3(x1, y0, z), make_float3(x1, y1, z),
            make_float3(x0, y0, z), make_float3(x1, y1, z), make_float3(x0, y1, z)};
}

/// A material whose closest hit for ray type 0 is `closest_hit`, with variable id = `id`.
inline std::shared_ptr<Material> make_material(Context& ctx, std::shared_ptr<Program> closest_hit,
                                               unsigned id) {
    auto material = ctx.create_material();
    material->set_closest_hit(0, std::move(closest_hit));
    (*material)["id"] = id;
    return material;
}

inline std::shared_ptr<GeometryInstance> make_instance(Context& ctx,
                                                       std::shared_ptr<GeometryBase> geometry,
                                                       std::shared_ptr<Material> material) {
    auto instance = ctx.create_geometry_instance();
    instance->set_geometry(std::move(geometry));
    instance->add_material(std::move(material));
    return instance;
}

inline std::shared_ptr<GeometryGroup> make_geometry_group(
    Context& ctx, std::initializer_list<std::shared_ptr<GeometryInstance>> instances) {
    auto group = ctx.create_geometry_group();
    for (const auto& instance : instances) group->add_child(instance);
    return group;
}

inline Matrix4x3 translation(float x, float y, float z) {
    return Matrix4x3{{1, 0, 0, x, 0, 1, 0, y, 0, 0, 1, z}};
}
inline Matrix4x3 scaling(float x, float y, float z) {
    return Matrix4x3{{x, 0, 0, 0, 0, y, 0, 0, 0, 0, z, 0}};
}

inline CastRay cast_ray(float3 origin, float3 direction) {
    return CastRay{origin, direction};
}

/// A folder of the running test's own (under the system's temporary folder, named by suite,
/// test and process, so parallel ctest runs do not share one), removed at the end; the
/// scene and image loaders' tests write their files into it.
class TempDirTest : public testing::Test {
  protected:
    void SetUp() override {
        const testing::TestInfo* test = testing::UnitTest::GetInstance()->current_test_info();
        std::string name = std::string("lucent-") + test->test_suite_name() + "-" + test->name() +
                           "-" + std::to_string(::getpid());
        std::replace(name.begin(), name.end(), '/', '_');  // parameterised tests' names
        dir = std::filesystem::temp_directory_path() / name;
        std::filesystem::create_directories(dir);
    }
    void TearDown() override { std::filesystem::remove_all(dir); }
    /// Writes `bytes` to the file `name` in the folder; returns its path.
    std::string write(const std::string& name, const std::string& bytes) const {
        std::ofstream(dir / name, std::ios::binary) << bytes;
        return (dir / name).string();
    }
    std::filesystem::path dir;
};

/// A CPU context with one entry point (the shared caster), ray type 0 carrying
/// TestPayload, and the shared miss program: cast(top, rays) traces and returns payloads.
class CasterFixture : public testing::Test {
  protected:
    CasterFixture() : ctx(test_context_options()) {
        ctx.set_entry_point_count(1);
        ctx.set_ray_type<TestPayload>(0, "radiance");
        ctx.set_miss_program(0, program(ctx, LUCENT_PROGRAM(common_miss)));
        caster = program(ctx, LUCENT_PROGRAM(common_cast));
        ctx.set_ray_generation_program(0, caster);
    }

    template <class N>
    std::vector<TestPayload> cast(std::shared_ptr<N> top, const std::vector<CastRay>& rays) {
        (*caster)["top"] = top;
        (*caster)["rays"] = input_buffer(ctx, rays);
        auto results = ctx.create_buffer<TestPayload>(BufferType::kOutput, unsigned(rays.size()));
        (*caster)["results"] = results;
        ctx.launch(0, unsigned(rays.size()));
        return read_buffer<TestPayload>(*results);
    }

    Context ctx;
    std::shared_ptr<Program> caster;
};

}  // namespace lucent_tests
