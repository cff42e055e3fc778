// A display frame in host memory: what the CPU backend (and any backend whose output is
// already on the host) gives Context::display_frame.
#pragma once

#include <vector>

#include "lucent/display.h"

namespace lucent::core {

class HostDisplayFrame final : public DisplayFrame {
  public:
    HostDisplayFrame(unsigned width, unsigned height)
        : DisplayFrame(width, height), m_rgba(bytes()) {}
    bool on_device() const override { return false; }
    std::vector<unsigned char> rgba() const override { return m_rgba; }
    unsigned char* pixels() { return m_rgba.data(); }

  private:
    std::vector<unsigned char> m_rgba;
};

}  // namespace lucent::core
