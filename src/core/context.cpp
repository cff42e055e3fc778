// Context: settings, object creation, and launch = compile (when stale) + backend run.
#include "lucent/context.h"

#include <algorithm>
#include <chrono>
#include <sstream>

#include "backends/backend_factory.h"
#include "core/backend.h"
#include "core/context_state.h"
#include "core/module_registry.h"
#include "core/runtime_module.h"
#include "core/scene_compiler.h"
#include "lucent/device/tea.h"

namespace lucent {

struct Context::Impl {
    detail::OwnerRef shared = std::make_shared<detail::ContextShared>();
    core::ContextState state;
    core::AccelCache accel_cache;
    std::unique_ptr<core::Backend> backend;
    std::unique_ptr<core::CompiledScene> compiled;
    LaunchReport last;
    std::string notice;  // why kAuto chose the CPU
    ContextOptions options;  // as constructed; devices as last set (set_devices)
    unsigned seed = 0;
    std::vector<uint4> device_keys;  // per device slot, from the seed (set_random_seed)
    std::function<void(const LaunchProgress&)> on_progress;
    unsigned next_id = 0;

    /// One device unless a list is set.
    unsigned device_count() const {
        return options.devices.empty() ? 1u : unsigned(options.devices.size());
    }

    /// Sebald's Fig. 4: one key per device slot from the slot and the seed.
    void derive_device_keys() {
        device_keys.clear();
        for (unsigned slot = 0; slot < device_count(); ++slot)
            device_keys.push_back(generate_tea_key(zafar_tea_key(), make_uint2(slot, seed)));
    }

    /// Launches run on `next` from now on; `devices` is its list (empty: the one device
    /// options.backend chose).
    void use_backend(std::unique_ptr<core::Backend> next, const std::vector<DeviceSpec>& devices);

    /// Compiles the scene if it changed and checks the launch against it.
    void prepare_launch(unsigned entry, unsigned width, unsigned height, unsigned depth,
                        LaunchReport& report, std::chrono::steady_clock::time_point t0);

