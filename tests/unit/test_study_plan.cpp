// SPDX-License-Identifier: Apache-2.0
// io/study_plan.h: a run's digest says what its result depends on, so a result on disk is
// reused exactly when nothing it was made from changed.
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include <gtest/gtest.h>

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
