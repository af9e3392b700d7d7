// SPDX-License-Identifier: Apache-2.0
// The modeler's long jobs (app/job.h): the document made off the calling thread, progress as
// the work reports it, Esc's cancel reaching the work, failures handed back whole.
#include <chrono>
#include <stdexcept>
#include <thread>

#include <gtest/gtest.h>

#include "app/job.h"

using namespace sweepers;

namespace {

void waitUntilReady(const DocumentJob& job) {
    for (int k = 0; k < 2000 && !job.ready(); ++k)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    ASSERT_TRUE(job.ready());
}

} // namespace

TEST(DocumentJob, MakesTheDocumentOffThisThreadAndReportsProgress) {
    const std::thread::id here = std::this_thread::get_id();
    std::thread::id there;
    DocumentJob job("opening a sphere", [&](const Progress& progress, Interrupter*) {
        there = std::this_thread::get_id();
        progress(3, 4);
        return std::make_unique<Document>(Document::sphereScript(1.0 / 16), ".");
    });
    EXPECT_EQ(job.what(), "opening a sphere");
    waitUntilReady(job);
    EXPECT_EQ(job.done(), 3u);
    EXPECT_EQ(job.total(), 4u);
    EXPECT_FLOAT_EQ(job.fraction(), 0.75f);
    // Moved, as the window moves it out of its slot to take it.
    DocumentJob taken = std::move(job);
    const std::unique_ptr<Document> doc = taken.take();
    ASSERT_TRUE(doc);
    EXPECT_GT(doc->grid().activeVoxelCount(), 0u);
    EXPECT_NE(there, here);
    EXPECT_FALSE(taken.then());
    EXPECT_FALSE(taken.adoption());
}

TEST(DocumentJob, CancelReachesTheWorkAndFailuresComeBackWhole) {
    DocumentJob job("waiting", [](const Progress&, Interrupter* stop) {
        while (!stop->wasInterrupted())
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
        throw Cancelled();
        return std::unique_ptr<Document>();
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    EXPECT_FALSE(job.ready()); // it waits for Esc
    EXPECT_FLOAT_EQ(job.fraction(), 0.0f);
    job.cancel();
    waitUntilReady(job);
    EXPECT_THROW(job.take(), Cancelled);

    DocumentJob bad("opening a bad file",
                    [](const Progress&, Interrupter*) -> std::unique_ptr<Document> {
                        throw std::runtime_error("bad.vdb: not a VDB file");
                    });
    waitUntilReady(bad);
    try {
        bad.take();
        ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_STREQ(e.what(), "bad.vdb: not a VDB file");
    }

    // A job that changes the current document: no document, its `then` kept for the window.
    bool thenRan = false;
    DocumentJob change(
        "undoing", [](const Progress&, Interrupter*) { return std::unique_ptr<Document>(); },
        std::make_shared<Adoption>(), [&] { thenRan = true; });
    waitUntilReady(change);
    EXPECT_FALSE(change.take());
    ASSERT_TRUE(change.then());
    EXPECT_TRUE(change.adoption());
    change.then()();
    EXPECT_TRUE(thenRan);
}
