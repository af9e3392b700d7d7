// SPDX-License-Identifier: Apache-2.0
// Animated modeling (sculpt/film.h): the film's timing, frames that show each stroke
// happening, and the ends of the film against the start and against `apply`.
#include <cmath>
#include <map>
#include <stdexcept>

#include <gtest/gtest.h>
#include <openvdb/tools/Interpolation.h>

#include "deform/step_prefix.h"
#include "grids.h"
#include "io/film_files.h"
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
    return loadStrokeScript(kScript, "film.json");
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
        const double volume = levelSetVolume(*frames.at(n));
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

TEST(Film, APlayerSeeksOnFromAnyFrame) {
    // A timeline's play head: frame after frame, or jumping on, each frame is the whole
    // film's, the partial segment of one frame taken back before the next.
    const StrokeScript s = script();
    FilmTiming timing;
    timing.fps = 12.0;
    const auto all = play(s, timing);
    Sculptor sculptor = startOf(s);
    FilmPlayer player(sculptor, s, timing);
    EXPECT_EQ(player.frameCount(), 10u);
    EXPECT_EQ(player.frame(), 0u);
    for (std::size_t n : {2, 3, 5, 9, 10}) {
        player.seek(n);
        EXPECT_EQ(player.frame(), n);
        EXPECT_EQ(test::differingVoxels(sculptor.grid(), *all.at(n)), 0u) << "frame " << n;
    }
    EXPECT_THROW(player.seek(4), std::invalid_argument);  // back: a new player
    EXPECT_THROW(player.seek(11), std::invalid_argument); // past the end
    EXPECT_EQ(test::differingVoxels(sculptor.grid(), *all.at(10)), 0u);
}

TEST(Film, APrefixIsTheFirstSubSteps) {
    const StrokeScript s = script();
    const auto parts = planStroke(startOf(s).grid(), s.strokes[0]);
    const StepDeformation& whole = *parts[0].deformation;
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
    const StrokeScript again = loadStrokeScript(formatStrokeScript(s), "again.json");
    ASSERT_EQ(again.durations.size(), 1u);
    EXPECT_DOUBLE_EQ(again.durations[0], 0.5);
    std::string bad = kScript;
    bad.replace(bad.find("\"duration\": 0.5") + 12, 3, "-1");
    try {
        loadStrokeScript(bad, "bad.json");
        FAIL() << "a negative duration was taken";
    } catch (const ScriptError& e) {
        EXPECT_STREQ(e.what(), "bad.json: /strokes/0/duration: must be positive (got -1)");
    }
}

namespace {

// A grab: the ball at rest on the sphere's side, pulled out along a curve and back (3.6.1,
// Figure 3.23), a second long.
const char* kGrab = R"({
  "sweepers": 1,
  "grid": { "voxel_size": 0.03125, "half_width": 3 },
  "start": { "sphere": { "center": [0, 0, 0], "radius": 0.5 } },
  "strokes": [
    { "type": "keyframed",
      "tool": { "shape": "ball", "size": 0.2, "falloff": 0.3 },
      "keys": [ { "time": 0, "t": [0.45, 0, 0] }, { "time": 0.4, "t": [0.65, 0.1, 0] },
                { "time": 0.6, "t": [0.65, -0.1, 0] }, { "time": 1, "t": [0.45, 0, 0] } ] }
  ]
})";

// A bump pushed out of the top of a big sphere (nearly flat there) in the frame, which
// slides along x (3.6.1, Figure 3.25), a second long.
const char* kSlide = R"({
  "sweepers": 1,
  "grid": { "voxel_size": 0.03125, "half_width": 3 },
  "start": { "sphere": { "center": [0, -1.5, 0], "radius": 2 } },
  "strokes": [
    { "type": "slide",
      "tools": [ { "shape": "ball", "size": 0.15, "falloff": 0.2,
                   "path": [ { "t": [0, 0.45, 0] }, { "t": [0, 0.6, 0] } ] } ],
      "keys": [ { "time": 0, "t": [-0.25, 0, 0] }, { "time": 1, "t": [0.25, 0, 0] } ] }
  ]
})";

// Where the surface crosses the vertical line at x (z = 0), from above.
double heightAt(const Grid& g, double x) {
    const auto acc = g.getConstAccessor();
    const openvdb::tools::GridSampler<Grid::ConstAccessor, openvdb::tools::BoxSampler> s(
        acc, g.transform());
    const double h = g.voxelSize()[0];
    for (double y = 1.0; y > 0.0; y -= h / 4)
        if (s.wsSample(openvdb::Vec3d(x, y, 0.0)) <= 0.0) return y;
    return 0.0;
}

