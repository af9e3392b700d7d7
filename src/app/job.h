// SPDX-License-Identifier: Apache-2.0
// Long work on the modeler's document off the render thread: opening or importing a file,
// recovering a session, resampling at another detail, undoing by replay. One job at a time;
// the window shows its progress and Esc cancels it; the result is taken on the render thread
// when it is ready (poll), and a job that fails or is cancelled leaves the document as it was.
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <future>
#include <memory>
#include <string>

#include "app/session.h"
#include "document/document.h"
#include "levelset/interrupt.h"

namespace sweepers {

class DocumentJob {
  public:
    // Makes a new document, or (null) changes the current one through `then`.
    using Maker = std::function<std::unique_ptr<Document>(const Progress&, Interrupter*)>;

    // Starts `make` on a thread of its own. `adopt`: what a recovery's session takes over;
    // `then`: for a job that changes the current document rather than making a new one, what
    // to do with the document when the job is done.
    DocumentJob(std::string what, Maker make, std::shared_ptr<Adoption> adopt = nullptr,
                std::function<void()> then = {});

    // Whether the work has ended (done, failed or cancelled): take() does not wait then.
    bool ready() const;
    // The document made (null for a job with `then`); rethrows what the work threw
    // (Cancelled when it was cancelled). Once.
    std::unique_ptr<Document> take();

    void cancel() { stop_->interrupt(); }
    const std::string& what() const { return what_; }
    // Progress as the work reports it: `done` of `total` (0: not known yet).
    std::size_t done() const { return *done_; }
    std::size_t total() const { return *total_; }
    // The progress bar's fraction.
    float fraction() const;
    const std::shared_ptr<Adoption>& adoption() const { return adopt_; }
    const std::function<void()>& then() const { return then_; }

  private:
    std::string what_;
    std::shared_ptr<std::atomic<std::size_t>> done_, total_;
    std::shared_ptr<FlagInterrupter> stop_;
    std::shared_ptr<Adoption> adopt_;
    std::function<void()> then_;
    std::future<std::unique_ptr<Document>> result_;
};

} // namespace sweepers
