// SPDX-License-Identifier: Apache-2.0
#include "app/job.h"

#include <chrono>
#include <utility>

namespace sweepers {

DocumentJob::DocumentJob(std::string what, Maker make, std::shared_ptr<Adoption> adopt,
                         std::function<void()> then)
    : what_(std::move(what)), done_(std::make_shared<std::atomic<std::size_t>>(0)),
      total_(std::make_shared<std::atomic<std::size_t>>(0)),
      stop_(std::make_shared<FlagInterrupter>()), adopt_(std::move(adopt)), then_(std::move(then)) {
    // The thread holds its own references: the job may be moved while it runs.
    Progress progress = [done = done_, total = total_](std::size_t d, std::size_t t) {
        *done = d;
        *total = t;
    };
    result_ = std::async(std::launch::async, [make = std::move(make), progress, stop = stop_] {
        return make(progress, stop.get());
    });
}

bool DocumentJob::ready() const {
    return result_.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
}

std::unique_ptr<Document> DocumentJob::take() {
    return result_.get();
}

float DocumentJob::fraction() const {
    const std::size_t d = done(), t = total();
    return t ? float(d) / float(t) : 0.0f;
}

} // namespace sweepers
