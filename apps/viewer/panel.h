// The ImGui panel: frames/s, the last frame's stage timings, and a control per sample
// option (checkbox, slider or text field, from the option's kind and range).
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
};

/// What the user changed in the panel this frame.
struct PanelChanges {
    std::map<std::string, std::string> options;  // name → new value
    std::optional<unsigned> spp_limit;
};

/// Draws the panel; returns what the user changed.
PanelChanges draw_panel(const samples::Sample& sample, const WorkerStatus& status,
                        const PanelState& state);

}  // namespace lucent::viewer
