// SPDX-License-Identifier: Apache-2.0
#define GL_GLEXT_PROTOTYPES
#include "app/harness.h"

#include <GL/gl.h>
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <ostream>
#include <stdexcept>

#include <stb_image_write.h>

#include "core/statistics.h"
#include "io/atomic_file.h"

namespace sweepers {

ModelerHarness::ModelerHarness(const ModelerOptions& o)
    : opt_(o), batch_(!o.replayInput.empty() || !o.screenshot.empty() || !o.recordFrames.empty()),
      replay_(o.replay.events) {}

void ModelerHarness::deliver(Modeler& m) {
    replay_.deliver(m.controller(), [&m](const InputEvent& e) { m.dispatch(e); });
}

void ModelerHarness::afterDraw(Modeler& m, bool working) {
    if (batch_ && m.settled() && replay_.over()) batchStep(m);
    if (!working) replay_.endFrame(m.controller());
}

void ModelerHarness::batchStep(Modeler& m) {
    if (!opt_.recordFrames.empty() && recordNext_ == 0) {
        Timeline* film = m.openFilm();
        if (!film) throw std::runtime_error("--record-frames: the film cannot be opened");
        recordNext_ = 1;
        film->scrubTo(1);
        return;
    }
    if (recordNext_ != 0) {
        Timeline& film = *m.openFilm(); // open since the recording began
        const std::size_t count = film.frameCount();
        if (recordNext_ <= count) {
            const int digits = std::max(4, int(std::to_string(count).size()));
            char name[32];
            std::snprintf(name, sizeof name, "frame_%0*zu.png", digits, recordNext_);
            screenshot(m.window(), (std::filesystem::path(opt_.recordFrames) / name).string());
            if (++recordNext_ <= count) {
                film.scrubTo(recordNext_);
                return;
            }
            std::fprintf(stderr, "sweepers: wrote %zu frames to %s\n", count,
                         opt_.recordFrames.c_str());
        }
    }
    if (!opt_.screenshot.empty()) screenshot(m.window(), opt_.screenshot);
    glfwSetWindowShouldClose(m.window(), GLFW_TRUE);
}

void ModelerHarness::afterSwap(Modeler& m, Clock::time_point frameStart,
                               Clock::time_point drawStart, bool idle) {
    Figures& f = m.figures();
    if (measuring_) {
        // Latency of the segment: from its drag event to the new mesh on screen.
        glFinish();
        const auto now = Clock::now();
        const SegmentReport& r = measuring_->report;
        latencies_.push_back({1e3 * r.advectSeconds(), 1e3 * r.stats.renormalizeSeconds,
                              1e3 * r.meshSeconds, f.uploadMs, 1e3 * secondsSince(drawStart, now),
                              1e3 * secondsSince(measuring_->since, now),
                              double(f.uploadedBricks)});
        measuring_.reset();
    }
    f.frameMs = 1e3 * secondsSince(frameStart);
    if (idle) idleFrames_.push_back(f.frameMs);
}

void ModelerHarness::finish(Modeler& m) const {
    if (opt_.latencyReport) reportLatency(m);
    if (!opt_.latencyCsv.empty()) writeLatencyCsv(opt_.latencyCsv);
    if (!opt_.saveVdb.empty()) m.document().saveVdb(opt_.saveVdb, m.savedPrecision());
    if (!opt_.saveScript.empty()) m.document().saveScript(opt_.saveScript);
    if (!opt_.saveFrame.empty()) {
        try {
            m.saveFrame(opt_.saveFrame);
        } catch (const std::runtime_error& e) {
            throw std::runtime_error(std::string("--save-frame: ") + e.what());
        }
    }
}

void ModelerHarness::reportLatency(const Modeler& m) const {
    static const char* names[] = {"advect", "renorm", "mesh", "upload", "draw", "total"};
    if (latencies_.empty()) {
        // Zeros would read as a measurement.
        std::fprintf(stderr, "latency: nothing was sculpted, so there is nothing to report "
                             "(did the drags reach the shape?)\n");
    } else {
        std::fprintf(stderr, "latency over %zu segments at voxel size %g (ms, p50 / p95):",
                     latencies_.size(), m.document().grid().voxelSize()[0]);
        for (int k = 0; k < 6; ++k) {
            std::vector<double> v;
            for (const auto& l : latencies_)
                v.push_back(l[k]);
            std::fprintf(stderr, " %s %.1f / %.1f%s", names[k], percentile(v, 0.5),
                         percentile(v, 0.95), k < 5 ? "," : "\n");
        }
    }
    if (!idleFrames_.empty())
        std::fprintf(stderr, "frame time when not sculpting (ms, p50 over %zu frames): %.1f\n",
                     idleFrames_.size(), percentile(idleFrames_, 0.5));
}

void ModelerHarness::writeLatencyCsv(const std::string& path) const {
    std::string text = "advect,renorm,mesh,upload,draw,total,bricks\n";
    char row[256];
    for (const auto& l : latencies_) {
        std::snprintf(row, sizeof row, "%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.0f\n", l[0], l[1], l[2],
                      l[3], l[4], l[5], l[6]);
        text += row;
    }
    writeTextAtomically(path, text);
}

void screenshot(GLFWwindow* window, const std::string& path) {
    int fw, fh;
    glfwGetFramebufferSize(window, &fw, &fh);
    std::vector<unsigned char> px(std::size_t(fw) * fh * 3);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadBuffer(GL_BACK);
    glReadPixels(0, 0, fw, fh, GL_RGB, GL_UNSIGNED_BYTE, px.data());
    stbi_flip_vertically_on_write(1);
    // Encoded into the checked atomic save, like every other file we write.
    writeFileAtomically(path, [&](std::ostream& out) {
        const auto put = [](void* stream, void* data, int size) {
            static_cast<std::ostream*>(stream)->write(static_cast<const char*>(data), size);
        };
        if (!stbi_write_png_to_func(put, &out, fw, fh, 3, px.data(), fw * 3))
            throw std::runtime_error(path + ": cannot encode the screenshot");
    });
}

} // namespace sweepers
