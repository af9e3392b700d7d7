// SPDX-License-Identifier: Apache-2.0
// io/study_plan.h: a run's digest says what its result depends on, so a result on disk is
// reused exactly when nothing it was made from changed.
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include <gtest/gtest.h>

#include "io/study_files.h"
#include "io/study_plan.h"
#include "scratch_dir.h"

using namespace sweepers;

namespace {

const char* const kMeshScript = R"({"sweepers": 1, "grid": {"voxel_size": 0.0625},
 "start": {"mesh": "capsule.obj"},
 "strokes": [{"type": "sweep", "tools": [{"shape": "ball", "size": 0.3, "falloff": 0.3,
   "path": [{"t": [0.6, 0, 0]}, {"t": [0.9, 0, 0]}]}]}]})";

const char* const kSphereScript = R"({"sweepers": 1, "grid": {"voxel_size": 0.0625},
 "start": {"sphere": {"center": [0, 0, 0], "radius": 0.5}},
 "strokes": [{"type": "sweep", "tools": [{"shape": "ball", "size": 0.2, "falloff": 0.2,
   "path": [{"t": [0, 0.5, 0]}, {"t": [0, 0.7, 0]}]}]}]})";

void write(const std::string& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    out << text;
    ASSERT_TRUE(out.good()) << path;
}

struct Digests {
    std::map<std::string, std::string> scripts, runs; // by name, by id
};

Digests digestsOf(const StudyPlan& plan) {
    Digests d;
    for (const StudyScript& s : plan.scripts)
        d.scripts[s.name] = s.digest;
    for (const PlannedRun& r : plan.runs)
        d.runs[r.id] = r.digest;
    return d;
}

// The runs whose digests differ between the two plans, among those both hold.
std::size_t runsChanged(const Digests& a, const Digests& b) {
    std::size_t n = 0;
    for (const auto& [id, digest] : a.runs)
        if (const auto it = b.runs.find(id); it != b.runs.end()) n += it->second != digest;
    return n;
}

} // namespace

TEST(StudyPlan, DigestsChangeWhenAndOnlyWhenTheirInputsDo) {
    const test::ScratchDir dir;
    std::filesystem::copy_file(std::string(SWEEPERS_DATA_DIR) + "/animation/capsule.obj",
                               dir / "capsule.obj");
    write(dir / "mesh.json", kMeshScript);
    write(dir / "sphere.json", kSphereScript);
    const std::vector<std::string> scripts = {dir / "mesh.json", dir / "sphere.json"};
    const std::vector<StudyVariant> variants = {StudyVariant::Corrected, StudyVariant::Trilinear};
    const auto plan = [&](const std::vector<double>& sizes) {
        return digestsOf(planStudy(scripts, sizes, variants, dir / "study", false));
    };
    const std::vector<double> sizes = {1.0 / 16, 1.0 / 24};
    const Digests first = plan(sizes);
    ASSERT_EQ(first.runs.size(), 8u);
    // Every run its own digest.
    std::map<std::string, int> seen;
    for (const auto& [id, digest] : first.runs)
        EXPECT_EQ(++seen[digest], 1) << id;

    // Planned again, and with the files written again unchanged: the same digests.
    EXPECT_EQ(plan(sizes).runs, first.runs);
    write(dir / "mesh.json", kMeshScript);
    std::filesystem::last_write_time(dir / "capsule.obj",
                                     std::filesystem::file_time_type::clock::now());
    const Digests rewritten = plan(sizes);
    EXPECT_EQ(rewritten.scripts, first.scripts);
    EXPECT_EQ(rewritten.runs, first.runs);

    // The mesh the first script starts from, edited: its runs change, the other's do not.
    {
        std::ofstream out(dir / "capsule.obj", std::ios::app);
        out << "# edited\n";
    }
    const Digests meshEdited = plan(sizes);
    EXPECT_NE(meshEdited.scripts.at("mesh"), first.scripts.at("mesh"));
    EXPECT_EQ(meshEdited.scripts.at("sphere"), first.scripts.at("sphere"));
    EXPECT_EQ(runsChanged(first, meshEdited), 4u);

    // The second script's text edited: its runs change, the first's (as edited) do not.
    std::string text = kSphereScript;
    text.replace(text.find("0.7"), 3, "0.8");
    write(dir / "sphere.json", text);
    const Digests scriptEdited = plan(sizes);
    EXPECT_EQ(scriptEdited.scripts.at("mesh"), meshEdited.scripts.at("mesh"));
    EXPECT_NE(scriptEdited.scripts.at("sphere"), meshEdited.scripts.at("sphere"));
    EXPECT_EQ(runsChanged(meshEdited, scriptEdited), 4u);

    // Another voxel size: the runs at the size both plans hold keep their digests.
    const Digests resized = plan({1.0 / 16, 1.0 / 32});
    EXPECT_EQ(resized.runs.size(), 8u);
    EXPECT_EQ(runsChanged(scriptEdited, resized), 0u);
    std::size_t kept = 0;
    for (const auto& [id, digest] : resized.runs)
        kept += scriptEdited.runs.count(id);
    EXPECT_EQ(kept, 4u);
}

