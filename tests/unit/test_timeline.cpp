// SPDX-License-Identifier: Apache-2.0
// app/timeline.h: the modeler's history played as a film, scrubbed, played and sent back.
#include <gtest/gtest.h>

#include "app/timeline.h"
#include "document/document.h"
#include "document_strokes.h"
#include "grids.h"
#include "io/start_grid.h"

using namespace sweepers;
using sweepers::test::differingVoxels;
using sweepers::test::drag;

TEST(Timeline, ScrubsPlaysAndGoesBackOverTheHistory) {
    Document doc(Document::sphereScript(1.0 / 32), ".");
    drag(doc, {0, 0, 1}, {0, 0, 0.4}, 4); // 4 segments of a quarter second: 25 frames
    FilmTiming timing;
    std::vector<GridPtr> film(1);
    Sculptor reference(makeStartGrid(doc.script(), "."));
    playFilm(reference, doc.script(), timing, 1, 1000,
             [&](std::size_t, double, const Grid& g) { film.push_back(g.deepCopy()); });
    ASSERT_EQ(film.size(), 26u);

    Timeline tl(doc, timing);
    EXPECT_EQ(tl.frameCount(), 25u);
    Clock::time_point now = Clock::now();
    // Every frame asked for is made (no time passes meanwhile).
    auto settle = [&] {
        tl.step(now);
        while (tl.busy() || tl.shown() != tl.wanted()) {
            tl.wait();
            tl.step(now);
        }
        EXPECT_TRUE(tl.takeMessage().empty());
    };
    auto same = [&](std::size_t n) {
        ASSERT_EQ(tl.shown(), n);
        ASSERT_NE(tl.grid(), nullptr);
        EXPECT_EQ(differingVoxels(*tl.grid(), *film[n]), 0u) << "frame " << n;
    };
    settle();
    same(1);
    EXPECT_TRUE(tl.takeMeshChanges().all);
    const double start = tl.mesher()->enclosedVolume();
    tl.scrubTo(13); // the middle of the drag: half of the horn
    settle();
    same(13);
    EXPECT_FALSE(tl.takeMeshChanges().all); // on from frame 1: only what changed
    const double middle = tl.mesher()->enclosedVolume(), end = doc.mesher().enclosedVolume();
    EXPECT_GT(middle, start + 0.1 * (end - start));
    EXPECT_LT(middle, end - 0.1 * (end - start));
    tl.scrubTo(5); // back: the film is played again from the start shape
    settle();
    same(5);
    EXPECT_TRUE(tl.takeMeshChanges().all);
    // Half a second of play at twice the speed is 24 frames on: the end, where play stops.
    tl.setSpeed(2.0);
    tl.play(now);
    now += std::chrono::milliseconds(250);
    settle();
    same(17);
    EXPECT_TRUE(tl.playing());
    now += std::chrono::milliseconds(250);
    settle();
    same(25);
    EXPECT_FALSE(tl.playing());
    EXPECT_EQ(differingVoxels(*tl.grid(), doc.grid()), 0u);
    tl.scrubTo(1000);
    EXPECT_EQ(tl.wanted(), 25u);
    tl.play(now); // from the end: from the start again
    EXPECT_EQ(tl.wanted(), 1u);
    tl.pause();
    // Asked back while a later frame is being made: that work stops, the frame asked for
    // comes from the start shape.
    settle();
    tl.scrubTo(25);
    tl.step(now);
    EXPECT_TRUE(tl.busy());
    tl.scrubTo(2);
    settle();
    same(2);
}
