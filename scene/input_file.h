// Checks on a scene, mesh or texture file before it is read: a FIFO, a device (/dev/zero) or
// a folder given as a file would be read for ever or fail obscurely.
#pragma once

#include <cstdint>
#include <string>

namespace lucent::scene {

/// Throws Error naming `path` and `what` it was meant to be ("OBJ file", "texture") when it
/// exists and is not a regular file. A missing file is left to the reader's own message.
void require_regular_file(const std::string& path, const char* what);

/// The size in bytes of a regular file (0 when it cannot be read).
uint64_t file_size(const std::string& path);

}  // namespace lucent::scene
