// Temporary files that a signal must not leave behind. write_image writes a hidden
// temporary beside its target and renames it; a render killed (Ctrl-C, kill) during that
// write used to leave the temporary. While registered here, a temporary is removed by the
// handlers of SIGINT, SIGTERM, SIGHUP and SIGQUIT, which then end the process as the signal
// would have.
#pragma once

#include <string>

namespace lucent::scene {

/// Installs the handlers (once; later calls do nothing). A program that writes images calls
/// it at start (the `lucent` CLI does); without it a signal ends the process as before.
void remove_temp_files_on_signals();

/// Keeps `path` registered for removal while it lives (at most 16 at once: more are not
/// registered, and are left to the writer's own cleanup). Copying is not allowed.
class TempFileGuard {
  public:
    explicit TempFileGuard(const std::string& path);
    ~TempFileGuard();
    TempFileGuard(const TempFileGuard&) = delete;
    TempFileGuard& operator=(const TempFileGuard&) = delete;

  private:
    int m_slot = -1;
};

}  // namespace lucent::scene
