// How much memory the machine has free for a new job, and how much this process used.
#pragma once

namespace sweepers {

// The kernel's estimate of memory available without swapping (MemAvailable), in bytes;
// 0 when it cannot be read.
double availableMemoryBytes();

// The process's peak resident memory (VmHWM), in bytes; 0 when it cannot be read.
double peakResidentBytes();
// Starts the peak over from the memory resident now, so that peakResidentBytes() measures
// one piece of work (Linux's clear_refs). False when the kernel refused: the peak then
// stays the process's own since it started.
bool restartPeakResident();

} // namespace sweepers
