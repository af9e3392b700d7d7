// SPDX-License-Identifier: Apache-2.0
// The modeler's panels (Dear ImGui), as functions over the state they show. They change only
// the tool settings and the look they show; what a click asks of the document (open, save,
// undo, resample, a dialog's answer) comes back as PanelRequests, which the window carries
// out after the frame.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <set>
#include <string>

#include "app/gl_renderer.h"
#include "app/job.h"
#include "app/sculpt_controller.h"
#include "app/timeline.h"
#include "document/document.h"

namespace sweepers {

// What the Statistics section shows: the document's figures (taken when they change: counting
// the active voxels walks the whole tree) and the last frame's and segment's.
struct Figures {
    double voxelSize = 0;
    std::size_t activeVoxels = 0, triangles = 0, undoCount = 0, undoBytes = 0, gridBytes = 0;
    double frameMs = 0, uploadMs = 0; // the last frame, and its uploads of the mesh
    std::size_t uploadedBricks = 0;   // ... in bricks
    SegmentReport lastSegment;
    double filmVolume = 0; // of the frame the film shows
};

// What the panels show and edit besides the document and the tool: the file and voxel size
// fields, the messages, the questions waiting for an answer, the labels cut off.
struct PanelState {
    char path[1024] = {};
    float voxelSizeInput = 1.0f / 64;
    bool saveHalf = false;     // Save writes a .vdb's values as 16-bit floats
    std::string status, error; // a line under the panel; a dialog
    // A question (Yes runs the action), the question before quitting with unsaved changes,
    // and an interrupted session the user has not decided about (and what the offer says).
    std::string confirmText;
    std::function<void()> confirmAction;
    bool askQuit = false;
    std::string offerRecovery, offerText;
    std::set<std::string> clipped; // panel items cut off at the window's width
    Figures figures;
};

// What a frame's clicks ask of the window.
struct PanelRequests {
    bool open = false, toolFromFile = false, save = false, newSphere = false;
    bool undo = false, redo = false, openFilm = false, closeFilm = false, exportFrame = false;
    int filmKey = 0; // a timeline button, as its key (GLFW's code)
    std::optional<double> resample;
    bool saveAndQuit = false, discardAndQuit = false;
    bool recover = false, discardSession = false; // the offered session (ui.offerRecovery)
    std::function<void()> confirmed;              // the confirmed question's action
};

// The tool, the document's buttons, detail and statistics. `locked`: nothing may change the
// document (a sculpting piece runs, or the film is open).
void mainPanel(PanelState& ui, SculptController& ctl, GlRenderer& renderer, const Document& doc,
               bool locked, PanelRequests& out);
// The timeline under the picture (its slider and speed scrub the film itself).
void filmPanel(PanelState& ui, Timeline& film, PanelRequests& out);
// A long job's progress, with its Cancel button.
void jobPanel(DocumentJob& job);
// The dialogs: an error, unsaved changes at quitting, a session to recover (offered when no
// job is `working`), a question.
void dialogs(PanelState& ui, bool working, PanelRequests& out);

} // namespace sweepers
