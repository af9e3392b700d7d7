// The pieces of a grid-resolution study that need no grid: variants, observed orders, and
// the table a study resumes from.
#include <cmath>
#include <cstdio>
#include <fstream>

#include <gtest/gtest.h>

#include "io/study_files.h"
#include "io/vdb_file.h"
#include "study/study.h"

using namespace sweepers;

namespace {

StudyRow row(const std::string& variant, double h, double rms, double volumeError = 0.0) {
    StudyRow r;
    r.variant = variant;
    r.voxelSize = h;
    r.error.rms = rms;
    r.error.referenceVolume = 0.5;
    r.error.meshVolume = 0.5 + volumeError;
    r.error.samples = 100;
    r.volume = 0.5;
    r.euler = r.referenceEuler = 2;
    r.components = r.referenceComponents = 1;
    return r;
}

TEST(Study, VariantNamesRoundTrip) {
    for (StudyVariant v : {StudyVariant::Trilinear, StudyVariant::Cubic, StudyVariant::PerSubStep,
                           StudyVariant::FirstOrder})
        EXPECT_EQ(parseVariant(variantName(v)), v);
    EXPECT_FALSE(parseVariant("quintic"));
    EXPECT_TRUE(variantOptions(StudyVariant::PerSubStep).resampleEachSubStep);
    EXPECT_EQ(variantOptions(StudyVariant::Cubic).sampling, Sampling::MonotoneCubic);
    EXPECT_EQ(variantOptions(StudyVariant::FirstOrder).renormalization, FmmOrder::First);
}

TEST(Study, OrdersCompareEachRunWithTheNextCoarserOfItsVariant) {
    std::vector<StudyRow> rows = {
        row("trilinear", 1.0 / 32, 4e-3, -8e-3), row("cubic", 1.0 / 32, 1e-3, 1e-3),
        row("trilinear", 1.0 / 64, 1e-3, 1e-3), row("cubic", 1.0 / 64, 5e-4, 0.0),
        row("trilinear", 1.0 / 128, 5e-4, -1e-3)};
    rows.push_back(row("cubic", 1.0 / 128, 0.0));
    rows.back().failure = "out of memory";
    fillOrders(rows);
    EXPECT_TRUE(std::isnan(rows[0].orderRms));
    EXPECT_TRUE(std::isnan(rows[1].orderRms));
    EXPECT_NEAR(rows[2].orderRms, 2.0, 1e-12);
    EXPECT_NEAR(rows[3].orderRms, 1.0, 1e-12);
    EXPECT_NEAR(rows[4].orderRms, 1.0, 1e-12);
    EXPECT_TRUE(std::isnan(rows[5].orderRms));
    // Volume: of the error's size, whatever its sign; none against an error of zero.
    EXPECT_TRUE(std::isnan(rows[0].orderVolume));
    EXPECT_NEAR(rows[2].orderVolume, 3.0, 1e-9);
    EXPECT_TRUE(std::isnan(rows[3].orderVolume));
    EXPECT_NEAR(rows[4].orderVolume, 0.0, 1e-9);
    EXPECT_TRUE(std::isnan(rows[5].orderVolume));
}

TEST(Study, TheReportMarksARunWhoseTopologyIsNotTheExactShapes) {
    std::vector<StudyRow> rows = {row("trilinear", 1.0 / 32, 4e-3, 1e-3),
                                  row("trilinear", 1.0 / 64, 1e-3, 2e-4)};
    rows[0].euler = 0;
    rows[0].genus = 1;
    fillOrders(rows);
    const std::string report = studyReport(rows, "poke.json");
    EXPECT_NE(report.find("| 0 | 1 | 1 (exact: Euler 2, genus 0, 1 component) |"),
              std::string::npos)
        << report;
    EXPECT_EQ(report.find("(exact:", report.find("| trilinear | 1/64 |")), std::string::npos)
        << "the run of the exact topology is marked";
    // The volume error in percent of the exact volume, and its order.
    EXPECT_NE(report.find("| 0.04% | 2.32 |"), std::string::npos) << report;
}

TEST(Study, AHistoryThatTearsSpaceClaimsNoExactTopology) {
    // A pinch made a torus: the start's topology is not the exact one, and nothing is marked.
    std::vector<StudyRow> rows = {row("trilinear", 1.0 / 32, 4e-3)};
    rows[0].euler = 0;
    rows[0].genus = 1;
    rows[0].referenceTopologyKnown = false;
    const std::string report = studyReport(rows, "pinch_torus.json");
    EXPECT_EQ(report.find("(exact:"), std::string::npos) << report;
    const std::string path = ::testing::TempDir() + "study_torn.csv";
    std::ofstream(path) << studyCsv(rows);
    const std::vector<StudyRow> back = readStudyCsv(path);
    ASSERT_EQ(back.size(), 1u);
    EXPECT_FALSE(back[0].referenceTopologyKnown);
    EXPECT_EQ(back[0].genus, 1);
}

TEST(Study, TableReadsBackWhatWasWritten) {
    std::vector<StudyRow> rows = {row("trilinear", 1.0 / 32, 4e-3, 1e-3),
                                  row("trilinear", 1.0 / 64, 1e-3)};
    rows[1].error.signFlips = 7;
    rows[1].wallSeconds = 1.25;
    rows[1].error.meshVolume = 0.5 - 2.5e-4;
    rows.push_back(row("cubic", 0.03, 0.0));
    rows.back().failure = "a \"quoted\", comma'd reason";
    fillOrders(rows);
    const std::string path = ::testing::TempDir() + "study_table.csv";
    std::ofstream(path) << studyCsv(rows);
    const std::vector<StudyRow> back = readStudyCsv(path);
    ASSERT_EQ(back.size(), 3u);
    EXPECT_EQ(back[1].variant, "trilinear");
    EXPECT_EQ(back[1].voxelSize, 1.0 / 64); // exactly: resuming matches runs by it
    EXPECT_EQ(back[1].error.signFlips, 7u);
    EXPECT_DOUBLE_EQ(back[1].wallSeconds, 1.25);
    EXPECT_NEAR(back[1].orderRms, 2.0, 1e-3);
    EXPECT_DOUBLE_EQ(back[1].error.referenceVolume, 0.5);
    EXPECT_NEAR(back[1].error.volumeError(), -2.5e-4, 1e-12);
    EXPECT_NEAR(back[1].orderVolume, 2.0, 1e-3);
    EXPECT_EQ(back[1].referenceEuler, 2);
    EXPECT_EQ(back[1].referenceComponents, 1u);
    EXPECT_TRUE(back[1].referenceTopologyKnown);
    EXPECT_EQ(back[2].failure, rows[2].failure);
    EXPECT_EQ(studyRunName(back[1]), "trilinear_64");
    EXPECT_EQ(studyRunName(back[2]), "cubic_0.03");
    std::ofstream(path) << "not,a,study\n";
    EXPECT_THROW(readStudyCsv(path), FileError);
    // A table of another version (its columns differ) is refused, not misread.
    const std::string table = studyCsv(rows);
    const std::string header = table.substr(0, table.find('\n') + 1);
    std::string older = table;
    older.replace(older.find(",volume_ref,volume_err,order_volume"), 35, "");
    std::ofstream(path) << older;
    try {
        readStudyCsv(path);
        ADD_FAILURE() << "a table with other columns was read";
    } catch (const FileError& e) {
        EXPECT_NE(std::string(e.what()).find("other columns"), std::string::npos) << e.what();
    }
    // A damaged count or voxel size is refused, not converted: the table's first row with
    // its sign_flips (field 19) or voxel size (field 2) replaced.
    for (const char* bad : {"-1", "1e300", "nan", "2.5"}) {
        std::string line =
            table.substr(header.size(), table.find('\n', header.size()) + 1 - header.size());
        std::size_t at = 0;
        for (int c = 0; c < 18; ++c)
            at = line.find(',', at) + 1;
        line.replace(at, line.find(',', at) - at, bad);
        std::ofstream(path) << header << line;
        EXPECT_THROW(readStudyCsv(path), FileError) << "sign_flips " << bad;
    }
    std::ofstream(path) << header << "trilinear,-0.5" << std::string(24, ',') << "\n";
    EXPECT_THROW(readStudyCsv(path), FileError) << "a negative voxel size";
    std::remove(path.c_str());
    EXPECT_TRUE(readStudyCsv(path).empty()); // no table yet: nothing to resume
}

} // namespace
