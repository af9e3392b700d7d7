// Animated modeling (sculpt/film.h): the film's timing, frames that show each stroke
// happening, and the ends of the film against the start and against `apply`.
#include <cmath>
#include <map>
#include <stdexcept>

#include <gtest/gtest.h>

#include "deform/step_prefix.h"
#include "grids.h"
#include "io/stroke_script.h"
#include "levelset/measure.h"
#include "sculpt/film.h"

using namespace sweepers;

namespace {

// A ball pulls a horn out of a small sphere in two path segments (half a second in all), then
// a dab of clay (no duration: one segment's worth).
const char* kScript = R"({
  "sweepers": 1,
  "grid": { "voxel_size": 0.03125, "half_width": 3 },
  "start": { "sphere": { "center": [0, 0, 0], "radius": 0.5 } },
  "strokes": [
    { "type": "sweep", "duration": 0.5,
      "tools": [ { "shape": "ball", "size": 0.2, "falloff": 0.3,
                   "path": [ { "t": [0, 0.45, 0] }, { "t": [0, 0.65, 0] }, { "t": [0, 0.85, 0] } ] } ] },
    { "type": "inflate", "at": [0.5, 0, 0], "radius": 0.12 }
  ]
})";

StrokeScript script() {
    return parseStrokeScript(kScript, "film.json");
}

Sculptor startOf(const StrokeScript& s) {
    return Sculptor(makeSphere(s.start.center, s.start.radius, s.grid.voxelSize, s.grid.halfWidth));
}

// Every frame of the film (or those wanted), as copies.
std::map<std::size_t, GridPtr> play(const StrokeScript& s, const FilmTiming& timing,
                                    std::size_t first = 1, std::size_t last = 1000,
                                    const std::function<bool(std::size_t)>& wanted = {}) {
    Sculptor sculptor = startOf(s);
    std::map<std::size_t, GridPtr> frames;
    playFilm(
        sculptor, s, timing, first, last,
        [&](std::size_t n, double, const Grid& g) {
            EXPECT_EQ(frames.count(n), 0u) << "frame " << n << " shown twice";
            frames[n] = g.deepCopy();
        },
        wanted);
    return frames;
}

} // namespace

TEST(Film, StrokesLastTheirDurationOrTheirSegments) {
    FilmTiming timing;
    timing.secondsPerSegment = 0.2;
    const std::vector<double> d = strokeDurations(script(), timing);
    ASSERT_EQ(d.size(), 2u);
    EXPECT_DOUBLE_EQ(d[0], 0.5); // given
    EXPECT_DOUBLE_EQ(d[1], 0.2); // one segment's worth
    // seconds x fps frames after the start, the last one at the end.
    EXPECT_EQ(filmFrameCount(2.0, 24.0), 49u);
    EXPECT_EQ(filmFrameCount(0.7, 24.0), 18u); // 16.8 frames: the 18th shows the end
    EXPECT_DOUBLE_EQ(filmFrameTime(18, 0.7, 24.0), 0.7);
    EXPECT_DOUBLE_EQ(filmFrameTime(13, 0.7, 24.0), 0.5);
    timing.fps = 0.0;
    EXPECT_THROW(strokeDurations(script(), timing), std::invalid_argument);
}

TEST(Film, RunsFromTheStartToWhatApplyGives) {
    const StrokeScript s = script();
    FilmTiming timing;
    timing.fps = 12.0; // 0.75 s: 10 frames
    const auto frames = play(s, timing);
    ASSERT_EQ(frames.size(), 10u);
    EXPECT_EQ(frames.begin()->first, 1u);
    Sculptor start = startOf(s);
    EXPECT_EQ(test::differingVoxels(*frames.at(1), start.grid()), 0u);
    applyStrokes(start, s.strokes);
    EXPECT_EQ(test::differingVoxels(*frames.at(10), start.grid()), 0u);
    // The horn grows frame by frame while the ball pulls (frames 1 to 7 span its 0.5 s),
    // including the frames inside a segment (2, 3 and 5, 6: the ball part of the way).
    double before = 0.0;
    for (std::size_t n = 1; n <= 7; ++n) {
        const double volume = measureLevelSet(*frames.at(n)).volume;
        EXPECT_GT(volume, before + 1e-4) << "frame " << n;
        before = volume;
    }
}