// The x of the centre of the bump the surface has over `base` (at z = 0): the mean of x
// weighted by the height the bump adds.
double bumpAt(const Grid& g, const Grid& base) {
    const double h = g.voxelSize()[0];
    double sum = 0.0, moment = 0.0;
    for (double x = -0.7; x <= 0.7; x += h / 2) {
        const double rise = heightAt(g, x) - heightAt(base, x);
        sum += rise;
        moment += rise * x;
    }
    return moment / sum;
}

} // namespace

TEST(Keyframes, ThroughEveryKeyAndHeldAtTheEnds) {
    Keyframes k;
    k.times = {0.0, 0.5, 2.0};
    Placement a, b, c;
    b.t = {1, 0, 0};
    b.axis = {0, 0, 1};
    b.angleDegrees = 40.0;
    c.t = {1, 1, 0};
    c.scale = Eigen::Vector3d::Constant(2.0);
    k.placements = {a, b, c};
    for (std::size_t i = 0; i < 3; ++i)
        EXPECT_TRUE(
            keyedPlacement(k, k.times[i]).matrix().isApprox(k.placements[i].matrix(), 1e-12));
    EXPECT_TRUE(keyedPlacement(k, 5.0).matrix().isApprox(c.matrix(), 1e-12));
    // Between keys: smooth, not a straight line (the middle key's tangent bends it).
    const Placement mid = keyedPlacement(k, 1.25);
    EXPECT_GT(mid.t.y(), 0.0);
    EXPECT_LT(mid.t.y(), 1.0);
    EXPECT_GT(mid.scale.x(), 1.0);
    k.times = {0.0, 0.5, 0.5};
    EXPECT_THROW(checkKeyframes(k), std::invalid_argument);
}

TEST(Film, AKeyframedGrabThatComesBackGivesBackTheStart) {
    const StrokeScript s = loadStrokeScript(kGrab, "grab.json");
    FilmTiming timing;
    timing.fps = 10.0; // 11 frames
    const auto frames = play(s, timing);
    ASSERT_EQ(frames.size(), 11u);
    Sculptor start = startOf(s);
    const double rest = levelSetVolume(start.grid());
    // Out along the curve, and back: the middle frames are pulled, the last is the start.
    EXPECT_GT(levelSetVolume(*frames.at(5)), rest + 1e-3);
    // At 0.4 s the ball is up at (0.65, 0.1): the grabbed clay reaches x = 0.6 above the
    // equator, which the sphere (radius 0.5) does not.
    EXPECT_EQ(heightAt(start.grid(), 0.6), 0.0);
    EXPECT_GT(heightAt(*frames.at(5), 0.6), 0.0);
    EXPECT_EQ(test::differingVoxels(*frames.at(11), start.grid()), 0u);
    // Every frame from the start shape: frame 7 alone is frame 7 of the whole film.
    const auto alone = play(s, timing, 7, 7);
    EXPECT_EQ(test::differingVoxels(*alone.at(7), *frames.at(7)), 0u);
    // apply takes the stroke at its last key: the start again.
    applyStrokes(start, s.strokes);
    EXPECT_EQ(test::differingVoxels(*frames.at(11), start.grid()), 0u);
}

TEST(Film, ASlidingBumpFollowsItsFrame) {
    const StrokeScript s = loadStrokeScript(kSlide, "slide.json");
    FilmTiming timing;
    timing.fps = 4.0; // frames at 0, 0.25, 0.5, 0.75, 1 s
    const auto frames = play(s, timing);
    ASSERT_EQ(frames.size(), 5u);
    const double h = s.grid.voxelSize;
    const Sculptor start = startOf(s);
    for (std::size_t n = 1; n <= 5; ++n) {
        const double frameX = -0.25 + 0.5 * double(n - 1) / 4.0;
        EXPECT_NEAR(bumpAt(*frames.at(n), start.grid()), frameX, h) << "frame " << n;
        EXPECT_GT(heightAt(*frames.at(n), frameX), 0.5 + 3 * h) << "frame " << n;
    }
    Sculptor applied = startOf(s);
    applyStrokes(applied, s.strokes);
    EXPECT_EQ(test::differingVoxels(*frames.at(5), applied.grid()), 0u);
}

