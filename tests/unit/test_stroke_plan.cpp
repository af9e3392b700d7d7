// SPDX-License-Identifier: Apache-2.0
// The one planner (sculpt/stroke_plan.h): a plan made ahead of the shape is the plan made on
// it, step for step, wherever the shape does not decide; the steps are what the sculptor
// applies; the shape's decisions are left out of the plan ahead and only those.
#include <gtest/gtest.h>

#include "io/input_file.h"
#include "io/stroke_script.h"
#include "levelset/create.h"
#include "sculpt/sculptor.h"
#include "sculpt/stroke_plan.h"

using namespace sweepers;

TEST(StrokePlan, AheadOfTheShapeItIsThePlanOnTheShapeWhereTheShapeDoesNotDecide) {
    // Every stroke kind, with the options whose plans differ (radial copies, a ball carried,
    // a removal, segments given or not, mirror and strength); parsed only, so the fluid
    // stroke, which needs its solution, is left to tests/cli/check.sh.
    const std::string path = SWEEPERS_CLI_TEST_DIR "/every_stroke_kind.json";
    StrokeScript script = parseStrokeScript(readWholeFile(path, 1 << 20, "a script"), path);
    ASSERT_TRUE(std::holds_alternative<FluidStroke>(script.strokes.back()));
    script.strokes.pop_back();
    const double h = script.grid.voxelSize;
    GridPtr grid = makeSphere(Eigen::Vector3d::Zero(), 1.0, h, 3.0);
    Sculptor sculptor(grid);
    std::size_t compared = 0, leftOut = 0;
    for (std::size_t i = 0; i < script.strokes.size(); ++i) {
        const Stroke& stroke = script.strokes[i];
        const std::vector<PlannedStep> ahead = planStrokeAhead(stroke, h);
        std::vector<PlannedStep> ran;
        sculptor.applyStroke(stroke, [&](const SegmentReport& r) { ran.push_back(r.step); });
        const bool flowByShape = std::holds_alternative<FlowStroke>(stroke) &&
                                 std::get<FlowStroke>(stroke).segments == 0;
        if (!flowByShape) {
            ASSERT_EQ(ahead.size(), ran.size()) << "stroke " << i;
            EXPECT_EQ(ahead.size(), segmentCount(stroke, h)) << "stroke " << i;
        }
        ASSERT_FALSE(ran.empty()) << "stroke " << i;
        for (std::size_t k = 0; k < ran.size(); ++k) {
            const PlannedStep& a = ahead[std::min(k, ahead.size() - 1)];
            const PlannedStep& r = ran[k];
            SCOPED_TRACE("stroke " + std::to_string(i) + " step " + std::to_string(k));
            EXPECT_EQ(r.kind, a.kind);
            EXPECT_EQ(r.segment, k);
            EXPECT_FALSE(r.leftToShape);
            // What ran is a deformation, or a dab, never both.
            EXPECT_NE(bool(r.deformation), r.dab.has_value());
            if (a.leftToShape) {
                EXPECT_FALSE(a.deformation);
                ++leftOut;
                continue;
            }
            EXPECT_EQ(a.segment, r.segment);
            EXPECT_EQ(a.subSteps, r.subSteps);
            EXPECT_EQ(a.affected.min, r.affected.min);
            EXPECT_EQ(a.affected.max, r.affected.max);
            EXPECT_EQ(a.tools, r.tools);
            EXPECT_EQ(a.bound, r.bound);
            EXPECT_EQ(a.dab.has_value(), r.dab.has_value());
            if (a.dab) {
                EXPECT_EQ(a.dab->center, r.dab->center);
                EXPECT_EQ(a.dab->time, r.dab->time);
            }
            if (r.deformation) {
                EXPECT_EQ(r.subSteps, r.deformation->steps());
                EXPECT_EQ(r.affected.min, r.deformation->affectedBox().min);
            }
            ++compared;
        }
    }
    // The shape decides the star-shaped swirl's, the inflations' and the removal's steps (4)
    // and the vortex's (one or more); everything else was compared.
    EXPECT_GE(leftOut, 5u);
    EXPECT_GE(compared, 20u);
}