TEST(Film, AFrameIsTheSameWhicheverFramesAreWritten) {
    // Frames computed alone (the others skipped, or a range) are those of the whole film: a
    // frame inside a segment is taken back exactly before the segment is applied whole.
    const StrokeScript s = script();
    FilmTiming timing;
    timing.fps = 12.0;
    const auto all = play(s, timing);
    const auto some = play(s, timing, 1, 1000, [](std::size_t n) { return n == 3 || n == 9; });
    ASSERT_EQ(some.size(), 2u);
    EXPECT_EQ(test::differingVoxels(*some.at(3), *all.at(3)), 0u);
    EXPECT_EQ(test::differingVoxels(*some.at(9), *all.at(9)), 0u);
    const auto range = play(s, timing, 5, 6);
    ASSERT_EQ(range.size(), 2u);
    EXPECT_EQ(test::differingVoxels(*range.at(5), *all.at(5)), 0u);
    EXPECT_EQ(test::differingVoxels(*range.at(6), *all.at(6)), 0u);
    EXPECT_GT(test::differingVoxels(*all.at(5), *all.at(6)), 0u);
}

TEST(Film, APrefixIsTheFirstSubSteps) {
    const StrokeScript s = script();
    const auto parts = planStroke(startOf(s).grid(), s.strokes[0]);
    const StepDeformation& whole = *parts[0];
    ASSERT_GE(whole.steps(), 2);
    const StepPrefix half(whole, whole.steps() / 2);
    EXPECT_EQ(half.steps(), whole.steps() / 2);
    const Eigen::Vector3d p(0.05, 0.6, 0.0);
    Eigen::Vector3d q = p;
    for (int k = half.steps() - 1; k >= 0; --k)
        q = whole.inverseStep(k, q);
    EXPECT_LT((half.inverseMap(p) - q).norm(), 1e-12);
    // Part of the way: the point comes from nearer than under the whole segment.
    EXPECT_GT((half.inverseMap(p) - whole.inverseMap(p)).norm(), 1e-3);
    EXPECT_THROW(StepPrefix(whole, 0), std::invalid_argument);
    EXPECT_THROW(StepPrefix(whole, whole.steps()), std::invalid_argument);
}

TEST(Film, PlacementsPartOfTheWay) {
    Placement a, b;
    a.t = {0, 1, 0};
    b.t = {0, 2, 0};
    b.axis = {1, 0, 0};
    b.angleDegrees = 60.0;
    b.scale = Eigen::Vector3d::Constant(2.0);
    for (const double f : {0.0, 1.0}) {
        const std::optional<Placement> p = placementAlong(a, b, f);
        ASSERT_TRUE(p);
        EXPECT_TRUE(p->matrix().isApprox((f == 0.0 ? a : b).matrix(), 1e-9)) << f;
    }
    const std::optional<Placement> half = placementAlong(a, b, 0.5);
    ASSERT_TRUE(half);
    EXPECT_NEAR(half->angleDegrees, 30.0, 1e-9);
    EXPECT_NEAR(half->scale.x(), std::sqrt(2.0), 1e-9);
    // Half a motion, twice: the whole motion.
    const Eigen::Matrix4d step = half->matrix().matrix() * a.matrix().matrix().inverse();
    EXPECT_TRUE((step * step * a.matrix().matrix()).isApprox(b.matrix().matrix(), 1e-9));
    // A tool turned by 45 degrees, then stretched along the world's x: not T R S part way.
    Placement turned;
    turned.angleDegrees = 45.0;
    Placement stretched = turned;
    stretched.scale = {2.0, 1.0, 1.0};
    EXPECT_TRUE(placementAlong(turned, stretched, 0.5)); // along its own axes: fine
    Placement skewed;
    skewed.t = {0, 0, 0};
    skewed.scale = {2.0, 1.0, 1.0};
    EXPECT_FALSE(placementAlong(turned, Placement(skewed), 0.5)) << "a skewed placement";
}

TEST(Film, DurationsRoundTripAndANegativeOneIsRefused) {
    const StrokeScript s = script();
    const StrokeScript again = parseStrokeScript(formatStrokeScript(s), "again.json");
    ASSERT_EQ(again.durations.size(), 1u);
    EXPECT_DOUBLE_EQ(again.durations[0], 0.5);
    std::string bad = kScript;
    bad.replace(bad.find("\"duration\": 0.5") + 12, 3, "-1");
    try {
        parseStrokeScript(bad, "bad.json");
        FAIL() << "a negative duration was taken";
    } catch (const ScriptError& e) {
        EXPECT_STREQ(e.what(), "bad.json: /strokes/0/duration: must be positive (got -1)");
    }
}
