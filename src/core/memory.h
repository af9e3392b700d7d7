// How much memory the machine has free for a new job.
#pragma once

namespace sweepers {

// The kernel's estimate of memory available without swapping (MemAvailable), in bytes;
// 0 when it cannot be read.
double availableMemoryBytes();

} // namespace sweepers
