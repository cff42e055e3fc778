#include "cuda/jit/nvrtc_compiler.h"

#include <dlfcn.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <nvrtc.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/cache_directory.h"
#include "core/cache_key.h"
#include "cuda/jit/embedded_sources.h"
#include "cuda/jit/ptx_calls.h"
#include "lucent/error.h"

namespace lucent::cuda {

namespace {

struct NvrtcApi {
    decltype(&::nvrtcVersion) version = nullptr;
    decltype(&::nvrtcCreateProgram) create = nullptr;
    decltype(&::nvrtcDestroyProgram) destroy = nullptr;
    decltype(&::nvrtcCompileProgram) compile = nullptr;
    decltype(&::nvrtcGetProgramLogSize) log_size = nullptr;
    decltype(&::nvrtcGetProgramLog) log = nullptr;
    decltype(&::nvrtcGetCUBINSize) cubin_size = nullptr;
    decltype(&::nvrtcGetCUBIN) cubin = nullptr;
    decltype(&::nvrtcGetPTXSize) ptx_size = nullptr;
    decltype(&::nvrtcGetPTX) ptx = nullptr;
    decltype(&::nvrtcGetErrorString) error_string = nullptr;
    bool ok = false;
    std::string why;
};

const NvrtcApi& nvrtc() {
    static const NvrtcApi api = [] {
        NvrtcApi a;
        std::vector<std::string> candidates;
        if (const char* p = std::getenv("LUCENT_NVRTC")) candidates.push_back(p);
        candidates.insert(candidates.end(),
                          {"libnvrtc.so.13", "libnvrtc.so", "/usr/local/cuda/lib64/libnvrtc.so.13",
                           "/usr/local/cuda/lib64/libnvrtc.so"});
        void* lib = nullptr;
        for (auto& c : candidates)
            if ((lib = dlopen(c.c_str(), RTLD_NOW | RTLD_LOCAL))) break;
        if (!lib) {
            a.why = "NVRTC (libnvrtc.so) not found; install the CUDA toolkit or set LUCENT_NVRTC";
            return a;
        }
        auto get = [&](auto& fn, const char* name) {
            fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(dlsym(lib, name));
            if (!fn) a.why = std::string("NVRTC lacks ") + name;
        };
        get(a.version, "nvrtcVersion");
        get(a.create, "nvrtcCreateProgram");
        get(a.destroy, "nvrtcDestroyProgram");
        get(a.compile, "nvrtcCompileProgram");
        get(a.log_size, "nvrtcGetProgramLogSize");
        get(a.log, "nvrtcGetProgramLog");
        get(a.cubin_size, "nvrtcGetCUBINSize");
        get(a.cubin, "nvrtcGetCUBIN");
        get(a.ptx_size, "nvrtcGetPTXSize");
        get(a.ptx, "nvrtcGetPTX");
        get(a.error_string, "nvrtcGetErrorString");
        a.ok = a.why.empty();
        return a;
    }();
    return api;
}

using Key = core::CacheKey;

constexpr char kMagic[8] = {'L', 'U', 'C', 'B', 'I', 'N', '0', '1'};

uint64_t checksum(const std::string& data) {
    uint64_t h = 1469598103934665603ull;
    for (unsigned char c : data) h = (h ^ c) * 1099511628211ull;
    return h;
}

/// A cache entry: magic, the full key, payload size, payload checksum, payload. Anything
/// that does not match exactly is treated as absent (and overwritten).
constexpr size_t kHeaderBytes = 8 + 32 + 8 + 8;
constexpr uint64_t kMaxPayload = uint64_t(1) << 30;

/// Reads exactly `n` bytes (false at the end or on an error).
bool read_exactly(int fd, char* out, size_t n) {
    while (n > 0) {
        const ssize_t got = ::read(fd, out, n);
        if (got < 0 && errno == EINTR) continue;
        if (got <= 0) return false;
        out += got;
        n -= size_t(got);
    }
    return true;
}

/// The entry is opened without following a link and without blocking (a FIFO planted in
/// its place would hang the read), must be a regular file, and must be as long as its
/// header says before anything is allocated for it.
bool read_entry(const std::filesystem::path& file, const std::string& key, std::string& cubin) {
    const int fd = ::open(file.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return false;
    struct FdCloser {
        int fd;
        ~FdCloser() { ::close(fd); }
    } closer{fd};
    struct stat st{};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || uint64_t(st.st_size) < kHeaderBytes)
        return false;
    char header[kHeaderBytes];
    if (!read_exactly(fd, header, kHeaderBytes) || std::memcmp(header, kMagic, 8) != 0 ||
        std::string(header + 8, 32) != key)
        return false;
    uint64_t size = 0, sum = 0;
    std::memcpy(&size, header + 40, 8);
    std::memcpy(&sum, header + 48, 8);
    if (size > kMaxPayload || uint64_t(st.st_size) != kHeaderBytes + size) return false;
    cubin.resize(size);
    if (!read_exactly(fd, cubin.data(), size)) return false;
    return checksum(cubin) == sum;
}

/// Written to a temporary of an unpredictable name created with O_EXCL (mkstemp) in the
/// cache's own folder, then renamed over the entry: a link planted at either name is never
/// followed, and readers never see half an entry.
void write_entry(const std::filesystem::path& file, const std::string& key,
                 const std::string& cubin) {
    std::string tmp = file.string() + ".XXXXXX";
    const int fd = ::mkstemp(tmp.data());
    if (fd < 0) return;  // an unwritable cache only costs speed
    std::string bytes(kMagic, 8);
    bytes += key;
    const uint64_t size = cubin.size(), sum = checksum(cubin);
    bytes.append(reinterpret_cast<const char*>(&size), 8);
    bytes.append(reinterpret_cast<const char*>(&sum), 8);
    bytes += cubin;
    bool ok = true;
    for (size_t done = 0; ok && done < bytes.size();) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR) continue;
        ok = n > 0;
        if (ok) done += size_t(n);
    }
    ok = ::close(fd) == 0 && ok;
    if (!ok || ::rename(tmp.c_str(), file.c_str()) != 0) ::unlink(tmp.c_str());
}

