// The Lucent host API in one include (lucent/lucent.h).
#pragma once

#include "lucent/lucent.h"
