// Every key and mouse binding of the viewer in one table: the key handling looks its
// presses up here and the F1 list draws it, so the list cannot drift from the code.
#pragma once

#include <span>

namespace lucent::viewer {

/// What a key press does (the viewer's loop switches on it).
enum class KeyAction {
    kNone,  // a held key or a mouse binding, read by Input::move_camera
    kQuit,
    kTogglePanel,
    kToggleKeys,  // the F1 list
    kReset,
    kCameraBack,
    kSavePng,
    kCopyFlags,
    kNextDenoiser,
    kToggleVpls,
    kToggleGi,
    kToggleMerge,
};

struct Binding {
    int key;            // GLFW_KEY_*; 0 for a mouse binding or a held key
    const char* input;  // as the list shows it: "Tab", "left drag"
    const char* does;
    KeyAction action;
};

/// The bindings in the order the F1 list shows them.
std::span<const Binding> bindings();
/// The action of a pressed GLFW key; kNone when no binding has it.
KeyAction action_of_key(int key);

}  // namespace lucent::viewer
