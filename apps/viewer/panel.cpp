#include "panel.h"

#include <imgui.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace lucent::viewer {
namespace {

bool is_integer(const std::string& text) {
    int value = 0;
    const char* end = text.data() + text.size();
    auto [ptr, ec] = std::from_chars(text.data(), end, value);
    return !text.empty() && ec == std::errc() && ptr == end;
}

/// An on/off option: an integer defaulting to 0 or 1 whose help explains "0:" or "1 =".
bool is_switch(const samples::SampleOption& option) {
    if (option.default_value != "0" && option.default_value != "1") return false;
    for (const char* mark : {"0:", "1:", "0 =", "1 ="})
        if (option.help.find(mark) != std::string::npos) return true;
    return false;
}

/// One option's control; returns true with `value` set when the user changed it.
bool option_control(const samples::SampleOption& option, const std::string& current,
                    std::string& value) {
    const char* label = option.name.c_str();
    if (is_switch(option)) {
        bool on = current == "1";
        if (!ImGui::Checkbox(label, &on)) return false;
        value = on ? "1" : "0";
        return true;
    }
    double lo = 0, hi = 0;
    // A slider where the help names a range it can cover: a short one, or one a logarithmic
    // slider spans (lo > 0); a text field else (exposure 0..1e6, seed 0..2^30).
    const bool ranged = samples::option_range(option, lo, hi) && !current.empty();
    const bool logarithmic = ranged && lo > 0 && hi / lo >= 1000;
    if (ranged && (hi - lo <= 1024 || logarithmic)) {
        const ImGuiSliderFlags flags = logarithmic ? ImGuiSliderFlags_Logarithmic : 0;
        if (is_integer(option.default_value) && std::floor(lo) == lo && std::floor(hi) == hi) {
            int v = std::atoi(current.c_str());
            // Released, not dragged: each change may rebuild or restart the render.
            ImGui::SliderInt(label, &v, int(lo), int(hi), "%d", flags);
            if (!ImGui::IsItemDeactivatedAfterEdit()) return false;
            value = std::to_string(v);
            return true;
        }
        float v = float(std::atof(current.c_str()));
        ImGui::SliderFloat(label, &v, float(lo), float(hi), "%.4g", flags);
        if (!ImGui::IsItemDeactivatedAfterEdit()) return false;
        char text[32];
        std::snprintf(text, sizeof text, "%.6g", v);
        value = text;
        return true;
    }
    char text[256];
    std::snprintf(text, sizeof text, "%s", current.c_str());
    if (!ImGui::InputText(label, text, sizeof text, ImGuiInputTextFlags_EnterReturnsTrue))
        return false;
    value = text;
    return true;
}

}  // namespace

PanelChanges draw_panel(const samples::SampleInfo& info, const WorkerStatus& status,
                        const PanelState& state) {
    PanelChanges changes;
    ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowBgAlpha(0.8f);
    ImGui::Begin("lucent view", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
    ImGui::Text("%s on %s", info.name.c_str(), status.backend.c_str());
    if (!status.backend_notice.empty()) ImGui::TextWrapped("%s", status.backend_notice.c_str());
    ImGui::Text("window %.0f frames/s, render %.2f frames/s%s", state.ui_fps, state.render_fps,
                status.busy ? " (rendering)" : "");
    if (const ShownFrame* f = state.frame; f && f->number > 0) {
        ImGui::Text("frame %llu, %ux%u, %.1f ms", (unsigned long long)f->number, f->width,
                    f->height, f->frame_ms);
        if (status.progressive) ImGui::Text("%u samples per pixel", f->samples);
        for (const samples::StageTiming& stage : f->stages)
            ImGui::Text("  %-18s %9.2f ms", stage.name.c_str(), stage.ms);
        ImGui::Text("  %-18s %9.2f ms", "present", state.present_ms);
        ImGui::TextWrapped("shown by %s", state.presentation.c_str());
    } else if (status.opened) {
        ImGui::Text("rendering the first frame...");
    } else if (status.error.empty()) {
        ImGui::Text("building the scene...");
    }
    if (status.fixed_camera)
        ImGui::TextWrapped(
            "This sample has no interactive session: its own camera, "
            "re-rendered when an option changes.");
    if (!status.error.empty())
        ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", status.error.c_str());
    if (!state.message.empty()) ImGui::Text("%s", state.message.c_str());
    if (status.progressive) {
        // Applied on Enter or when the field loses focus, not per keystroke.
        int limit = int(status.spp_limit);
        ImGui::PushItemWidth(140);
        const bool entered = ImGui::InputInt("stop at spp (0: never)", &limit, 16, 256,
                                             ImGuiInputTextFlags_EnterReturnsTrue);
        if (entered || ImGui::IsItemDeactivatedAfterEdit())
            changes.spp_limit = unsigned(std::max(limit, 0));
        ImGui::PopItemWidth();
    }
    if (!info.options.empty() &&
        ImGui::CollapsingHeader("options", ImGuiTreeNodeFlags_DefaultOpen)) {
        ImGui::PushItemWidth(140);
        for (const samples::SampleOption& option : info.options) {
            auto it = status.sets.find(option.name);
            const std::string current = it != status.sets.end() ? it->second : option.default_value;
            std::string value;
            if (option_control(option, current, value)) changes.options[option.name] = value;
            if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", option.help.c_str());
        }
        ImGui::PopItemWidth();
    }
    ImGui::End();
    return changes;
}

}  // namespace lucent::viewer
