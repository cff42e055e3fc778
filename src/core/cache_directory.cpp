#include "core/cache_directory.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>

namespace lucent::core {

std::string cache_directory() {
    if (const char* d = std::getenv("LUCENT_CACHE_DIR")) return std::string(d) == "off" ? "" : d;
    if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return std::string(x) + "/lucent";
    if (const char* h = std::getenv("HOME"); h && *h) return std::string(h) + "/.cache/lucent";
    return "";
}

std::string private_cache_subdirectory(const std::string& sub) {
    const std::string root = cache_directory();
    if (root.empty()) return "";
    std::error_code ec;
    std::filesystem::create_directories(root, ec);
    const std::string dir = root + "/" + sub;
    if (::mkdir(dir.c_str(), 0700) != 0 && errno != EEXIST) return "";
    struct stat st{};
    // lstat: a symbolic link planted in place of the folder is not followed.
    if (::lstat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode) || st.st_uid != ::geteuid() ||
        (st.st_mode & 022) != 0)
        return "";
    return dir;
}

}  // namespace lucent::core
