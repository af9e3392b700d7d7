// SPDX-License-Identifier: Apache-2.0
// The swept-fluid solution (deform/swept_fluid.h) is solved once per machine: the first run
// that needs it solves it (a noticeable wait at 72^3 cells) and keeps it as a VDB file in the cache
// directory, $SWEEPERS_CACHE, else $XDG_CACHE_HOME/sweepers, else ~/.cache/sweepers; later
// runs read it (in a child process, as any file we did not just write). A cache file that is
// damaged or was solved with other parameters is solved again and replaced; a cache that
// cannot be written (a read-only or full disk) costs the next run the solve, nothing else.
#pragma once

#include <memory>
#include <string>

#include "deform/swept_fluid.h"

namespace sweepers {

// Where the solution of `spec` is kept.
std::string fluidCachePath(const FluidSpec& spec = {});

// The smoothed solution of `spec`: from this process's memory, the cache file, or a solve.
// `said`, when given, receives one line on what happened ("read ...", "solved ... and kept
// it in ...", or why it could not be kept).
std::shared_ptr<const SweptFluid> sweptFluid(const FluidSpec& spec = {},
                                             std::string* said = nullptr);

} // namespace sweepers
