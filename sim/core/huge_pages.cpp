#include "sim/core/huge_pages.hpp"

#include <cstdlib>
#include <sys/mman.h>

namespace tpsim::core {

void* allocate_huge(std::size_t bytes) {
    // aligned_alloc wants a multiple of the alignment; the tail of the last page is unused.
    const std::size_t rounded = (bytes + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
    void* block = std::aligned_alloc(kHugePageBytes, rounded);
    if (!block) throw std::bad_alloc();
    // Advice only: a kernel without transparent huge pages leaves the block as it is.
    madvise(block, rounded, MADV_HUGEPAGE);
    return block;
}

void free_huge(void* block) noexcept {
    std::free(block);
}

}  // namespace tpsim::core
