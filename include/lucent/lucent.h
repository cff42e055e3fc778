// Lucent's host API in one include: the Context and everything it creates (buffers, nodes,
// programs, program modules, variables), errors, and the library's version.
#pragma once

#include "lucent/buffer.h"
#include "lucent/context.h"
#include "lucent/error.h"
#include "lucent/module.h"
#include "lucent/nodes.h"
#include "lucent/program.h"
#include "lucent/run_agreed.h"
#include "lucent/variables.h"
#include "lucent/version.h"
