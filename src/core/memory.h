// SPDX-License-Identifier: Apache-2.0
// How much memory the machine has free for a new job, how much this process used, and how
// the process keeps what it frees.
#pragma once

namespace sweepers {

// Whether this build runs under AddressSanitizer, which replaces the allocator (glibc's
// settings do not reach it) and reserves terabytes of address space. GCC says so with
// __SANITIZE_ADDRESS__, clang with __has_feature.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif
#else
constexpr bool kAddressSanitizer = false;
#endif

// The kernel's estimate of memory available without swapping (MemAvailable), in bytes;
// 0 when it cannot be read.
double availableMemoryBytes();

// The process's peak resident memory (VmHWM), in bytes; 0 when it cannot be read.
double peakResidentBytes();
// Starts the peak over, so that peakResidentBytes() measures one piece of work: the memory
// the process keeps freed (keepFreedMemory) goes back to the kernel first, or the work
// before would count in it, then the peak restarts from what is resident (Linux's
// clear_refs). False when the kernel refused: the peak then stays the process's own.
bool restartPeakResident();

// Keeps the memory the process frees for its next allocations instead of handing it back
// to the kernel at once: a stroke segment allocates and frees the same few megabytes every
// time, and every page handed back and asked for again costs a page fault, which on a
// virtual machine is slow enough to be a large part of a segment. Called
// first thing by the executables; does nothing where the C library is not glibc.
void keepFreedMemory();

} // namespace sweepers
