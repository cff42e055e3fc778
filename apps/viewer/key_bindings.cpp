#include "key_bindings.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

namespace lucent::viewer {
namespace {

constexpr Binding kBindings[] = {
    {0, "left drag", "orbit around the target", KeyAction::kNone},
    {0, "right or middle drag", "pan", KeyAction::kNone},
    {0, "wheel", "zoom towards the target", KeyAction::kNone},
    {GLFW_KEY_W, "W (held)", "fly forward", KeyAction::kFlyForward},
    {GLFW_KEY_S, "S (held)", "fly back", KeyAction::kFlyBack},
    {GLFW_KEY_A, "A (held)", "fly left", KeyAction::kFlyLeft},
    {GLFW_KEY_D, "D (held)", "fly right", KeyAction::kFlyRight},
    {GLFW_KEY_Q, "Q (held)", "fly down", KeyAction::kFlyDown},
    {GLFW_KEY_E, "E (held)", "fly up", KeyAction::kFlyUp},
    {0, "Shift (held)", "fly 4x faster", KeyAction::kNone},
    {GLFW_KEY_F1, "F1", "show or hide this list", KeyAction::kToggleKeys},
    {GLFW_KEY_TAB, "Tab", "show or hide the panel", KeyAction::kTogglePanel},
    {GLFW_KEY_H, "H", "show or hide the panel", KeyAction::kTogglePanel},
    {GLFW_KEY_N, "N", "next denoiser: off, a-trous, svgf", KeyAction::kNextDenoiser},
    {GLFW_KEY_R, "R", "reset the accumulation", KeyAction::kReset},
    {GLFW_KEY_C, "C", "camera back to the start", KeyAction::kCameraBack},
    {GLFW_KEY_F, "F", "copy the camera as render flags", KeyAction::kCopyFlags},
    {GLFW_KEY_P, "P", "save a PNG of the render", KeyAction::kSavePng},
    {GLFW_KEY_L, "L", "show VPLs (radiosity)", KeyAction::kToggleVpls},
    {GLFW_KEY_I, "I", "GI on/off (radiosity)", KeyAction::kToggleGi},
    {GLFW_KEY_M, "M", "merging on/off (radiosity)", KeyAction::kToggleMerge},
    {GLFW_KEY_ESCAPE, "Esc", "quit", KeyAction::kQuit},
};

}  // namespace

std::span<const Binding> bindings() {
    return kBindings;
}

KeyAction action_of_key(int key) {
    for (const Binding& b : kBindings)
        if (b.key != 0 && b.key == key) return b.action;
    return KeyAction::kNone;
}

int key_of(KeyAction action) {
    for (const Binding& b : kBindings)
        if (b.key != 0 && b.action == action) return b.key;
    return 0;
}

}  // namespace lucent::viewer
