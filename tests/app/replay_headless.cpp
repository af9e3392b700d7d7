// SPDX-License-Identifier: Apache-2.0
// Replays a modeler input file through the sculpt controller with no window, as
// `sweepers --size WxH --replay-input EVENTS --save-script OUT` does with one, and writes
// the recorded stroke script (the test compares the two, byte for byte).
//
//   replay_headless EVENTS WIDTH HEIGHT VOXEL_SIZE OUT.json
#include <cstdio>
#include <cstdlib>
#include <exception>

#include "app/sculpt_controller.h"
#include "document/document.h"

int main(int argc, char** argv) {
    using namespace sweepers;
    if (argc != 6) {
        std::fprintf(stderr, "usage: replay_headless EVENTS WIDTH HEIGHT VOXEL_SIZE OUT.json\n");
        return 2;
    }
    try {
        Document doc(Document::sphereScript(std::atof(argv[4])), ".");
        SculptController controller(/*waitEachPiece=*/true);
        controller.setViewport(std::atoi(argv[2]), std::atoi(argv[3]));
        controller.setDocument(&doc);
        controller.frameView();
        replayEvents(controller, readInputReplay(argv[1]).events);
        doc.endEdit();
        doc.saveScript(argv[5]);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "replay_headless: %s\n", e.what());
        return 1;
    }
    return 0;
}
