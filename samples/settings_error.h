// The error for render settings that the user got wrong (unknown sample, bad --set), so a
// command line can tell them from engine failures (exit code 2 rather than 1).
#pragma once

#include "lucent/error.h"

namespace lucent::samples {

/// Thrown by find_sample and OptionValues (Sample::read_options) for bad user input.
class SettingsError : public Error {
  public:
    using Error::Error;
};

}  // namespace lucent::samples