    std::string next_name(const char* kind) {
        return std::string(kind) + "#" + std::to_string(++next_id);
    }
};

namespace {
using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

void check_device_count(const std::vector<DeviceSpec>& devices, const char* call) {
    if (devices.size() > kMaxDevices)
        throw Error(std::string(call) + ": " + std::to_string(devices.size()) +
                    " devices listed; at most " + std::to_string(kMaxDevices));
}
}  // namespace

void Context::Impl::use_backend(std::unique_ptr<core::Backend> next,
                                const std::vector<DeviceSpec>& devices) {
    backend = std::move(next);
    core::Backend* raw = backend.get();
    shared->fetch_from_device = [raw](const Buffer& b) { raw->fetch(b); };
    options.devices = devices;
    derive_device_keys();
}

Context::Context(ContextOptions options) : m_impl(std::make_unique<Impl>()) {
    m_impl->state.context = this;
    m_impl->on_progress = std::move(options.on_progress);
    check_device_count(options.devices, "Context");
    m_impl->use_backend(core::make_backend(options, m_impl->notice), options.devices);
    m_impl->options = std::move(options);
    if (m_impl->options.jit_check_sm && !core::can_jit_check())
        throw Error("Context: the JIT check needs a build with the CUDA toolkit; drop the option");
}

const std::string& Context::backend_notice() const {
    return m_impl->notice;
}

Context::~Context() {
    // Buffers may outlive the Context: they must not call into its backend any more.
    m_impl->shared->fetch_from_device = nullptr;
}

std::string Context::backend_name() const {
    return m_impl->backend->name();
}

unsigned Context::device_count() const {
    return m_impl->device_count();
}

std::vector<DeviceSpec> Context::devices() const {
    if (!m_impl->options.devices.empty()) return m_impl->options.devices;
    // One device from the backend choice: the CPU keeps buffers in host storage, a GPU not.
    if (m_impl->backend->uses_host_storage()) return {DeviceSpec{DeviceSpec::Kind::kCpu, 0}};
    return {DeviceSpec{DeviceSpec::Kind::kCuda, 0}};
}

void Context::set_devices(std::vector<DeviceSpec> devices) {
    check_device_count(devices, "Context::set_devices");
    ContextOptions options = m_impl->options;
    options.devices = devices;
    std::string notice;
    // Made before anything changes: a device that cannot run leaves the context as it was.
    std::unique_ptr<core::Backend> next = core::make_backend(options, notice);
    // What the old devices wrote reaches the host copies through the old backend.
    for (const auto& buffer : m_impl->backend->host_copies_behind()) buffer->sync_from_device();
    // The compiled scene and its per-device state (GPU layouts, kernels) belong to the old
    // devices; the next launch compiles for the new ones (host accelerations are reused).
    m_impl->compiled.reset();
    m_impl->use_backend(std::move(next), devices);
    m_impl->notice = std::move(notice);
}
void Context::set_random_seed(unsigned seed) {
    m_impl->seed = seed;
    m_impl->derive_device_keys();
}
unsigned Context::random_seed() const {
    return m_impl->seed;
}

void Context::variables_changed() {
    ++m_impl->shared->generation;
}

// ---- entry points and ray types ------------------------------------------------------
namespace {
void check_entry(const core::ContextState& s, unsigned entry, const char* call) {
    if (entry >= s.entries.size())
        throw Error(std::string("Context::") + call + ": entry point " + std::to_string(entry) +
                    " is out of range; there are " + std::to_string(s.entries.size()) +
                    " (call set_entry_point_count first)");
}
void check_kind(const std::shared_ptr<Program>& p, ProgramKind kind, const char* call,
                const char* macro) {
    if (p && p->kind() != kind)
        throw Error(std::string("Context::") + call + ": " + p->describe() + " is not a " +
                    program_kind_name(kind) + " program; define it with " + macro);
}
}  // namespace

void Context::set_entry_point_count(unsigned count) {
    if (count == 0) throw Error("Context::set_entry_point_count: need at least one entry point");
    m_impl->state.entries.resize(count);
    ++m_impl->shared->generation;
}
unsigned Context::entry_point_count() const {
    return unsigned(m_impl->state.entries.size());
}

void Context::set_ray_generation_program(unsigned entry, std::shared_ptr<Program> program) {
    check_entry(m_impl->state, entry, "set_ray_generation_program");
    check_kind(program, ProgramKind::kRayGeneration, "set_ray_generation_program",
               "LUCENT_RAY_GENERATION");
    m_impl->state.entries[entry].ray_generation = std::move(program);
    ++m_impl->shared->generation;
}
void Context::set_exception_program(unsigned entry, std::shared_ptr<Program> program) {
    check_entry(m_impl->state, entry, "set_exception_program");
    check_kind(program, ProgramKind::kException, "set_exception_program", "LUCENT_EXCEPTION");
    m_impl->state.entries[entry].exception = std::move(program);
    ++m_impl->shared->generation;
}
std::shared_ptr<Program> Context::ray_generation_program(unsigned entry) const {
    check_entry(m_impl->state, entry, "ray_generation_program");
    return m_impl->state.entries[entry].ray_generation;
}
std::shared_ptr<Program> Context::exception_program(unsigned entry) const {
    check_entry(m_impl->state, entry, "exception_program");
    return m_impl->state.entries[entry].exception;
}

void Context::set_ray_type(unsigned index, RayTypeDesc desc) {
    if (index >= 64)
        throw Error("Context::set_ray_type: ray type " + std::to_string(index) +
                    " is out of range (at most 64 ray types, numbered from 0)");
    if (!desc.payload)
        throw Error("Context::set_ray_type: ray type '" + desc.name + "' needs a payload type");
    auto& s = m_impl->state;
    if (s.ray_types.size() <= index) {
        s.ray_types.resize(index + 1);
        s.miss.resize(index + 1);
    }
    s.ray_types[index] = std::move(desc);
    ++m_impl->shared->generation;
}
unsigned Context::ray_type_count() const {
    return unsigned(m_impl->state.ray_types.size());
}
const RayTypeDesc& Context::ray_type(unsigned index) const {
    if (index >= m_impl->state.ray_types.size())
        throw Error("Context::ray_type: ray type " + std::to_string(index) +
                    " is not declared; declare it with set_ray_type<Payload>(index, name)");
    return m_impl->state.ray_types[index];
}
void Context::set_miss_program(unsigned ray_type, std::shared_ptr<Program> program) {
    auto& s = m_impl->state;
    if (ray_type >= s.ray_types.size() || !s.ray_types[ray_type].payload)
        throw Error("Context::set_miss_program: ray type " + std::to_string(ray_type) +
                    " is not declared; declare it first with set_ray_type<Payload>(" +
                    std::to_string(ray_type) + ", name)");
    check_kind(program, ProgramKind::kMiss, "set_miss_program", "LUCENT_MISS");
    s.miss[ray_type] = std::move(program);
    ++m_impl->shared->generation;
}
std::shared_ptr<Program> Context::miss_program(unsigned ray_type) const {
    auto& s = m_impl->state;
    return ray_type < s.miss.size() ? s.miss[ray_type] : nullptr;
}

// ---- execution settings ---------------------------------------------------------------
void Context::set_max_recursion_depth(unsigned depth) {
    if (depth == 0 || depth > 1024)
        throw Error("Context::set_max_recursion_depth: " + std::to_string(depth) +
                    " is out of range; use 1..1024");
    m_impl->state.max_depth = depth;
    ++m_impl->shared->generation;
}
unsigned Context::max_recursion_depth() const {
    return m_impl->state.max_depth;
}

void Context::set_exception_enabled(int code, bool enabled) {
    auto& codes = m_impl->state.enabled_exceptions;
    if (code == kAllExceptions) {
        codes.clear();
        if (enabled) codes.push_back(kAllExceptions);
    } else if (enabled) {
        if (std::find(codes.begin(), codes.end(), code) == codes.end()) codes.push_back(code);
    } else {
        if (exception_enabled(kAllExceptions)) {
            // Expand "all" into the engine codes so one can be turned off.
            codes = {kExceptionStackOverflow,
                     kExceptionBufferIndexOutOfBounds,
                     kExceptionPayloadTypeMismatch,
                     kExceptionInvalidHandle,
                     kExceptionInvalidRayType,
                     kExceptionMaterialIndexOutOfRange,
                     kExceptionInvalidRayFlags,
                     kUserExceptionBase};
        }
        codes.erase(std::remove(codes.begin(), codes.end(), code), codes.end());
    }
    ++m_impl->shared->generation;
}
bool Context::exception_enabled(int code) const {
    return core::exception_code_enabled(m_impl->state.enabled_exceptions, code);
}
void Context::set_print_enabled(bool enabled) {
    m_impl->state.print_enabled = enabled;
    ++m_impl->shared->generation;
}
bool Context::print_enabled() const {
    return m_impl->state.print_enabled;
}
void Context::set_print_launch_index(int x, int y, int z) {
    m_impl->state.print_index = int3{x, y, z};
    ++m_impl->shared->generation;
}

// ---- program modules ------------------------------------------------------------------
namespace {
core::ContextModule* known_module(core::ContextState& state, const ModuleInfo* info) {
    for (core::ContextModule& m : state.modules)
        if (m.info == info) return &m;
    return nullptr;
}
}  // namespace

const ModuleInfo& Context::add_module(std::string_view name) {
    const ModuleInfo* info = find_module(name);
    if (!info)
        throw Error("Context::add_module: this program contains no module named '" +
                    std::string(name) + "' (it has: " + detail::known_module_names() +
                    "); include the module's header in one of the program's files");
    if (!known_module(m_impl->state, info)) m_impl->state.modules.push_back({info, nullptr});
    return *info;
}

const ModuleInfo& Context::add_module(ModuleSource source) {
    // A module that is not compiled into the program is compiled now, for the host, with
    // the system's C++ compiler: the CPU backend runs its programs from that library, and
    // every backend reads their types from it (the GPU compiles the text again, with NVRTC).
    // A module loaded that way before is checked against its text the same way.
    const ModuleInfo* info = find_module(source.module);
    if (!info || core::is_runtime_module(source.module)) info = &core::load_runtime_module(source);
    if (const ModuleSource* embedded = embedded_module_source(source.module);
        embedded && !embedded->same_text(source))
        throw Error("Context::add_module: module '" + source.module + "' is given as " +
                    source.main + " but this program embeds a different text for it, from " +
                    embedded->main + "; rebuild the program, or drop the run-time source");
    core::ContextModule* known = known_module(m_impl->state, info);
    if (known && known->source && !known->source->same_text(source))
        throw Error("Context::add_module: module '" + source.module + "' was given as " +
                    known->source->main + " and now with a different text as " + source.main +
                    "; a context holds one text per module");
    auto shared = std::make_shared<const ModuleSource>(std::move(source));
    if (known)
        known->source = shared;
    else
        m_impl->state.modules.push_back({info, shared});
    ++m_impl->shared->generation;  // the megakernel's text may change
    return *info;
}

std::vector<const ModuleInfo*> Context::added_modules() const {
    std::vector<const ModuleInfo*> list;
    for (const core::ContextModule& m : m_impl->state.modules) list.push_back(m.info);
    return list;
}

// ---- object creation -------------------------------------------------------------------
std::shared_ptr<Program> Context::create_program(std::string_view name) {
    const ProgramDesc* found = nullptr;
    std::string modules;
    for (const core::ContextModule& m : m_impl->state.modules) {
        modules += (modules.empty() ? "'" : ", '") + std::string(m.info->name()) + "'";
        const ProgramDesc* desc = m.info->find(name);
        if (desc && found)
            throw Error("Context::create_program: program '" + std::string(name) +
                        "' is defined by module '" + std::string(found->module->name()) +
                        "' and by module '" + std::string(m.info->name()) +
                        "'; name the module: create_program(module, name)");
        if (desc) found = desc;
    }
    if (!found)
        throw Error("Context::create_program: no module of this context defines a program '" +
                    std::string(name) + "' (its modules: " +
                    (modules.empty() ? std::string("none") : modules) +
                    "); add the module that defines it with Context::add_module");
    return create_program(*found);
}
std::shared_ptr<Program> Context::create_program(const ModuleInfo& module, std::string_view name) {
    const ProgramDesc* desc = module.find(name);
    if (!desc) {
        std::string names;
        for (const ProgramDesc* p : module.programs())
            names += (names.empty() ? "" : ", ") + std::string(p->name);
        throw Error("Context::create_program: module '" + std::string(module.name()) +
                    "' has no program '" + std::string(name) +
                    "' (its programs: " + (names.empty() ? "none" : names) + ")");
    }
    return create_program(*desc);
}
std::shared_ptr<Program> Context::create_program(const ProgramDesc& desc) {
    if (desc.module && !known_module(m_impl->state, desc.module))
        m_impl->state.modules.push_back({desc.module, nullptr});
    return std::make_shared<Program>(m_impl->shared, desc);
}
std::shared_ptr<Buffer> Context::create_buffer(BufferType type, const TypeInfo& element,
                                               unsigned width, unsigned height, unsigned depth) {
    unsigned dims = depth ? 3 : height ? 2 : 1;
    if ((dims >= 2 && height == 0) || (dims == 3 && depth == 0))
        throw Error("Context::create_buffer: a dimension is 0");
    return std::make_shared<Buffer>(m_impl->shared, m_impl->next_name("buffer"), type, element,
                                    dims, uint3{width, height ? height : 1, depth ? depth : 1});
}
std::shared_ptr<TextureSampler> Context::create_texture_sampler() {
    return std::make_shared<TextureSampler>(m_impl->shared, m_impl->next_name("texture"));
}
std::shared_ptr<Acceleration> Context::create_acceleration(Builder builder) {
    auto a = std::make_shared<Acceleration>(m_impl->shared, m_impl->next_name("acceleration"));
    a->set_builder(builder);
    return a;
}
std::shared_ptr<Group> Context::create_group() {
    return std::make_shared<Group>(m_impl->shared, m_impl->next_name("group"),
                                   create_acceleration());
}
std::shared_ptr<GeometryGroup> Context::create_geometry_group() {
    return std::make_shared<GeometryGroup>(m_impl->shared, m_impl->next_name("geometry_group"),
                                           create_acceleration());
}
std::shared_ptr<Transform> Context::create_transform() {
    return std::make_shared<Transform>(m_impl->shared, m_impl->next_name("transform"));
}
std::shared_ptr<Selector> Context::create_selector() {
    return std::make_shared<Selector>(m_impl->shared, m_impl->next_name("selector"));
}
std::shared_ptr<GeometryInstance> Context::create_geometry_instance() {
    return std::make_shared<GeometryInstance>(m_impl->shared,
                                              m_impl->next_name("geometry_instance"));
}
std::shared_ptr<Geometry> Context::create_geometry() {
    return std::make_shared<Geometry>(m_impl->shared, m_impl->next_name("geometry"));
}
std::shared_ptr<GeometryTriangles> Context::create_geometry_triangles() {
    return std::make_shared<GeometryTriangles>(m_impl->shared, m_impl->next_name("triangles"));
}
std::shared_ptr<GeometrySpheres> Context::create_geometry_spheres() {
    return std::make_shared<GeometrySpheres>(m_impl->shared, m_impl->next_name("spheres"));
}
std::shared_ptr<GeometryCurves> Context::create_geometry_curves() {
    return std::make_shared<GeometryCurves>(m_impl->shared, m_impl->next_name("curves"));
}
std::shared_ptr<Material> Context::create_material() {
    return std::make_shared<Material>(m_impl->shared, m_impl->next_name("material"));
}

// ---- compile and launch ----------------------------------------------------------------
namespace {
void check_ray_generation(const core::CompiledScene& scene, unsigned entry) {
    if (!scene.entries[entry].ray_generation)
        throw Error("Context: entry point " + std::to_string(entry) +
                    " has no ray generation program; bind one with "
                    "set_ray_generation_program(" +
                    std::to_string(entry) + ", program)");
}
}  // namespace

void Context::validate() {
    core::SceneCompiler(m_impl->state, m_impl->accel_cache).validate_only();
    for (unsigned e = 0; e < m_impl->state.entries.size(); ++e)
        if (!m_impl->state.entries[e].ray_generation)
            throw Error("Context: entry point " + std::to_string(e) +
                        " has no ray generation program; bind one with "
                        "set_ray_generation_program(" +
                        std::to_string(e) + ", program) or lower the entry point count");
}

/// Compiles the scene if it changed and checks the launch against it.
void Context::Impl::prepare_launch(unsigned entry, unsigned width, unsigned height,
                                   unsigned depth, LaunchReport& report,
                                   std::chrono::steady_clock::time_point t0) {
    bool stale = !compiled || compiled->generation != shared->generation;
    if (!stale && compiled->data_generation != shared->data_generation) {
        // New buffer contents: a recompile only if something was built from them.
        for (const auto& [buffer, version] : compiled->rebuild_inputs)
            stale = stale || buffer->version() != version;
        if (!stale) compiled->data_generation = shared->data_generation;
    }
    if (stale) {
        compiled.reset();  // a failed compile must not leave a stale scene behind
        core::SceneCompiler compiler(state, accel_cache,
                                     backend->traces_on_host());
        compiled = compiler.compile();
        compiled->generation = shared->generation;
        compiled->data_generation = shared->data_generation;
        report.accel_ms = compiler.accel_ms();
        report.compile_ms = ms_since(t0) - report.accel_ms;
        report.recompiled = true;
        if (const int sm = options.jit_check_sm)
            core::jit_check(*compiled, sm, report);
    }
    const core::CompiledScene& scene = *compiled;
    check_ray_generation(scene, entry);
    unsigned dims = depth > 1 ? 3 : height > 1 ? 2 : 1;
    for (const Buffer* out : scene.entries[entry].output_buffers) {
        uint3 s = out->size();
        if (out->dimensionality() == dims && (s.x != width || s.y != height || s.z != depth))
            throw Error("Context::launch: " + out->describe() +
                        " is written by the ray generation program of entry " +
                        std::to_string(entry) + " but the launch is " + std::to_string(width) +
                        "x" + std::to_string(height) +
                        (dims == 3 ? "x" + std::to_string(depth) : "") +
                        "; resize the buffer to the launch size");
    }
}

void Context::launch(unsigned entry, unsigned width) {
    launch(entry, width, 1, 1);
}
void Context::launch(unsigned entry, unsigned width, unsigned height) {
    launch(entry, width, height, 1);
}
void Context::launch(unsigned entry, unsigned width, unsigned height, unsigned depth) {
    check_entry(m_impl->state, entry, "launch");
    if (width == 0 || height == 0 || depth == 0)
        throw Error("Context::launch: launch size " + std::to_string(width) + "x" +
                    std::to_string(height) + "x" + std::to_string(depth) +
                    " is empty; every dimension must be at least 1");
    LaunchReport report;
    auto t0 = Clock::now();
    try {
        m_impl->prepare_launch(entry, width, height, depth, report, t0);
    } catch (const RankError&) {
        throw;
    } catch (const std::exception& e) {
        // The other ranks wait in this launch's agreement: they learn of the failure there
        // (agree throws the RankError every rank throws).
        if (!m_impl->options.ranks) throw;
        const std::string failure = e.what();
        m_impl->options.ranks->agree(&failure);
        throw;
    }
    const core::CompiledScene& scene = *m_impl->compiled;
    core::LaunchSpec spec;
    spec.entry = entry;
    spec.size = uint3{width, height, depth};
    spec.device_keys = m_impl->device_keys;
    if (m_impl->on_progress) {
        LaunchProgress progress;
        progress.entry = entry;
        progress.size = spec.size;
        for (const Buffer* out : scene.entries[entry].output_buffers) {
            const uint3 s = out->size();
            if (s.x == width && s.y == height && s.z == depth) progress.outputs.push_back(out);
        }
        spec.on_rows = [this, progress](unsigned rows_done, unsigned rows) mutable {
            progress.rows_done = rows_done;
            progress.rows = rows;
            m_impl->on_progress(progress);
        };
    }
    auto t1 = Clock::now();
    const double jit_before = report.jit_ms;  // --jit-check's compile, before t1
    {
        // Whatever the launch did, buffers it views writably may hold what it wrote.
        struct MarkWritten {
            const std::vector<const Buffer*>& buffers;
            ~MarkWritten() {
                for (const Buffer* b : buffers) b->mark_written();
            }
        } mark_written{scene.entries[entry].written_buffers};
        m_impl->backend->launch(scene, spec, report);
    }
    // A kernel compile inside the backend's launch is reported apart.
    report.launch_ms = ms_since(t1) - (report.jit_ms - jit_before);
    m_impl->last = std::move(report);
}

const LaunchReport& Context::last_launch() const {
    return m_impl->last;
}

std::shared_ptr<DisplayFrame> Context::display_frame(const Buffer& output) {
    if (output.owner() != m_impl->shared)
        throw Error("Context::display_frame: " + output.describe() +
                    " belongs to another Context; pass a buffer this Context created");
    if (output.dimensionality() != 2 || !same_type(output.element(), type_info_of<float4>()))
        throw Error("Context::display_frame: " + output.describe() +
                    " is not a 2D buffer of float4; display frames are made from linear RGB "
                    "images such as a launch's float4 output");
    return m_impl->backend->display_frame(output);
}

// ---- reports ------------------------------------------------------------------------------
uint64_t LaunchReport::exception_count() const {
    uint64_t n = 0;
    for (auto& [code, e] : exceptions) n += e.count;
    return n;
}

std::string exception_name(int code) {
    switch (code) {
        case kExceptionStackOverflow:
            return "stack overflow";
        case kExceptionBufferIndexOutOfBounds:
            return "buffer index out of bounds";
        case kExceptionPayloadTypeMismatch:
            return "payload type mismatch";
        case kExceptionInvalidHandle:
            return "invalid node handle";
        case kExceptionInvalidRayType:
            return "invalid ray type";
        case kExceptionMaterialIndexOutOfRange:
            return "material index out of range";
        case kExceptionInvalidRayFlags:
            return "invalid ray flags or visibility mask";
    }
    std::ostringstream s;
    if (code >= kUserExceptionBase)
        s << "user exception 0x" << std::hex << code;
    else
        s << "exception " << code;
    return s.str();
}

std::string LaunchReport::summary() const {
    std::ostringstream s;
    for (auto& [code, e] : exceptions)
        s << exception_name(code) << ": " << e.count << " (first at " << e.first_index.x << ","
          << e.first_index.y << "," << e.first_index.z << ")\n";
    return s.str();
}

}  // namespace lucent
