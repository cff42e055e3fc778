// The Context: owns every object, the entry points and ray types, and launches.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "lucent/buffer.h"
#include "lucent/display.h"
#include "lucent/nodes.h"
#include "lucent/program.h"
#include "lucent/ranks.h"
#include "lucent/variables.h"

namespace lucent {

enum class BackendKind { kAuto, kCpu, kCuda };

/// One device a Context launches on: the CPU (all its cores) or a CUDA GPU by ordinal.
struct DeviceSpec {
    enum class Kind { kCpu, kCuda };
    Kind kind = Kind::kCpu;
    int ordinal = 0;  // kCuda: the GPU's CUDA ordinal
    bool operator==(const DeviceSpec&) const = default;
};

/// How far a launch has come, for showing partial results (ContextOptions::on_progress).
struct LaunchProgress {
    unsigned entry = 0;
    uint3 size{1, 1, 1};
    unsigned rows_done = 0;  // rows (row = z * height + y) 0 .. rows_done - 1 are finished
    unsigned rows = 1;
    /// The entry's output buffers (type output, launch-sized): their finished rows hold
    /// their final values and may be read now.
    std::vector<const Buffer*> outputs;
};

/// Parses a device list: "all" (every CUDA GPU, or the CPU where there is none), or
/// comma-separated items, each a GPU ordinal ("0") or "cpu": "0,1", "cpu,0", "0,0" (GPU 0
/// twice: two devices sharing one GPU). Throws Error naming the bad item.
std::vector<DeviceSpec> parse_device_list(const std::string& text);
/// "cpu" or "cuda:1".
std::string device_spec_name(const DeviceSpec& device);

/// CUDA: what the backend does for a kernel of more than 64 registers a thread. Capped at 64,
/// more warps fit on a multiprocessor but values spill; which is faster depends on the
/// program (docs/performance.md), so a capped variant is one more launch shape the tuning
/// times (docs/programming-model.md, "Launch shapes").
enum class RegisterVariants {
    kBackground,  // compiled on other threads after the first launch, timed once it is ready
    kWithKernel,  // compiled with the kernel, before the first launch: reproducible timings
    kOff,         // none: every kernel runs as compiled
};

/// CUDA, Builder::kAuto: the GPU builds a group's triangle tree at once, splitting objects
/// only; the host's tree with spatial splits (Builder::kBinnedSah's) traces faster, by up to
/// 1.3x on Sponza, but takes tens of ms to build (docs/performance.md). An upgrade builds
/// that tree from the GPU tree's triangles and puts it in the GPU tree's place.
enum class TreeUpgrades {
    kBackground,  // built on another thread, used from the first launch after it is ready
    kWithBuild,   // built right after the GPU build, before the launch: reproducible timings
    kOff,         // none: groups trace the GPU-built tree
};

struct ContextOptions {
    BackendKind backend = BackendKind::kAuto;
    unsigned threads = 0;  // CPU backend workers; 0 = one per core
    /// With the CPU backend: also generate the CUDA megakernel at each compile and compile it
    /// with NVRTC for this compute capability (e.g. 90), without a GPU; 0 = off. A check
    /// that the GPU path compiles; needs a build with the CUDA toolkit.
    int jit_check_sm = 0;
    /// The devices every launch is spread over (at most kMaxDevices). Empty: the one device
    /// `backend` chooses. With several, each launch's rows are taken from a shared queue by
    /// all of them, and the images are those of a one-device run (docs/multi-device.md).
    /// When set, `backend` is ignored; `threads` is the CPU device's worker count.
    std::vector<DeviceSpec> devices;
    /// Multi-device launches: launch-grid rows per piece taken from the queue (1D launches:
    /// 64 x this many indices); 0 = sized by each device's measured speed. For tests.
    unsigned piece_rows = 0;
    /// CUDA: the register-capped variants of large kernels (the environment variable
    /// LUCENT_GPU_REGISTER_VARIANTS=background|sync|off overrides it, for experiments).
    RegisterVariants register_variants = RegisterVariants::kBackground;
    /// CUDA: the upgrades of Builder::kAuto's GPU-built triangle trees (the environment
    /// variable LUCENT_GPU_TREE_UPGRADES=background|sync|off overrides it, for experiments).
    /// Groups with set_refit(true) or an any-hit program keep their GPU tree.
    TreeUpgrades tree_upgrades = TreeUpgrades::kBackground;
    /// Called on the launching thread as bands of rows of a launch finish, where the
    /// device's copy of the buffers is host memory (the CPU backend, one device); an
    /// interactive viewer shows them while a slow frame renders. Empty: launches run whole.
    std::function<void(const LaunchProgress&)> on_progress;
    /// The processes every launch is spread over (lucent/ranks.h, docs/distributed.md):
    /// each rank runs pieces on its own devices (`devices`, `backend`), and every rank's
    /// outputs hold the whole image after a launch. Every rank must run the same host code
    /// (each launch checks it). Null: this process alone.
    std::shared_ptr<Ranks> ranks;
};

constexpr unsigned kMaxDevices = 16;

/// A ray type: its name, the payload type every program handling it must use, and whether
/// rays of this type need a closest-hit program on every material they can reach
/// (false for visibility-only rays that work through any-hit and miss).
struct RayTypeDesc {
    std::string name;
    const TypeInfo* payload = nullptr;
    bool expects_closest_hit = true;
    /// The graphs rays of this type are traced against, when only some: then only the
    /// materials below them need this ray type's closest hit (IGI traces visibility rays
    /// against a second graph of boxes). Empty: every graph.
    std::vector<std::shared_ptr<Node>> roots;
};

constexpr int kAllExceptions = -1;

/// What the host learns after a launch: exception counts per code with the first launch
/// index that raised each, and how long each stage took.
struct LaunchReport {
    struct ExceptionSummary {
        uint64_t count = 0;
        uint3 first_index{0, 0, 0};
    };
    std::map<int, ExceptionSummary> exceptions;
    double compile_ms = 0;  // validation, variable resolution, record packing
    double accel_ms = 0;    // acceleration builds and refits (CUDA: with the GPU layouts')
    double launch_ms = 0;   // running the programs
    bool recompiled = false;
    double jit_ms = 0;  // CUDA: megakernel generation + NVRTC compile or cache load (0: reused)
    bool jit_cached = false;  // CUDA: the megakernel came from the disk cache
    double kernel_ms = 0;     // CUDA: the megakernel alone (CUDA events), within launch_ms
    /// CUDA: this launch ran while the backend was still timing launch shapes for its entry
    /// and size (the first few launches, docs/performance.md "Launch shapes"); a benchmark
    /// times the launches after the tuning.
    bool launch_shape_trial = false;
    /// CUDA: this launch ran a variant of the kernel compiled for at most register_cap
    /// registers a thread, 64 or (with trace() inlined) 56 (compiled in the background after
    /// the first launch; more shapes the tuning times).
    bool registers_capped = false;
    unsigned register_cap = 0;  // 0: not capped
    /// CUDA: this launch ran the kernel's variant with trace() inlined into its
    /// ray-generation program (compiled in the background where no program that a trace
    /// runs traces again; one more shape the tuning times).
    bool trace_inlined = false;
    /// CUDA: this launch's kernel refilled lanes: a lane whose closest-hit trace was done
    /// took its next launch index alone and met the lanes still tracing, so traversal ran
    /// with more lanes of a warp busy (two of the inline-trace variants, one more shape the
    /// tuning times; not over a tile queue several GPUs share; the environment variable
    /// LUCENT_GPU_LANE_REFILL=off leaves them out).
    bool lanes_refilled = false;
    /// CUDA: triangle trees (TreeUpgrades) this launch traced for the first time, in place of
    /// the GPU-built trees it replaced; the launch-shape tuning starts again after them.
    unsigned trees_upgraded = 0;
    /// Multi-device launches: what each device ran, in ContextOptions::devices order.
    struct DeviceShare {
        std::string device;      // "cuda:0"
        uint64_t indices = 0;    // launch indices it ran
        unsigned pieces = 0;     // pieces it took from the queue
        double busy_ms = 0;      // from its first piece's start to its last piece's end
    };
    std::vector<DeviceShare> devices;
    /// Multi-device launches: bringing every device's copy of the written buffers up to
    /// date with the pieces the other devices ran (within launch_ms).
    double exchange_ms = 0;
    /// Launches spread over ranks (ContextOptions::ranks): what each rank ran, in rank
    /// order (empty when the launch ran whole on every rank), and the gather of the
    /// pieces every rank's outputs receive from the others (within launch_ms).
    struct RankShare {
        uint64_t indices = 0;  // launch indices it ran
        unsigned pieces = 0;   // pieces it took from the shared counter
        double busy_ms = 0;    // its devices' run, from the launch's start on that rank
    };
    std::vector<RankShare> ranks;
    double gather_ms = 0;
    uint64_t exception_count() const;
    /// One line per exception code: "stack overflow: 12 (first at 3,4,0)".
    std::string summary() const;
};

/// Human name of an exception code ("stack overflow", "user exception 0x401").
std::string exception_name(int code);

class Context : public VariableScope {
  public:
    explicit Context(ContextOptions options = {});
    ~Context() override;
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;

