// SPDX-License-Identifier: Apache-2.0
// The process's peak resident memory, and restarting its count for one piece of work.
#include <cstdio>
#include <cstring>

#include <memory>
#include <vector>

#include <gtest/gtest.h>
#include <sys/mman.h>
#include <sys/resource.h>

#include "core/memory.h"

using namespace sweepers;

namespace {

// 256 MB mapped and touched, then unmapped (straight from the kernel, so that no allocator,
// AddressSanitizer's included, keeps it resident afterwards).
void touchAndRelease(std::size_t bytes) {
    void* p = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    ASSERT_NE(p, MAP_FAILED);
    std::memset(p, 1, bytes);
    ::munmap(p, bytes);
}

TEST(Memory, ThePeakCountRestartsFromWhatIsResidentNow) {
    constexpr std::size_t kBytes = std::size_t(256) << 20;
    const double before = peakResidentBytes();
    ASSERT_GT(before, 0.0);
    touchAndRelease(kBytes);
    const double withBlock = peakResidentBytes();
    EXPECT_GE(withBlock, double(kBytes));
    ASSERT_TRUE(restartPeakResident());
    const double restarted = peakResidentBytes();
    EXPECT_LT(restarted, withBlock - 0.75 * double(kBytes));
    EXPECT_GT(availableMemoryBytes(), 0.0);
}

// The process's minor page faults so far.
long minorFaults() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return usage.ru_minflt;
}

char* volatile sink; // keeps the compiler from leaving out the blocks written below

// Allocates a block, writes every page of it, frees it.
void writeBlock(std::size_t bytes) {
    const std::unique_ptr<char[]> block(new char[bytes]);
    sink = block.get();
    std::memset(sink, 1, bytes);
}

TEST(Memory, FreedMemoryIsKeptForTheNextAllocation) {
    if (kAddressSanitizer)
        GTEST_SKIP() << "AddressSanitizer's allocator does not take glibc's settings";
    keepFreedMemory();
    constexpr std::size_t kBytes = std::size_t(24) << 20, kPages = kBytes / 4096;
    writeBlock(kBytes);
    const long before = minorFaults();
    writeBlock(kBytes); // the same pages again: no fault
    const long faults = minorFaults() - before;
    std::printf("[ memory ] %ld page faults writing %zu pages a second time\n", faults, kPages);
    EXPECT_LT(faults, long(kPages / 20));
}

TEST(Memory, ThePeakOfAPieceOfWorkLeavesOutWhatTheWorkBeforeFreed) {
    if (kAddressSanitizer)
        GTEST_SKIP() << "AddressSanitizer's allocator does not take glibc's settings";
    keepFreedMemory();
    // 192 MB in blocks the heap gives (below the mapping threshold), all freed: the heap
    // keeps them, resident, for the next allocations.
    constexpr std::size_t kBlock = std::size_t(24) << 20, kBlocks = 8;
    {
        std::vector<std::unique_ptr<char[]>> blocks;
        for (std::size_t i = 0; i < kBlocks; ++i) {
            blocks.emplace_back(new char[kBlock]);
            sink = blocks.back().get();
            std::memset(sink, 1, kBlock);
        }
    }
    const double withBlocks = peakResidentBytes();
    ASSERT_TRUE(restartPeakResident());
    EXPECT_LT(peakResidentBytes(), withBlocks - 0.75 * double(kBlock * kBlocks));
}

} // namespace
