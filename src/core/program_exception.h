// How a program's exception travels on the CPU: as a C++ exception that abandons the
// current launch index (or, in a bounding-box program, the acceleration build).
#pragma once

namespace lucent::core {

/// Thrown by the device API (raise_exception) on the CPU: an engine exception such as
/// stack overflow, or a user exception. Caught by the launch loop and the accel builder.
struct ProgramException {
    int code;
    unsigned detail;
};

}  // namespace lucent::core
