// SPDX-License-Identifier: Apache-2.0
#include "sculpt/sculptor.h"

#include "vdb/parallel.h"

#include "core/stopwatch.h"

namespace sweepers {

Sculptor::Sculptor(GridPtr grid, AdvectOptions options)
    : grid_(std::move(grid)), options_(options) {}

void Sculptor::replaceGrid(GridPtr grid) {
    grid_ = std::move(grid);
    record_ = LeafSnapshot();
    if (meshing_) mesher_.rebuild(*grid_, options_.interrupter);
}

void Sculptor::setInterrupter(Interrupter* interrupter) {
    options_.interrupter = interrupter;
}

void Sculptor::startMeshing() {
    mesher_.rebuild(*grid_, options_.interrupter);
    meshing_ = true;
}

void Sculptor::startRecording() {
    record_ = LeafSnapshot();
    recording_ = true;
}

LeafSnapshot Sculptor::stopRecording() {
    recording_ = false;
    return std::exchange(record_, LeafSnapshot());
}

void Sculptor::restoreRecording() {
    record_.restore(*grid_);
    if (meshing_) mesher_.update(*grid_, record_.bounds());
    record_ = LeafSnapshot();
}

SegmentReport Sculptor::applySegment(const StepDeformation& deformation) {
    if (recording_) record_.capture(*grid_, changedRegion(*grid_, deformation));
    SegmentReport r;
    const auto t0 = Clock::now();
    r.stats = advector_.run(*grid_, deformation, options_, meshing_ ? &changed_ : nullptr);
    r.seconds = secondsSince(t0);
    if (meshing_) {
        const SerialClock clock;
        r.remeshedLeaves = mesher_.update(*grid_, changed_);
        r.meshSeconds = clock.wallSeconds();
        r.meshSerialSeconds = clock.serialSeconds();
    }
    return r;
}

SegmentReport Sculptor::applySmoothDab(const SmoothBrush& brush) {
    CurvatureSmoother smoother(*grid_, brush, options_.interrupter, smoothOptions_);
    if (recording_) record_.capture(*grid_, smoother.reach());
    SegmentReport r;
    const SerialClock dab;
    const SmoothStats s = smoother.run();
    r.smooth = s;
    r.seconds = r.otherSeconds = dab.wallSeconds();
    r.otherSerialSeconds = dab.serialSeconds();
    if (meshing_) {
        const SerialClock clock;
        r.remeshedLeaves = mesher_.update(*grid_, s.changed);
        r.meshSeconds = clock.wallSeconds();
        r.meshSerialSeconds = clock.serialSeconds();
    }
    return r;
}

SegmentReport Sculptor::applyStroke(const Stroke& stroke,
                                    const std::function<void(const SegmentReport&)>& each) {
    SegmentReport last;
    for (PlannedStep& step : planStroke(*grid_, stroke)) {
        last = step.dab ? applySmoothDab(*step.dab) : applySegment(*step.deformation);
        last.segment = step.segment;
        last.step = std::move(step);
        if (each) each(last);
    }
    return last;
}

std::vector<SegmentReport> applyStrokes(Sculptor& sculptor, const std::vector<Stroke>& strokes,
                                        const Progress& progress,
                                        const std::function<void(std::size_t)>& after,
                                        History* history) {
    std::size_t total = 0, done = 0;
    for (const Stroke& s : strokes)
        total += segmentCount(s, sculptor.grid().voxelSize()[0]);
    std::vector<SegmentReport> reports;
    for (std::size_t i = 0; i < strokes.size(); ++i) {
        sculptor.applyStroke(strokes[i], [&](const SegmentReport& r) {
            reports.push_back(r);
            reports.back().stroke = i;
            if (history) history->push_back(r.step.deformation);
            reports.back().step.deformation.reset();
            if (sculptor.meshing()) reports.back().meshVolume = sculptor.mesher().enclosedVolume();
            if (progress) progress(++done, total);
        });
        if (after) after(i);
    }
    return reports;
}

} // namespace sweepers