    /// "cpu (2 threads)" or "cuda (...)": the backend that runs launches.
    std::string backend_name() const;
    /// Why BackendKind::kAuto chose the CPU ("no NVIDIA driver ..."), or empty.
    const std::string& backend_notice() const;
    /// How many devices each launch is spread over (1 unless a device list is set).
    unsigned device_count() const;
    /// The devices launches run on: the list set (ContextOptions::devices, set_devices), or
    /// the one device the backend choice made ({cpu} or {cuda:0}).
    std::vector<DeviceSpec> devices() const;
    /// Moves every later launch onto `devices`, as ContextOptions::devices would have at
    /// construction (empty: back to the one device ContextOptions::backend chooses). What
    /// launches wrote on the old devices is fetched into the buffers' host copies first, the
    /// old devices' memory is released, and the next launch compiles the scene for the new
    /// ones; nodes, buffers, programs and variables are kept. The TEA keys follow the new
    /// device slots (device_tea_key()). Throws Error naming the device that cannot run (or
    /// a list longer than kMaxDevices), leaving the context on its old devices.
    void set_devices(std::vector<DeviceSpec> devices);

    /// The seed of the per-device TEA keys (device API device_tea_key(); Sebald Fig. 4).
    void set_random_seed(unsigned seed);
    unsigned random_seed() const;
    std::string scope_name() const override { return "Context"; }

