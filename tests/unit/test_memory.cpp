// The process's peak resident memory, and restarting its count for one piece of work.
#include <cstring>

#include <gtest/gtest.h>
#include <sys/mman.h>

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

} // namespace
