// SPDX-License-Identifier: Apache-2.0
#include "app/panels.h"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <imgui.h>

#include "core/format.h"

namespace sweepers {

namespace {

// The panel's width when it first opens; every label must fit in it (mustFit).
constexpr float kPanelWidth = 380.0f;
// The voxel sizes the panel offers as levels of detail (1/N).
constexpr int kDetailLevels[] = {64, 128, 256, 512};
// A mesh's bytes per triangle: three indices, and about half a vertex's position and normal.
constexpr double kMeshBytesPerTriangle = 3 * 4 + 0.5 * 24;

// "1/128" where the voxel size is one over a whole number, else the number.
std::string detailName(double h) {
    const double n = std::round(1.0 / h);
    if (h > 0 && std::abs(1.0 / n - h) < 1e-9 * h) return "1/" + std::to_string(int(n));
    return formatNumber(h);
}

// An item whose right edge passes the panel's: its label is cut off. Reported once at exit,
// so that a test of the window at its default size sees it.
void mustFit(PanelState& ui, const char* what) {
    const float right = ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x;
    if (ImGui::GetItemRectMax().x > right + 0.5f) ui.clipped.insert(what);
}

// The memory a document of this shape needs at voxel size h: its band and its mesh both grow
// with the surface's area in voxels, so the figures now scale as (h_now / h)^2.
double memoryAtVoxelSize(const Figures& f, double h) {
    const double now = f.voxelSize > 0 ? f.voxelSize : h;
    const double bytes = double(f.gridBytes) + kMeshBytesPerTriangle * f.triangles;
    return bytes * (now / h) * (now / h);
}

// The tool modes, as many to a row as fit the panel's width: the sweeps first, then swirl,
// fluid and clay, then the topology tools.
void modeButtons(PanelState& ui, ToolSettings& s) {
    const ImGuiStyle& style = ImGui::GetStyle();
    const float right = ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x;
    int m = int(s.mode);
    for (std::size_t k = 0; k < kModes.size(); ++k) {
        if (k != 0) {
            const float width = ImGui::GetFrameHeight() + style.ItemInnerSpacing.x +
                                ImGui::CalcTextSize(kModes[k].label).x;
            ImGui::SameLine();
            if (ImGui::GetCursorScreenPos().x + width > right) ImGui::NewLine();
        }
        ImGui::RadioButton(kModes[k].label, &m, int(kModes[k].mode));
        mustFit(ui, kModes[k].label);
    }
    s.mode = SculptMode(m);
}

void toolSection(PanelState& ui, SculptController& ctl, GlRenderer& renderer) {
    ImGui::Text("Tool");
    ToolSettings& s = ctl.settings();
    ImGui::BeginDisabled(ctl.drag() == DragKind::Sculpt);
    modeButtons(ui, s);
    ImGui::EndDisabled();
    if (s.mode == SculptMode::Pinch)
        ImGui::TextWrapped("Drag from the surface: the hole goes through along the view, "
                           "the drag sets its radius; release to pinch.");
    else if (s.mode == SculptMode::Strangle)
        ImGui::TextWrapped("Drag across a limb: the drag sets the circle's radius, the "
                           "radius below the gap; release to strangle.");
    if (s.bakedTool) {
        ImGui::Text("tool: %s", s.bakedSource.file.c_str());
        ImGui::SameLine();
        if (ImGui::Button("Ball")) ctl.useBall();
    }
    float r = float(s.radius), f = float(s.falloff);
    if (ImGui::SliderFloat("radius  [ ]", &r, 0.02f, 1.0f, "%.3f", ImGuiSliderFlags_Logarithmic))
        s.radius = r;
    mustFit(ui, "radius  [ ]");
    if (ImGui::SliderFloat("falloff  shift [ ]", &f, 0.02f, 1.0f, "%.3f",
                           ImGuiSliderFlags_Logarithmic))
        s.falloff = f;
    mustFit(ui, "falloff  shift [ ]");
    float strength = float(s.strength);
    if (ImGui::SliderFloat("strength  shift F", &strength, 0.01f, 1.0f, "%.2f"))
        s.strength = std::clamp(double(strength), 0.01, 1.0);
    mustFit(ui, "strength  shift F");
    // Smoothing's own strength (Shift-drag uses it whatever the tool): past 1 it reaches the
    // form, not only the noise.
    float smooth = float(s.smoothStrength);
    if (ImGui::SliderFloat("smooth strength", &smooth, 0.1f, float(kMostSmoothStrength), "%.2f",
                           ImGuiSliderFlags_Logarithmic))
        s.smoothStrength = std::clamp(double(smooth), 0.01, kMostSmoothStrength);
    mustFit(ui, "smooth strength");
    int mirror = int(s.mirror);
    ImGui::Combo("mirror (M)", &mirror, "none\0x\0y\0z\0");
    mustFit(ui, "mirror (M)");
    s.mirror = MirrorAxis(mirror);
    ImGui::SliderInt("radial", &s.radialCount, 1, 64);
    mustFit(ui, "radial");
    if (s.radialCount > 1) {
        ImGui::Combo("radial axis", &s.radialAxis, "x\0y\0z\0");
        mustFit(ui, "radial axis");
    }
    if (ctl.sizing() != Sizing::None)
        ImGui::TextWrapped("Move the mouse to set the %s; click to keep it, Esc to put it back.",
                           ctl.sizing() == Sizing::Radius ? "radius" : "strength");
    ImGui::Checkbox("wireframe (W)", &s.wireframe);
    // The surface's look: clay, or a matcap that reads form without lights.
    int look = int(renderer.look());
    ImGui::Combo("look", &look, "clay\0glossy\0red wax\0normals\0");
    mustFit(ui, "look");
    renderer.setLook(kSurfaceLooks[std::clamp(look, 0, 3)]);
}

void documentSection(PanelState& ui, PanelRequests& out) {
    out.undo = ImGui::Button("Undo");
    ImGui::SameLine();
    out.redo = ImGui::Button("Redo");
    ImGui::SameLine();
    out.openFilm = ImGui::Button("Film of the history (V)");
    mustFit(ui, "Film of the history (V)");
    ImGui::Separator();
    ImGui::InputText("file", ui.path, sizeof ui.path);
    out.open = ImGui::Button("Open");
    ImGui::SameLine();
    out.toolFromFile = ImGui::Button("Tool from file");
    ImGui::SameLine();
    out.save = ImGui::Button("Save");
    ImGui::SameLine();
    out.newSphere = ImGui::Button("New sphere");
    mustFit(ui, "New sphere");
    ImGui::Checkbox("half floats", &ui.saveHalf);
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip("Save .vdb files with 16-bit float values: a third smaller, each "
                          "value within a voxel of the surface rounded by under 1/2048 voxel");
    ImGui::TextWrapped("Open reads .vdb and .json, imports .obj/.ply/.stl; Save writes "
                       ".vdb, the stroke script for .json, a mesh for .obj/.ply/.stl.");
}

// Detail: the history replayed at a finer or coarser voxel size, offered at the sizes artists
// pick from, each with what it would cost for this shape, or at any size.
void detailSection(PanelState& ui, PanelRequests& out) {
    const Figures& f = ui.figures;
    char current[64];
    std::snprintf(current, sizeof current, "%s (now)", detailName(f.voxelSize).c_str());
    if (ImGui::BeginCombo("detail", current)) {
        for (const int n : kDetailLevels) {
            const double h = 1.0 / n;
            const std::string item =
                "1/" + std::to_string(n) + "  (about " + formatBytes(memoryAtVoxelSize(f, h)) + ")";
            const bool now = std::abs(h - f.voxelSize) < 1e-9 * h;
            if (ImGui::Selectable(item.c_str(), now) && !now) {
                ui.voxelSizeInput = float(h);
                out.resample = h;
            }
        }
        ImGui::EndCombo();
    }
    mustFit(ui, "detail");
    ImGui::InputFloat("voxel size", &ui.voxelSizeInput, 0.0f, 0.0f, "%.6f");
    mustFit(ui, "voxel size");
    if (ImGui::Button("Resample at this voxel size")) out.resample = ui.voxelSizeInput;
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("Replay the history at this voxel size");
    mustFit(ui, "Resample at this voxel size");
}

// The engine's figures: for whoever wants them, out of an artist's way.
void statisticsSection(const Figures& f, const SculptController& ctl, const Document& doc) {
    if (!ImGui::CollapsingHeader("Statistics")) return;
    ImGui::Text("voxel size %.5g, active voxels %zu", f.voxelSize, f.activeVoxels);
    ImGui::Text("triangles %zu, volume %.5f", f.triangles, ctl.volume());
    ImGui::Text("frame %.1f ms, upload %.1f ms", f.frameMs, f.uploadMs);
    const SegmentReport& last = f.lastSegment;
    ImGui::Text("last segment: advect %.1f, renorm %.1f,", 1e3 * last.advectSeconds(),
                1e3 * last.stats.renormalizeSeconds);
    ImGui::Text("  mesh %.1f ms", 1e3 * last.meshSeconds);
    ImGui::Text("undo: %zu edits in %.1f of %.0f MB,", f.undoCount, double(f.undoBytes) / (1 << 20),
                double(doc.undoBudget()) / (1 << 20));
    ImGui::Text("  %zu more by replay", doc.droppedCount());
}

// A modal dialog with buttons; returns the index of the one pressed (-1: none), and closes.
int modal(const char* name, const std::function<void()>& body,
          std::initializer_list<const char*> buttons) {
    if (!ImGui::BeginPopupModal(name, nullptr, ImGuiWindowFlags_AlwaysAutoResize)) return -1;
    body();
    int pressed = -1, k = 0;
    for (const char* label : buttons) {
        if (k > 0) ImGui::SameLine();
        if (ImGui::Button(label)) pressed = k;
        ++k;
    }
    if (pressed >= 0) ImGui::CloseCurrentPopup();
    ImGui::EndPopup();
    return pressed;
}

} // namespace

void mainPanel(PanelState& ui, SculptController& ctl, GlRenderer& renderer, const Document& doc,
               bool locked, PanelRequests& out) {
    ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(kPanelWidth, 0), ImGuiCond_FirstUseEver);
    ImGui::Begin("Sweepers");
    // Sliders and fields leave room for the longest label beside them.
    const ImGuiStyle& style = ImGui::GetStyle();
    ImGui::PushItemWidth(-(ImGui::CalcTextSize("falloff  shift [ ]").x + style.ItemInnerSpacing.x +
                           style.WindowPadding.x * 0.5f));
    toolSection(ui, ctl, renderer);
    // Nothing that changes the document while a drag is being sculpted, or while the film of
    // its history plays.
    ImGui::BeginDisabled(locked);
    documentSection(ui, out);
    ImGui::Separator();
    detailSection(ui, out);
    ImGui::EndDisabled();
    if (!ui.status.empty()) ImGui::TextWrapped("%s", ui.status.c_str());
    statisticsSection(ui.figures, ctl, doc);
    ImGui::PopItemWidth();
    ImGui::End();
}

