// SPDX-License-Identifier: Apache-2.0
// The pieces of a grid-resolution study that need no grid: variants, observed orders, and
// a run's result as the table is made from it.
#include <cmath>
#include <cstdio>

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
    EXPECT_EQ(variantOptions(StudyVariant::FirstOrder).renormalization, UpwindOrder::First);
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
    const std::string report = studyReport(rows, {});
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
    const std::string report = studyReport(rows, {});
    EXPECT_EQ(report.find("(exact:"), std::string::npos) << report;
    const StudyRow back = studyRowFromJson(studyRowJson(rows[0], true), "row");
    EXPECT_FALSE(back.referenceTopologyKnown);
    EXPECT_EQ(back.genus, 1);
}

TEST(Study, ARunsResultReadsBackWhatWasWritten) {
    std::vector<StudyRow> rows = {row("trilinear", 1.0 / 32, 4e-3, 1e-3),
                                  row("trilinear", 1.0 / 64, 1e-3)};
    rows[1].error.signFlips = 7;
    rows[1].wallSeconds = 1.0 / 3.0;
    rows[1].measureSeconds = 2.0 / 3.0;
    rows[1].error.meshVolume = 0.5 - 2.5e-4;
    rows[1].host = "node-17";
    rows[1].threads = 8;
    rows.push_back(row("cubic", 0.03, 0.0));
    rows.back().failure = "a \"quoted\", comma'd reason";
    for (StudyRow& r : rows)
        r.script = "poke";
    fillOrders(rows);
    std::vector<StudyRow> back;
    for (const StudyRow& r : rows)
        back.push_back(studyRowFromJson(studyRowJson(r, true), "result.json"));
    EXPECT_EQ(back[1].script, "poke");
    EXPECT_EQ(back[1].variant, "trilinear");
    EXPECT_EQ(back[1].voxelSize, 1.0 / 64); // exactly: a result is matched to its run by it
    EXPECT_EQ(back[1].error.signFlips, 7u);
    EXPECT_EQ(back[1].wallSeconds, 1.0 / 3.0); // every digit, for the table made from it
    EXPECT_EQ(back[1].measureSeconds, 2.0 / 3.0);
    EXPECT_EQ(back[1].host, "node-17");
    EXPECT_EQ(back[1].threads, 8);
    EXPECT_TRUE(std::isnan(back[0].orderRms));
    EXPECT_NEAR(back[1].orderRms, 2.0, 1e-12);
    EXPECT_DOUBLE_EQ(back[1].error.referenceVolume, 0.5);
    EXPECT_NEAR(back[1].error.volumeError(), -2.5e-4, 1e-15);
    EXPECT_EQ(back[1].referenceEuler, 2);
    EXPECT_EQ(back[1].referenceComponents, 1u);
    EXPECT_TRUE(back[1].referenceTopologyKnown);
    EXPECT_EQ(back[2].failure, rows[2].failure);
    EXPECT_EQ(studyRunName(back[1]), "trilinear_64");
    EXPECT_EQ(studyRunId(back[2]), "poke-cubic_0.03");
    // The table is the same whether made from the rows or from what was read back.
    EXPECT_EQ(studyCsv(back), studyCsv(rows));
    // A damaged count or voxel size is refused, not converted.
    const nlohmann::json good = studyRowJson(rows[1], true);
    for (const nlohmann::json& bad :
         {nlohmann::json(-1), nlohmann::json(1e300), nlohmann::json(2.5), nlohmann::json("7")}) {
        nlohmann::json damaged = good;
        damaged["sign_flips"] = bad;
        EXPECT_THROW(studyRowFromJson(damaged, "result.json"), FileError) << bad;
    }
    nlohmann::json damaged = good;
    damaged["voxel_size"] = -0.5;
    EXPECT_THROW(studyRowFromJson(damaged, "result.json"), FileError) << "a negative voxel size";
    damaged = good;
    damaged.erase("err_rms");
    EXPECT_THROW(studyRowFromJson(damaged, "result.json"), FileError) << "a column missing";
    EXPECT_THROW(studyRowFromJson(nlohmann::json::array(), "result.json"), FileError);
}

} // namespace
