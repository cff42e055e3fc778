// Several devices per Context (OptiX paper §5; Sebald §3.2): a launch split into pieces
// taken from a shared queue gives the images of a one-device run, in 1D, 2D and 3D, over
// launches that read what earlier ones wrote; per-device TEA keys; device lists.
// Runs on the CPU (two CPU devices); where a GPU answers, also GPU + GPU (one GPU listed
// twice), CPU + GPU, and every GPU of the machine.
#include "backends/backend_factory.h"
#include "tests/programs/multi_device_programs.h"
#include "tests/test_support.h"

namespace lucent_tests {
namespace {

using Kind = DeviceSpec::Kind;
const DeviceSpec kCpu{Kind::kCpu, 0};
DeviceSpec gpu(int ordinal) {
    return DeviceSpec{Kind::kCuda, ordinal};
}

int gpus() {
    return lucent::core::gpu_count();
}

std::string list_name(const std::vector<DeviceSpec>& devices) {
    std::string s;
    for (const DeviceSpec& d : devices) s += (s.empty() ? "" : ",") + device_spec_name(d);
    return s;
}

/// The device lists to check, each with the one-device lists whose results it must give
/// (element by element: a CPU + GPU run gives, at each index, what the device that ran it
/// gives alone; CPU and GPU may differ in the last bits of a float).
struct DeviceCase {
    std::vector<DeviceSpec> devices;
    std::vector<std::vector<DeviceSpec>> references;
};
std::vector<DeviceCase> device_cases() {
    std::vector<DeviceCase> cases{{{kCpu, kCpu}, {{kCpu}}}, {{kCpu}, {{kCpu}}}};
    if (gpus() >= 1) {
        cases.push_back({{gpu(0), gpu(0)}, {{gpu(0)}}});
        cases.push_back({{kCpu, gpu(0)}, {{kCpu}, {gpu(0)}}});
    }
    if (gpus() >= 2) {
        std::vector<DeviceSpec> all;
        for (int g = 0; g < gpus(); ++g) all.push_back(gpu(g));
        cases.push_back({all, {{gpu(0)}}});
    }
    return cases;
}

ContextOptions options_for(const std::vector<DeviceSpec>& devices, unsigned piece_rows = 2) {
    ContextOptions o;
    o.devices = devices;
    o.threads = 1;
    o.piece_rows = piece_rows;  // small pieces: every device takes some
    return o;
}

/// A context with ray type 0, the shared miss, and a sphere of radius 0.8 at the origin.
struct Scene {
    explicit Scene(const ContextOptions& options) : ctx(options) {
        ctx.set_entry_point_count(2);
        ctx.set_ray_type<TestPayload>(0, "radiance");
        ctx.set_miss_program(0, program(ctx, LUCENT_PROGRAM(common_miss)));
        auto hit = make_material(ctx, program(ctx, LUCENT_PROGRAM(common_sphere_hit)), 1);
        ctx["top"] = make_geometry_group(
            ctx, {make_instance(ctx, make_spheres(ctx, {make_float4(0, 0, 0, 0.8f)}), hit)});
    }
    Context ctx;
};

/// md_pattern over a launch of `size` (unused dimensions 0); the image it writes.
std::vector<float4> pattern(const ContextOptions& options, uint3 size, LaunchReport* report = nullptr,
                            unsigned repeats = 1) {
    Scene s(options);
    const unsigned dims = size.z ? 3 : size.y ? 2 : 1;
    auto image = s.ctx.create_buffer<float4>(BufferType::kOutput, size.x, size.y, size.z);
    s.ctx["image"] = image;
    s.ctx["dims"] = dims;
    s.ctx["repeats"] = repeats;
    s.ctx.set_ray_generation_program(0, program(s.ctx, LUCENT_PROGRAM(md_pattern)));
    s.ctx.set_ray_generation_program(1, program(s.ctx, LUCENT_PROGRAM(md_pattern)));
    s.ctx.launch(0, size.x, size.y ? size.y : 1, size.z ? size.z : 1);
    if (report) *report = s.ctx.last_launch();
    return read_buffer<float4>(*image);
}

bool same(float4 a, float4 b) {
    return a.x == b.x && a.y == b.y && a.z == b.z && a.w == b.w;
}
bool same(float a, float b) {
    return a == b;
}

/// Every element equals the same element of one of the references.
template <class T>
void expect_matches(const std::vector<T>& got, const std::vector<std::vector<T>>& references,
                    const std::string& what) {
    size_t bad = 0, first_bad = 0;
    for (size_t i = 0; i < got.size(); ++i) {
        bool ok = false;
        for (const auto& r : references) ok = ok || same(got[i], r[i]);
        if (!ok && bad++ == 0) first_bad = i;
    }
    EXPECT_EQ(bad, 0u) << what << ": " << bad << " of " << got.size()
                       << " elements differ from every one-device run, the first at " << first_bad;
}

void expect_shares_cover(const LaunchReport& report, size_t devices, uint64_t count) {
    ASSERT_EQ(report.devices.size(), devices);
    uint64_t total = 0;
    for (const auto& d : report.devices) total += d.indices;
    EXPECT_EQ(total, count) << "every launch index ran exactly once";
}

TEST(MultiDevice, PiecesOfOneTwoAndThreeDimensionalLaunchesGiveTheOneDeviceImage) {
    for (const DeviceCase& c : device_cases()) {
        SCOPED_TRACE(list_name(c.devices));
        for (uint3 size : {uint3{20000, 0, 0}, uint3{61, 47, 0}, uint3{9, 7, 5}}) {
            std::vector<std::vector<float4>> refs;
            for (const auto& r : c.references) refs.push_back(pattern(options_for(r), size));
            LaunchReport report;
            const auto got = pattern(options_for(c.devices), size, &report);
            const uint64_t count = uint64_t(size.x) * std::max(1u, size.y) * std::max(1u, size.z);
            expect_matches(got, refs, "pattern " + std::to_string(size.x) + "x" +
                                          std::to_string(size.y) + "x" + std::to_string(size.z));
            expect_shares_cover(report, c.devices.size(), count);
        }
    }
}

TEST(MultiDevice, EveryDeviceTakesPiecesFromTheQueue) {
    for (const DeviceCase& c : device_cases()) {
        if (c.devices.size() < 2) continue;
        SCOPED_TRACE(list_name(c.devices));
        LaunchReport report;
        // Enough work that no device can take every piece before the others start: GPUs
        // share one tile counter, and one can start tens of microseconds after another.
        bool gpu = false;
        for (const DeviceSpec& d : c.devices) gpu = gpu || d.kind == Kind::kCuda;
        pattern(options_for(c.devices, 1), uint3{256, 2000, 0}, &report, gpu ? 256 : 32);
        expect_shares_cover(report, c.devices.size(), 256 * 2000);
        for (const auto& d : report.devices) EXPECT_GT(d.pieces, 0u) << d.device;
    }
}

/// Three rounds of accumulate (read-modify-write of the own pixel) then blur (reads the
/// neighbours, which other devices may have written).
std::vector<float> accumulate_and_blur(const ContextOptions& options) {
    Scene s(options);
    const unsigned w = 37, h = 29;
    auto sum = s.ctx.create_buffer<float>(BufferType::kInputOutput, w, h);
    sum->upload(std::vector<float>(w * h, 1.0f));
    auto blurred = s.ctx.create_buffer<float>(BufferType::kOutput, w, h);
    s.ctx["sum"] = sum;
    s.ctx["source"] = sum;
    s.ctx["blurred"] = blurred;
    s.ctx.set_ray_generation_program(0, program(s.ctx, LUCENT_PROGRAM(md_accumulate)));
    s.ctx.set_ray_generation_program(1, program(s.ctx, LUCENT_PROGRAM(md_blur)));
    std::vector<float> out;
    for (unsigned round = 0; round < 3; ++round) {
        s.ctx["round"] = round;
        s.ctx.launch(0, w, h);
        s.ctx.launch(1, w, h);
        const auto b = read_buffer<float>(*blurred);
        out.insert(out.end(), b.begin(), b.end());
    }
    const auto last = read_buffer<float>(*sum);
    out.insert(out.end(), last.begin(), last.end());
    return out;
}

TEST(MultiDevice, LaunchesReadWhatOtherDevicesWroteInTheLaunchBefore) {
    for (const DeviceCase& c : device_cases()) {
        SCOPED_TRACE(list_name(c.devices));
        std::vector<std::vector<float>> refs;
        for (const auto& r : c.references) refs.push_back(accumulate_and_blur(options_for(r)));
        // Sums of exact small integers and halves: every device gives the same bits.
        expect_matches(accumulate_and_blur(options_for(c.devices)), refs, "accumulate and blur");
    }
}

TEST(MultiDevice, LaunchesMeasuredSpreadAndWholeGiveTheOneDeviceImage) {
    // Sized pieces (piece_rows 0): each entry point runs spread, then whole on one device
    // (the others' copies fall behind and catch up when they next run), then spread.
    for (const DeviceCase& c : device_cases()) {
        SCOPED_TRACE(list_name(c.devices));
        std::vector<std::vector<float>> refs;
        for (const auto& r : c.references) refs.push_back(accumulate_and_blur(options_for(r)));
        expect_matches(accumulate_and_blur(options_for(c.devices, 0)), refs, "spread and whole");
    }
}

TEST(MultiDevice, ALaunchWritingABufferOfAnotherShapeRunsWholeOnOneDevice) {
    for (const DeviceCase& c : device_cases()) {
        SCOPED_TRACE(list_name(c.devices));
        Scene s(options_for(c.devices, 1));
        const unsigned w = 40, h = 3000;
        auto last_row = s.ctx.create_buffer<float>(BufferType::kInputOutput, w);
        last_row->upload(std::vector<float>(w, -1.0f));
        auto spread = s.ctx.create_buffer<float>(BufferType::kOutput, w, h);
        s.ctx["last_row"] = last_row;
        s.ctx["spread"] = spread;
        s.ctx.set_ray_generation_program(0, program(s.ctx, LUCENT_PROGRAM(md_last_row)));
        s.ctx.set_ray_generation_program(1, program(s.ctx, LUCENT_PROGRAM(md_spread)));
        s.ctx.launch(0, w, h);
        unsigned ran = 0, pieces = 0;
        for (const auto& d : s.ctx.last_launch().devices) ran += d.indices > 0, pieces += d.pieces;
        EXPECT_EQ(ran, 1u) << "one device runs a launch that writes a buffer of another shape";
        EXPECT_EQ(pieces, 1u);
        // Every device reads the row the one device wrote; a buffer viewed as
        // BufferView<const T> is only read, so this launch is split (in pieces or tiles).
        s.ctx.launch(1, w, h);
        pieces = 0;
        for (const auto& d : s.ctx.last_launch().devices) pieces += d.pieces;
        if (c.devices.size() > 1) EXPECT_GT(pieces, 1u);
        const auto got = read_buffer<float>(*spread);
        for (unsigned y = 0; y < h; ++y)
            for (unsigned x = 0; x < w; ++x)
                ASSERT_EQ(got[y * w + x], float(x * 3 + 1) + float(y)) << x << "," << y;
    }
}

TEST(MultiDevice, ExceptionsAreCountedOnceWithTheFirstIndexOfTheWholeLaunch) {
    for (const DeviceCase& c : device_cases()) {
        SCOPED_TRACE(list_name(c.devices));
        Scene s(options_for(c.devices));
        const unsigned w = 16, h = 200;
        auto done = s.ctx.create_buffer<unsigned>(BufferType::kOutput, w, h);
        s.ctx["done"] = done;
        s.ctx.set_exception_enabled(kAllExceptions, true);
        s.ctx.set_ray_generation_program(0, program(s.ctx, LUCENT_PROGRAM(md_raise)));
        s.ctx.set_ray_generation_program(1, program(s.ctx, LUCENT_PROGRAM(md_raise)));
        s.ctx.launch(0, w, h);
        const auto& e = s.ctx.last_launch().exceptions;
        ASSERT_EQ(e.count(kUserExceptionBase + 3), 1u);
        const auto& summary = e.at(kUserExceptionBase + 3);
        EXPECT_EQ(summary.count, 5u);  // rows 36, 73, 110, 147, 184
        EXPECT_EQ(summary.first_index.x, 5u);
        EXPECT_EQ(summary.first_index.y, 36u);
    }
}

std::vector<uint4> keys(const ContextOptions& options, unsigned seed) {
    Scene s(options);
    auto out = s.ctx.create_buffer<uint4>(BufferType::kOutput, 50, 40);
    s.ctx["keys"] = out;
    s.ctx.set_random_seed(seed);
    s.ctx.set_ray_generation_program(0, program(s.ctx, LUCENT_PROGRAM(md_device_key)));
    s.ctx.set_ray_generation_program(1, program(s.ctx, LUCENT_PROGRAM(md_device_key)));
    s.ctx.launch(0, 50, 40);
    return read_buffer<uint4>(*out);
}

bool same_key(uint4 a, uint4 b) {
    return a.x == b.x && a.y == b.y && a.z == b.z && a.w == b.w;
}

TEST(MultiDevice, EachDeviceSlotHasItsOwnKeyAndARunIsReproducibleFromTheSeed) {
    for (const DeviceCase& c : device_cases()) {
        SCOPED_TRACE(list_name(c.devices));
        const unsigned n = unsigned(c.devices.size());
        const auto got = keys(options_for(c.devices, 1), 1234);
        for (unsigned y = 0; y < 40; ++y)
            for (unsigned x = 0; x < 50; ++x) {
                const unsigned slot = device_slot_of(uint3{x, y, 0}, uint3{50, 40, 1}, n);
                const uint4 want = generate_tea_key(zafar_tea_key(), make_uint2(slot, 1234));
                ASSERT_TRUE(same_key(got[y * 50 + x], want)) << x << "," << y;
            }
        // The same with other pieces (another split among the devices), different by seed.
        const auto again = keys(options_for(c.devices, 3), 1234);
        const auto other_seed = keys(options_for(c.devices, 3), 1235);
        for (size_t i = 0; i < got.size(); ++i) {
            ASSERT_TRUE(same_key(got[i], again[i])) << i;
            ASSERT_FALSE(same_key(got[i], other_seed[i])) << i;
        }
        if (n > 1) EXPECT_FALSE(same_key(got[0], got[8])) << "tiles 0 and 1: slots 0 and 1";
    }
}

TEST(MultiDevice, SlotsDealTilesInTurn) {
    EXPECT_EQ(device_slot_of(uint3{7, 7, 0}, uint3{64, 64, 1}, 2), 0u);
    EXPECT_EQ(device_slot_of(uint3{8, 0, 0}, uint3{64, 64, 1}, 2), 1u);
    EXPECT_EQ(device_slot_of(uint3{0, 8, 0}, uint3{64, 64, 1}, 3), 8u % 3u);
    EXPECT_EQ(device_slot_of(uint3{130, 0, 0}, uint3{1000, 1, 1}, 4), 2u);
    EXPECT_EQ(device_slot_of(uint3{5, 5, 5}, uint3{64, 64, 64}, 1), 0u);
}

TEST(BufferContents, AreZeroedUntilSomethingWritesThem) {
    // Buffer::zeroed() lets a GPU clear its copy instead of uploading the host's bytes: it
    // must be false as soon as anything may have written them, a launch on the CPU too.
    Scene s(options_for({kCpu}));
    auto sum = s.ctx.create_buffer<float>(BufferType::kInputOutput, 4, 3);
    auto unbound = s.ctx.create_buffer<float>(BufferType::kInputOutput, 4, 3);
    EXPECT_TRUE(sum->zeroed());
    sum->upload(std::vector<float>(12, 1.0f));
    EXPECT_FALSE(sum->zeroed());
    sum->resize(4, 3);
    EXPECT_TRUE(sum->zeroed()) << "resize zeroes the contents";
    s.ctx["sum"] = sum;
    s.ctx["round"] = 1u;
    s.ctx.set_ray_generation_program(0, program(s.ctx, LUCENT_PROGRAM(md_accumulate)));
    s.ctx.launch(0, 4, 3);
    EXPECT_FALSE(sum->zeroed()) << "the launch wrote it";
    EXPECT_EQ(read_buffer<float>(*sum)[1], 10.0f);  // 0 * 0.5 + 1 * 7 + 1 * 3 + 0
    EXPECT_TRUE(unbound->zeroed()) << "no launch views it";
    sum->resize(4, 3);
    (void)sum->map<float>();
    sum->unmap();
    EXPECT_FALSE(sum->zeroed()) << "mapped: the host may have written it";
}

TEST(BufferContents, StartOnACacheLineWhateverTheirSize) {
    // The CPU backend's workers write neighbouring 64-index pieces of an output; a host
    // copy that started mid-line made neighbouring pieces share lines (false sharing).
    Scene s(options_for({kCpu}));
    for (unsigned count : {1u, 3u, 1000u, 786432u}) {
        auto bytes = s.ctx.create_buffer<unsigned char>(BufferType::kOutput, count);
        const auto address = reinterpret_cast<uintptr_t>(bytes->map<unsigned char>());
        bytes->unmap();
        EXPECT_EQ(address % 64, 0u) << count << " bytes";
        bytes->resize(count + 17);
        EXPECT_EQ(reinterpret_cast<uintptr_t>(bytes->map<unsigned char>()) % 64, 0u)
            << "resized to " << count + 17;
        bytes->unmap();
    }
}

TEST(DeviceList, ParsesNumbersCpuAndAll) {
    EXPECT_EQ(parse_device_list("0,1"), (std::vector<DeviceSpec>{gpu(0), gpu(1)}));
    EXPECT_EQ(parse_device_list(" CPU , 0 "), (std::vector<DeviceSpec>{kCpu, gpu(0)}));
    EXPECT_EQ(parse_device_list("0,0"), (std::vector<DeviceSpec>{gpu(0), gpu(0)}));
    const auto all = parse_device_list("all");
    if (gpus() == 0)
        EXPECT_EQ(all, (std::vector<DeviceSpec>{kCpu}));
    else
        EXPECT_EQ(all.size(), size_t(std::min(gpus(), int(kMaxDevices))));
    EXPECT_EQ(device_spec_name(gpu(3)), "cuda:3");
}

TEST(DeviceList, BadItemsAreNamed) {
    expect_error([] { parse_device_list("gpu0"); }, {"'gpu0'", "cpu,0"});
    expect_error([] { parse_device_list("0,,1"); }, {"''", "0,1"});
    expect_error([] { parse_device_list(""); }, {"neither"});
    std::string many = "cpu";
    for (int i = 0; i < 16; ++i) many += ",cpu";
    expect_error([&] { parse_device_list(many); }, {"17 devices", "at most 16"});
}

TEST(DeviceList, AGpuThatIsNotThereIsAClearError) {
    ContextOptions o;
    o.devices = {kCpu, gpu(63)};
    expect_error([&] { Context ctx(o); }, {"cuda:63"});
}

}  // namespace
}  // namespace lucent_tests