    // ---- entry points and ray types ------------------------------------------
    void set_entry_point_count(unsigned count);
    unsigned entry_point_count() const;
    void set_ray_generation_program(unsigned entry, std::shared_ptr<Program> program);
    void set_exception_program(unsigned entry, std::shared_ptr<Program> program);
    std::shared_ptr<Program> ray_generation_program(unsigned entry) const;
    std::shared_ptr<Program> exception_program(unsigned entry) const;

    /// Declares ray type `index` (ray types are 0, 1, ... with no gaps).
    template <class Payload>
    void set_ray_type(unsigned index, std::string name, bool expects_closest_hit = true,
                      std::vector<std::shared_ptr<Node>> roots = {}) {
        set_ray_type(index, RayTypeDesc{std::move(name), &type_info_of<Payload>(),
                                        expects_closest_hit, std::move(roots)});
    }
    void set_ray_type(unsigned index, RayTypeDesc desc);
    unsigned ray_type_count() const;
    const RayTypeDesc& ray_type(unsigned index) const;
    void set_miss_program(unsigned ray_type, std::shared_ptr<Program> program);
    std::shared_ptr<Program> miss_program(unsigned ray_type) const;

    // ---- execution settings ---------------------------------------------------
    /// Deepest trace nesting allowed (ray generation's trace is depth 1).
    void set_max_recursion_depth(unsigned depth);
    unsigned max_recursion_depth() const;
    /// Turn one exception code (or kAllExceptions) on or off. All are off by default.
    void set_exception_enabled(int code, bool enabled);
    bool exception_enabled(int code) const;
    void set_print_enabled(bool enabled);
    bool print_enabled() const;
    /// Only this launch index prints (-1 in a coordinate means any).
    void set_print_launch_index(int x, int y = -1, int z = -1);