/// Beside a cached CUBIN, the call graph of its PTX (the PTX itself is not kept):
/// `<key>.calls`, written and read as the CUBIN's entry is; one line per function, its name
/// and then its callees', separated by spaces.
std::filesystem::path call_graph_entry(const std::filesystem::path& cubin_entry) {
    std::filesystem::path p = cubin_entry;
    return p.replace_extension(".calls");
}

std::string call_graph_text(const PtxCallGraph& graph) {
    std::string text;
    for (const auto& [name, callees] : graph) {
        text += name;
        for (const std::string& c : callees) text += " " + c;
        text += "\n";
    }
    return text;
}

PtxCallGraph parse_call_graph(const std::string& text) {
    PtxCallGraph graph;
    std::istringstream lines(text);
    for (std::string line; std::getline(lines, line);) {
        std::istringstream words(line);
        std::string name;
        if (!(words >> name)) continue;
        std::set<std::string>& callees = graph[name];
        for (std::string c; words >> c;) callees.insert(c);
    }
    return graph;
}

}  // namespace

std::string nvrtc_version(std::string* why) {
    const NvrtcApi& api = nvrtc();
    if (!api.ok) {
        if (why) *why = api.why;
        return "";
    }
    int major = 0, minor = 0;
    api.version(&major, &minor);
    return std::to_string(major) + "." + std::to_string(minor);
}

std::string kernel_cache_dir() {
    return core::private_cache_subdirectory("kernels");
}

CompileRequest embedded_request(std::string name, std::string source,
                                std::vector<std::string> options, int sm) {
    CompileRequest request;
    request.name = std::move(name);
    request.source = std::move(source);
    for (const EmbeddedSource& s : embedded_sources())
        request.headers.emplace_back(std::string(s.name), std::string(s.text));
    request.options = std::move(options);
    request.sm = sm;
    return request;
}

