#include "panel.h"

#include <imgui.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "key_bindings.h"

namespace lucent::viewer {
namespace {

/// One option's control, from its kind: a checkbox for a switch, a slider for a number or
/// an integer whose range a slider can cover (a short one, or one a logarithmic slider spans:
/// lo > 0), a text field else (exposure 0..1e6, seed 0..2^30, a file name). Returns true
/// with `value` set when the user changed it.
bool option_control(const samples::SampleOption& option, const std::string& current,
                    std::string& value) {
    using samples::OptionKind;
    const char* label = option.name.c_str();
    if (option.kind == OptionKind::kSwitch) {
        bool on = current == "1";
        if (!ImGui::Checkbox(label, &on)) return false;
        value = on ? "1" : "0";
        return true;
    }
    const double lo = option.lo, hi = option.hi;
    const bool ranged = option.kind != OptionKind::kText && lo < hi && !current.empty();
    const bool logarithmic = ranged && lo > 0 && hi / lo >= 1000;
    if (ranged && (hi - lo <= 1024 || logarithmic)) {
        const ImGuiSliderFlags flags = logarithmic ? ImGuiSliderFlags_Logarithmic : 0;
        if (option.kind == OptionKind::kInteger) {
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

/// The camera's eye, look, up and fov, and the "copy as flags" button.
bool camera_readout(const scene::Camera& c) {
    ImGui::Text("eye  %.4g, %.4g, %.4g", c.eye.x, c.eye.y, c.eye.z);
    ImGui::Text("look %.4g, %.4g, %.4g", c.look.x, c.look.y, c.look.z);
    ImGui::Text("up   %.3g, %.3g, %.3g   fov %.4g", c.up.x, c.up.y, c.up.z, c.fov_degrees);
    return ImGui::Button("copy as flags (F)");
}

/// The denoiser switch: a radio button per denoiser.
std::optional<samples::ViewDenoiser> denoiser_switch(samples::ViewDenoiser current) {
    using samples::ViewDenoiser;
    std::optional<ViewDenoiser> chosen;
    ImGui::TextUnformatted("denoiser");
    for (ViewDenoiser d : {ViewDenoiser::kOff, ViewDenoiser::kAtrous, ViewDenoiser::kSvgf}) {
        ImGui::SameLine();
        if (ImGui::RadioButton(samples::view_denoiser_name(d), current == d) && current != d)
            chosen = d;
    }
    return chosen;
}

}  // namespace

void draw_key_list() {
    const ImGuiViewport* screen = ImGui::GetMainViewport();
    ImGui::SetNextWindowPos(ImVec2(screen->Size.x * 0.5f, screen->Size.y * 0.5f), ImGuiCond_Always,
                            ImVec2(0.5f, 0.5f));
    ImGui::SetNextWindowBgAlpha(0.9f);
    ImGui::Begin("keys (F1)", nullptr,
                 ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoCollapse);
    if (ImGui::BeginTable("bindings", 2, ImGuiTableFlags_RowBg)) {
        for (const Binding& b : bindings()) {
            ImGui::TableNextRow();
            ImGui::TableNextColumn();
            ImGui::TextUnformatted(b.input);
            ImGui::TableNextColumn();
            ImGui::TextUnformatted(b.does);
        }
        ImGui::EndTable();
    }
    ImGui::End();
}

PanelChanges draw_panel(const samples::Sample& sample, const WorkerStatus& status,
                        const PanelState& state, float size[2]) {
    PanelChanges changes;
    const float scale = ImGui::GetIO().FontGlobalScale;
    ImGui::SetNextWindowPos(ImVec2(8 * scale, 8 * scale), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowBgAlpha(0.8f);
    ImGui::Begin("lucent view", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
    ImGui::Text("%s on %s", sample.name.c_str(), status.backend.c_str());
    if (!status.backend_notice.empty()) ImGui::TextWrapped("%s", status.backend_notice.c_str());
    ImGui::Text("window %.0f frames/s, render %.2f frames/s%s", state.ui_fps, state.render_fps,
                status.busy ? " (rendering)" : "");
    if (const ShownFrame* f = state.frame; f && f->number > 0) {
        ImGui::Text("frame %llu, %ux%u, %.1f ms%s", (unsigned long long)f->number, f->width,
                    f->height, f->frame_ms, status.progressive ? "," : "");
        if (status.progressive) {
            ImGui::SameLine();
            ImGui::Text("%u spp", f->samples);
        }
        if (ImGui::CollapsingHeader("timings")) {
            for (const samples::StageTiming& stage : f->stages)
                ImGui::Text("  %-18s %9.2f ms", stage.name.c_str(), stage.ms);
            ImGui::Text("  %-18s %9.2f ms", "present", state.present_ms);
            ImGui::TextWrapped("shown by %s", state.presentation.c_str());
        }
    } else if (status.opened) {
        ImGui::Text("rendering the first frame...");
    } else if (status.error.empty()) {
        ImGui::Text("building the scene...");
    }
    if (!status.error.empty())
        ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", status.error.c_str());
    if (!state.message.empty()) ImGui::Text("%s", state.message.c_str());
    if (state.camera && camera_readout(*state.camera)) changes.copy_flags = true;
    if (status.denoises) changes.denoiser = denoiser_switch(status.denoiser);
    if (status.progressive) {
        // Applied on Enter or when the field loses focus, not per keystroke.
        int limit = int(status.spp_limit);
        ImGui::PushItemWidth(100 * ImGui::GetIO().FontGlobalScale);
        const bool entered = ImGui::InputInt("stop at spp (0: never)", &limit, 16, 256,
                                             ImGuiInputTextFlags_EnterReturnsTrue);
        if (entered || ImGui::IsItemDeactivatedAfterEdit())
            changes.spp_limit = unsigned(std::max(limit, 0));
        ImGui::PopItemWidth();
    }
    if (!sample.options.empty() && ImGui::CollapsingHeader("options")) {
        ImGui::PushItemWidth(140 * ImGui::GetIO().FontGlobalScale);
        for (const samples::SampleOption& option : sample.options) {
            auto it = status.sets.find(option.name);
            const std::string current = it != status.sets.end() ? it->second : option.default_value;
            std::string value;
            if (option_control(option, current, value)) changes.options[option.name] = value;
            if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", option.help_with_range().c_str());
        }
        ImGui::PopItemWidth();
    }
    size[0] = ImGui::GetWindowWidth();
    size[1] = ImGui::GetWindowHeight();
    ImGui::End();
    return changes;
}

}  // namespace lucent::viewer