namespace {

// A finished run's result, as executeStudyRun writes it, with the figures given.
void finish(const StudyPlan& plan, const PlannedRun& run, double wall, double measure,
            double peakMb, std::size_t activeVoxels, double whole = 0.0) {
    StudyRow row;
    row.script = plan.scripts[run.script].name;
    row.variant = variantName(run.variant);
    row.voxelSize = run.voxelSize;
    row.wallSeconds = wall;
    row.measureSeconds = measure;
    row.runSeconds = whole;
    row.peakRssMb = peakMb;
    row.activeVoxels = activeVoxels;
    row.threads = 2;
    row.host = "here";
    const std::string dir = runDirectory(plan, run);
    std::filesystem::create_directories(dir);
    const nlohmann::json result = {{"format", "sweepers study result 1"},
                                   {"id", run.id},
                                   {"digest", run.digest},
                                   {"version", plan.version},
                                   {"row", studyRowJson(row, true)}};
    write(dir + "/result.json", result.dump());
}

} // namespace

TEST(StudyPlan, EstimatesFitSculptingMeasuringAndMemoryToTheTwoFinestRuns) {
    const test::ScratchDir dir;
    write(dir / "sphere.json", kSphereScript);
    StudyPlan plan = planStudy({dir / "sphere.json"}, {1.0 / 16, 1.0 / 32, 1.0 / 64, 1.0 / 128},
                               {StudyVariant::Corrected}, dir / "study", false);
    ASSERT_EQ(plan.runs.size(), 4u);
    const auto estimate = [&](std::size_t i) {
        estimateStudyRuns(plan, 2);
        return plan.runs[i];
    };
    // One run: time grows as 1/h^3 at most, sculpting and measuring alike (an upper bound).
    finish(plan, plan.runs[0], 1.0, 2.0, 70.0, 1000000);
    EXPECT_NEAR(estimate(2).seconds, 3.0 * 64, 1e-9);
    // Two: sculpting grew 8 times (1/h^3), measuring 4 times (1/h^2); each keeps its rate.
    finish(plan, plan.runs[1], 8.0, 8.0, 80.0, 4000000);
    EXPECT_NEAR(estimate(2).seconds, 8.0 * 8 + 8.0 * 4, 1e-9);
    EXPECT_NEAR(estimate(3).seconds, 8.0 * 64 + 8.0 * 16, 1e-9);
    EXPECT_EQ(estimate(3).basis, "measured run " + plan.runs[1].id);
    // Memory: while the program's own memory hides what a voxel costs (80 MB), at least
    // kRunBytesPerVoxel a voxel (the fit says 3.5 bytes).
    const double mb = double(1 << 20);
    EXPECT_NEAR(estimate(2).memoryMb, 80.0 + 12e6 * 160 / mb, 1e-6);
    // Once the grid holds a third of the run's memory, what a voxel cost between the two.
    // The rest of the whole run (the start built, the files written: 4 s) grows as the
    // voxels.
    finish(plan, plan.runs[2], 64.0, 32.0, 300.0, 16000000, 100.0);
    const double perVoxel = (300.0 - 80.0) * mb / 12e6; // 19.2 bytes
    EXPECT_NEAR(estimate(3).memoryMb, 300.0 + 48e6 * perVoxel / mb, 1e-6);
    EXPECT_NEAR(estimate(3).seconds, 64.0 * 8 + 32.0 * 4 + 4.0 * 4, 1e-9);
    // A damaged figure is no result, not an estimate of anything: the run is left out.
    const std::string result = runDirectory(plan, plan.runs[2]) + "/result.json";
    std::ifstream in(result);
    nlohmann::json damaged = nlohmann::json::parse(in);
    damaged["row"]["run_s"] = 1e300;
    write(result, damaged.dump());
    EXPECT_EQ(estimate(3).basis, "measured run " + plan.runs[1].id);
}