void add_options_from_env(CompileRequest& request, const char* variable) {
    const char* text = std::getenv(variable);
    if (!text) return;
    std::istringstream words(text);
    for (std::string w; words >> w;) request.options.push_back(w);
}

CompileResult compile_cubin(const CompileRequest& request) {
    using Clock = std::chrono::steady_clock;
    auto t0 = Clock::now();
    std::string why;
    std::string version = nvrtc_version(&why);
    if (version.empty()) throw Error("cannot compile GPU code: " + why);

    std::vector<std::string> options = request.options;
    options.push_back("--gpu-architecture=sm_" + std::to_string(request.sm));
    Key key;
    key.add(version);
    key.add(request.source);
    for (auto& [name, text] : request.headers) {
        key.add(name);
        key.add(text);
    }
    for (auto& o : options) key.add(o);
    const std::string hex = key.hex();

    CompileResult result;
    const std::string dir = kernel_cache_dir();
    const std::filesystem::path file =
        dir.empty() ? std::filesystem::path() : std::filesystem::path(dir) / (hex + ".cubin");
    if (!dir.empty() && read_entry(file, hex, result.cubin)) {
        result.from_cache = true;
        // Entries cached before call graphs were kept have none: unknown then.
        std::string calls;
        result.call_graph_known = read_entry(call_graph_entry(file), hex, calls);
        if (result.call_graph_known) result.call_graph = parse_call_graph(calls);
        result.ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
        return result;
    }

    const NvrtcApi& api = nvrtc();
    std::vector<const char*> header_text, header_names, option_ptrs;
    for (auto& [name, text] : request.headers) {
        header_names.push_back(name.c_str());
        header_text.push_back(text.c_str());
    }
    for (auto& o : options) option_ptrs.push_back(o.c_str());
    nvrtcProgram program;
    if (nvrtcResult r =
            api.create(&program, request.source.c_str(), request.name.c_str(),
                       int(header_text.size()), header_text.data(), header_names.data());
        r != NVRTC_SUCCESS)
        throw Error(std::string("NVRTC: cannot create program: ") + api.error_string(r));
    nvrtcResult compiled = api.compile(program, int(option_ptrs.size()), option_ptrs.data());
    size_t log_size = 0;
    api.log_size(program, &log_size);
    result.log.resize(log_size);
    if (log_size) api.log(program, result.log.data());
    while (!result.log.empty() && (result.log.back() == '\0' || result.log.back() == '\n'))
        result.log.pop_back();
    // LUCENT_NVRTC_LOG=1: print the compile's log, e.g. ptxas's register and stack report
    // with LUCENT_NVRTC_OPTIONS=--ptxas-options=-v (a tuning aid; docs/performance.md).
    if (compiled == NVRTC_SUCCESS && !result.log.empty() && std::getenv("LUCENT_NVRTC_LOG"))
        std::fprintf(stderr, "NVRTC log of %s:\n%s\n", request.name.c_str(), result.log.c_str());
    if (compiled != NVRTC_SUCCESS) {
        api.destroy(&program);
        throw Error("NVRTC could not compile " + request.name + " (" + api.error_string(compiled) +
                    "):\n" + result.log);
    }
    size_t size = 0;
    api.cubin_size(program, &size);
    result.cubin.resize(size);
    api.cubin(program, result.cubin.data());
    size_t ptx_size = 0;
    if (api.ptx_size(program, &ptx_size) == NVRTC_SUCCESS && ptx_size > 0) {
        std::string ptx(ptx_size, '\0');
        if (api.ptx(program, ptx.data()) == NVRTC_SUCCESS) {
            result.call_graph = ptx_call_graph(ptx);
            result.call_graph_known = true;
        }
    }
    api.destroy(&program);
    if (!dir.empty()) {
        write_entry(file, hex, result.cubin);
        if (result.call_graph_known)
            write_entry(call_graph_entry(file), hex, call_graph_text(result.call_graph));
    }
    result.ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    return result;
}

}  // namespace lucent::cuda
