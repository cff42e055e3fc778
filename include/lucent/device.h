// Everything a program module includes: vector math, device types, the device API,
// record reflection and the program macros.
#pragma once

#include "lucent/device/api.h"
#include "lucent/device/module.h"
#include "lucent/device/program.h"
#include "lucent/device/reflect.h"
#include "lucent/device/tea.h"
#include "lucent/device/types.h"
#include "lucent/device/vector_math.h"
