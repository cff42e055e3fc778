#include "scene/input_file.h"

#include <sys/stat.h>

#include "lucent/error.h"

namespace lucent::scene {

void require_regular_file(const std::string& path, const char* what) {
    struct stat st{};
    if (::stat(path.c_str(), &st) != 0) return;  // absent: the reader says so
    if (S_ISREG(st.st_mode)) return;
    const char* kind = S_ISDIR(st.st_mode)                        ? "a folder"
                       : S_ISFIFO(st.st_mode)                     ? "a FIFO (named pipe)"
                       : S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) ? "a device"
                       : S_ISSOCK(st.st_mode)                     ? "a socket"
                                                                  : "not a regular file";
    throw Error(path + ": this " + what + " is " + kind +
                ", not a file; Lucent reads scenes, meshes and textures only from regular "
                "files (copy the data into one)");
}

uint64_t file_size(const std::string& path) {
    struct stat st{};
    return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode) ? uint64_t(st.st_size) : 0;
}

}  // namespace lucent::scene
