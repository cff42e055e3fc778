// The Lucent host API: include this in applications.
#pragma once

#include "lucent/buffer.h"
#include "lucent/context.h"
#include "lucent/error.h"
#include "lucent/nodes.h"
#include "lucent/program.h"
#include "lucent/variables.h"