void filmPanel(PanelState& ui, Timeline& f, PanelRequests& out) {
    const ImVec2 size = ImGui::GetIO().DisplaySize;
    ImGui::SetNextWindowPos(ImVec2(size.x * 0.5f, size.y - 10.0f), ImGuiCond_Always,
                            ImVec2(0.5f, 1.0f));
    ImGui::SetNextWindowSize(ImVec2(std::min(size.x - 20.0f, 720.0f), 0.0f), ImGuiCond_Always);
    ImGui::Begin("Film of the history (V)", nullptr,
                 ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoResize);
    int frame = int(f.wanted());
    ImGui::SetNextItemWidth(-1.0f);
    if (ImGui::SliderInt("##frame", &frame, 1, int(f.frameCount()), "frame %d")) {
        f.pause();
        f.scrubTo(std::size_t(frame));
    }
    // The buttons are the timeline's keys.
    const std::pair<const char*, int> keys[] = {
        {f.playing() ? "Pause (space)" : "Play (space)", GLFW_KEY_SPACE},
        {"|< Home", GLFW_KEY_HOME},
        {"< ,", GLFW_KEY_COMMA},
        {". >", GLFW_KEY_PERIOD},
        {"End >|", GLFW_KEY_END}};
    for (const auto& [label, key] : keys) {
        if (key != GLFW_KEY_SPACE) ImGui::SameLine();
        if (ImGui::Button(label)) out.filmKey = key;
    }
    ImGui::SameLine();
    static const float speeds[] = {0.25f, 0.5f, 1.0f, 2.0f, 4.0f};
    int speed = 2;
    for (int k = 0; k < 5; ++k)
        if (double(speeds[k]) == f.speed()) speed = k;
    ImGui::SetNextItemWidth(90.0f);
    if (ImGui::Combo("speed", &speed,
                     "0.25x\0"
                     "0.5x\0"
                     "1x\0"
                     "2x\0"
                     "4x\0"))
        f.setSpeed(speeds[speed]);
    ImGui::Text("frame %zu of %zu, %.2f of %.2f s, volume %.5f%s", f.shown(), f.frameCount(),
                filmFrameTime(std::max<std::size_t>(f.shown(), 1), f.seconds(), f.fps()),
                f.seconds(), ui.figures.filmVolume, f.busy() ? "  (making a frame...)" : "");
    ImGui::BeginDisabled(f.busy() || !f.grid());
    out.exportFrame = ImGui::Button("Export this frame");
    ImGui::EndDisabled();
    ImGui::SameLine();
    ImGui::TextDisabled("to the file in the panel (.vdb or a mesh)");
    ImGui::SameLine();
    out.closeFilm = ImGui::Button("Close (V)");
    ImGui::End();
}

