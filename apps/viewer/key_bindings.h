// Every key and mouse binding of the viewer in one table: the key handling looks its
// presses up here and the F1 list draws it, so the list cannot drift from the code.
#pragma once

#include <span>

namespace lucent::viewer {

/// What a key does (the viewer's loop switches on a press's; Input reads the held ones).
enum class KeyAction {
    kNone,        // a mouse binding or Shift, read by Input::move_camera
    kFlyForward,  // held keys, read by Input::move_camera through key_of()
    kFlyBack,
    kFlyLeft,
    kFlyRight,
    kFlyDown,
    kFlyUp,
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
/// The GLFW key of an action (its first binding); 0 when none has one.
int key_of(KeyAction action);

}  // namespace lucent::viewer