TEST(Film, KeyedStrokesRoundTripAndBadKeysAreRefused) {
    for (const char* text : {kGrab, kSlide}) {
        const StrokeScript s = loadStrokeScript(text, "keyed.json");
        const std::string once = formatStrokeScript(s);
        EXPECT_EQ(formatStrokeScript(loadStrokeScript(once, "again.json")), once);
    }
    const auto refusal = [](std::string text, const std::string& from, const std::string& to) {
        text.replace(text.find(from), from.size(), to);
        try {
            loadStrokeScript(text, "bad.json");
        } catch (const ScriptError& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    EXPECT_EQ(refusal(kGrab, "\"time\": 0.6", "\"time\": 0.3"),
              "bad.json: /strokes/0/keys/2/time: keys must come in increasing time (this one is "
              "at 0.3, the one before at 0.4)");
    EXPECT_EQ(refusal(kGrab, "\"time\": 0, \"t\"", "\"time\": 0.1, \"t\""),
              "bad.json: /strokes/0/keys/0/time: the first key is at time 0");
    EXPECT_EQ(
        refusal(kGrab, "\"type\": \"keyframed\",", "\"type\": \"keyframed\", \"duration\": 2,"),
        "bad.json: /strokes/0/duration: a keyframed stroke lasts until its last key");
    EXPECT_EQ(refusal(kSlide, "\"time\": 1, \"t\": [0.25, 0, 0]",
                      "\"time\": 1, \"t\": [0.25, 0, 0], \"s\": [1, 2, 1]"),
              "bad.json: /strokes/0/keys/1/s: a slide's frame can only be scaled uniformly");
}

TEST(Film, AnEditedKeyChangesOnlyTheFramesItShapes) {
    // Six keys a fifth of a second apart; key 1 moved: the spline changes between key 0 and
    // key 3 (0 to 0.6 s) and passes through the other keys still, so at 10 fps frames 2, 3,
    // 4 and 6 change (0.1, 0.2, 0.3 and 0.5 s) and the others do not (5 and 7 at keys 2 and 3).
    std::string text = kGrab;
    const std::string keys =
        R"("keys": [ { "time": 0, "t": [0.45, 0, 0] }, { "time": 0.4, "t": [0.65, 0.1, 0] },
                { "time": 0.6, "t": [0.65, -0.1, 0] }, { "time": 1, "t": [0.45, 0, 0] } ])";
    const std::string six =
        R"("keys": [ { "time": 0, "t": [0.45, 0, 0] }, { "time": 0.2, "t": [0.6, 0.1, 0] },
                { "time": 0.4, "t": [0.65, 0.1, 0] }, { "time": 0.6, "t": [0.65, -0.1, 0] },
                { "time": 0.8, "t": [0.6, -0.1, 0] }, { "time": 1, "t": [0.45, 0, 0] } ])";
    ASSERT_NE(text.find(keys), std::string::npos);
    text.replace(text.find(keys), keys.size(), six);
    std::string edited = text;
    const std::string key1 = R"({ "time": 0.2, "t": [0.6, 0.1, 0] })";
    edited.replace(edited.find(key1), key1.size(), R"({ "time": 0.2, "t": [0.6, 0.2, 0] })");
    FilmTiming timing;
    timing.fps = 10.0;
    const auto before = play(loadStrokeScript(text, "six.json"), timing);
    const auto after = play(loadStrokeScript(edited, "edited.json"), timing);
    ASSERT_EQ(before.size(), 11u);
    ASSERT_EQ(after.size(), 11u);
    for (std::size_t n : {2, 3, 4, 6})
        EXPECT_GT(test::differingVoxels(*before.at(n), *after.at(n)), 0u) << "frame " << n;
    for (std::size_t n : {1, 5, 7, 8, 9, 10, 11})
        EXPECT_EQ(test::differingVoxels(*before.at(n), *after.at(n)), 0u) << "frame " << n;
    // What the frames are made of, as `animate` stamps them: key 1 reaches frames 2 to 6
    // (0.1 to 0.5 s: the spline pieces from key 0 to key 3), so every frame that changed
    // has another digest, and the frames from key 3 on keep theirs.
    const auto was = frameDigests(text, loadStrokeScript(text, "six.json"), timing);
    const auto is = frameDigests(edited, loadStrokeScript(edited, "edited.json"), timing);
    ASSERT_EQ(was.size(), 12u);
    ASSERT_EQ(is.size(), 12u);
    for (std::size_t n = 1; n <= 11; ++n) {
        const bool reached = n >= 2 && n <= 6;
        EXPECT_EQ(was[n] != is[n], reached) << "frame " << n;
        if (test::differingVoxels(*before.at(n), *after.at(n)) > 0) {
            EXPECT_NE(was[n], is[n]) << "frame " << n;
        }
    }
    // Another fog grid in the files, another digest.
    EXPECT_NE(frameDigests(text, loadStrokeScript(text, "six.json"), timing, "density")[7], was[7]);
}
