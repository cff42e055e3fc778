// The one error type of the host API.
#pragma once

#include <stdexcept>
#include <string>

namespace lucent {

/// Thrown by every host call that is wrong; the message names the object and the fix.
class Error : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

}  // namespace lucent