    // ---- program modules (lucent/module.h) -------------------------------------
    /// Makes the module `name`, compiled into this binary, available to create_program
    /// by name; its GPU text is what lucent_add_programs embedded. Throws Error listing the
    /// modules there are when none has this name.
    const ModuleInfo& add_module(std::string_view name);
    /// The same with the module's text given at run time (its LUCENT_MODULE names the
    /// module). A module that is not compiled into this binary is compiled now with the
    /// system's C++ compiler ($LUCENT_CXX, $CXX or c++ on PATH; $LUCENT_CXXFLAGS adds
    /// flags) into a shared library that is loaded and kept in the kernel cache's folder;
    /// an executable that does this needs ENABLE_EXPORTS (-rdynamic). Throws Error with the
    /// compiler's messages when it rejects the text, when no compiler is found, when this
    /// binary embeds a different text for the module, or when this process already loaded
    /// another text under its name.
    const ModuleInfo& add_module(ModuleSource source);
    /// The modules this context knows: added, or the modules of the programs it created.
    std::vector<const ModuleInfo*> added_modules() const;

    // ---- object creation ------------------------------------------------------
    /// The program `name` of one of this context's modules (add_module); Error when no
    /// module or two have it (then name the module: create_program(module, name)).
    std::shared_ptr<Program> create_program(std::string_view name);
    std::shared_ptr<Program> create_program(const ModuleInfo& module, std::string_view name);
    /// The program of a LUCENT_PROGRAM(ns::name); its module is added to this context.
    std::shared_ptr<Program> create_program(const ProgramDesc& desc);
    template <class T>
    std::shared_ptr<Buffer> create_buffer(BufferType type, unsigned width, unsigned height = 0,
                                          unsigned depth = 0) {
        return create_buffer(type, type_info_of<T>(), width, height, depth);
    }
    /// Width only: 1D; width and height: 2D; all three: 3D.
    std::shared_ptr<Buffer> create_buffer(BufferType type, const TypeInfo& element, unsigned width,
                                          unsigned height = 0, unsigned depth = 0);
    std::shared_ptr<TextureSampler> create_texture_sampler();
    std::shared_ptr<Acceleration> create_acceleration(Builder builder = Builder::kAuto);
    std::shared_ptr<Group> create_group();
    std::shared_ptr<GeometryGroup> create_geometry_group();
    std::shared_ptr<Transform> create_transform();
    std::shared_ptr<Selector> create_selector();
    std::shared_ptr<GeometryInstance> create_geometry_instance();
    std::shared_ptr<Geometry> create_geometry();
    std::shared_ptr<GeometryTriangles> create_geometry_triangles();
    std::shared_ptr<GeometrySpheres> create_geometry_spheres();
    std::shared_ptr<GeometryCurves> create_geometry_curves();
    std::shared_ptr<Material> create_material();

    // ---- compile and launch ---------------------------------------------------
    /// Checks everything a launch would (any entry point), without launching; throws Error.
    void validate();
    void launch(unsigned entry, unsigned width);
    void launch(unsigned entry, unsigned width, unsigned height);
    void launch(unsigned entry, unsigned width, unsigned height, unsigned depth);
    /// Exceptions and timings of the most recent launch.
    const LaunchReport& last_launch() const;
    /// `output` (a 2D float4 buffer of linear RGB, e.g. what the last launch wrote) as an
    /// 8-bit sRGB frame to show (lucent/display.h), encoded where the launch left it: on
    /// the GPU for a one-GPU CUDA context (the pixels stay there), else on the host.
    std::shared_ptr<DisplayFrame> display_frame(const Buffer& output);

    struct Impl;

  protected:
    void variables_changed() override;

  private:
    std::unique_ptr<Impl> m_impl;
};

}  // namespace lucent
