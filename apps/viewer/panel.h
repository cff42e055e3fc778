// The ImGui panel: frames/s, the camera (and a button copying it as render flags), the
// denoiser switch, the last frame's stage timings, and a control per sample option
// (checkbox, slider or text field, from the option's kind and range); and the F1 key list.
#pragma once

#include <map>
#include <optional>
#include <string>

#include "render_worker.h"
#include "samples/sample.h"

namespace lucent::viewer {

/// What the panel shows besides the worker's status.
struct PanelState {
    double ui_fps = 0;      // window frames/s
    double render_fps = 0;  // finished renders/s (smoothed)
    const ShownFrame* frame = nullptr;
    std::string presentation;  // how frames reach the window (ImageView::presentation)
    double present_ms = 0;     // what showing the last frame cost the window's thread
    std::string message;  // the last key's effect ("saved lucent-view-1.png")
    const scene::Camera* camera = nullptr;  // the viewer's, once the session opened
};

/// What the user changed in the panel this frame.
struct PanelChanges {
    std::map<std::string, std::string> options;  // name → new value
    std::optional<unsigned> spp_limit;
    std::optional<samples::ViewDenoiser> denoiser;
    bool copy_flags = false;  // "copy as flags" was pressed
};

/// Draws the panel; returns what the user changed. Its size (window pixels) goes to `size`.
PanelChanges draw_panel(const samples::Sample& sample, const WorkerStatus& status,
                        const PanelState& state, float size[2]);

/// Draws the F1 list: every binding of key_bindings.h.
void draw_key_list();

}  // namespace lucent::viewer
