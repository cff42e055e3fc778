#include "core/cache_directory.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <set>
#include <string>

namespace lucent::core {

std::string cache_directory() {
    if (const char* d = std::getenv("LUCENT_CACHE_DIR")) return std::string(d) == "off" ? "" : d;
    if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return std::string(x) + "/lucent";
    if (const char* h = std::getenv("HOME"); h && *h) return std::string(h) + "/.cache/lucent";
    return "";
}

namespace {

/// One line on stderr per folder and process: why the cache is not used.
void warn_once(const std::string& dir, const std::string& why) {
    static std::mutex mutex;
    static std::set<std::string> warned;
    std::lock_guard lock(mutex);
    if (!warned.insert(dir).second) return;
    std::fprintf(stderr,
                 "lucent: not using the cache folder '%s': %s; compiling without the cache "
                 "(set LUCENT_CACHE_DIR to a folder of your own)\n",
                 dir.c_str(), why.c_str());
}

}  // namespace

std::string private_cache_subdirectory(const std::string& sub) {
    const std::string root = cache_directory();
    if (root.empty()) return "";
    std::error_code ec;
    std::filesystem::create_directories(root, ec);
    const std::string dir = root + "/" + sub;
    if (::mkdir(dir.c_str(), 0700) != 0 && errno != EEXIST) return "";
    struct stat st{};
    // lstat: a symbolic link planted in place of the folder is not followed. A folder that
    // another user owns or can write to could hold entries they planted: refused.
    if (::lstat(dir.c_str(), &st) != 0) return "";
    if (!S_ISDIR(st.st_mode)) {
        warn_once(dir, "it is not a folder (a link or a file is in its place)");
        return "";
    }
    if (st.st_uid != ::geteuid()) {
        warn_once(dir, "it is owned by another user (uid " + std::to_string(st.st_uid) + ")");
        return "";
    }
    if ((st.st_mode & 022) != 0) {
        warn_once(dir, "others can write to it (mode " + std::to_string((st.st_mode >> 6) & 7) +
                           std::to_string((st.st_mode >> 3) & 7) + std::to_string(st.st_mode & 7) +
                           "; chmod 700 it)");
        return "";
    }
    return dir;
}

}  // namespace lucent::core
