// Must not compile: a program macro outside any LUCENT_MODULE. The test
// (modules.program_outside_module) expects the compiler's message to say what to declare.
#include "lucent/device.h"

LUCENT_RAY_GENERATION(stray, lucent::NoRecord) {}