void jobPanel(DocumentJob& job) {
    const ImVec2 size = ImGui::GetIO().DisplaySize;
    ImGui::SetNextWindowPos(ImVec2(size.x * 0.5f, size.y * 0.5f), ImGuiCond_Always,
                            ImVec2(0.5f, 0.5f));
    ImGui::Begin("Working", nullptr,
                 ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoCollapse);
    ImGui::Text("%s", job.what().c_str());
    char label[64];
    std::snprintf(label, sizeof label, "segment %zu / %zu", job.done(), job.total());
    ImGui::ProgressBar(job.fraction(), ImVec2(320, 0), label);
    if (ImGui::Button("Cancel (Esc)")) job.cancel();
    ImGui::End();
}

void dialogs(PanelState& ui, bool working, PanelRequests& out) {
    if (!ui.error.empty()) ImGui::OpenPopup("Error");
    if (modal("Error",
              [&] {
                  ImGui::TextWrapped("%s", ui.error.c_str());
                  ImGui::Text("The document was not changed.");
              },
              {"OK"}) == 0)
        ui.error.clear();
    if (ui.askQuit) ImGui::OpenPopup("Unsaved changes");
    const int quit =
        modal("Unsaved changes", [&] { ImGui::Text("Save before quitting? (file: %s)", ui.path); },
              {"Save and quit", "Discard", "Cancel"});
    if (quit >= 0) ui.askQuit = false;
    out.saveAndQuit = quit == 0;
    out.discardAndQuit = quit == 1;
    if (!ui.offerRecovery.empty() && !working) ImGui::OpenPopup("Recover");
    const int recover = modal("Recover",
                              [&] {
                                  ImGui::TextWrapped("%s", ui.offerText.c_str());
                                  ImGui::TextDisabled("%s", ui.offerRecovery.c_str());
                              },
                              {"Recover", "Discard it", "Ask again next time"});
    out.recover = recover == 0;
    out.discardSession = recover == 1;
    if (recover == 2) ui.offerRecovery.clear(); // asked again next time
    if (!ui.confirmText.empty()) ImGui::OpenPopup("Confirm");
    const int answer =
        modal("Confirm", [&] { ImGui::Text("%s", ui.confirmText.c_str()); }, {"Yes", "Cancel"});
    if (answer == 0) out.confirmed = std::move(ui.confirmAction);
    if (answer >= 0) ui.confirmText.clear();
}

} // namespace sweepers
