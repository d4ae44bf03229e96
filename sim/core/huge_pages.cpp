#include "sim/core/huge_pages.hpp"

#include <algorithm>
#include <cstdlib>
#include <sys/mman.h>

namespace tpsim::core {

void* allocate_huge(std::size_t bytes, std::size_t alignment) {
    const bool huge = bytes >= kHugePageBytes;
    if (huge) alignment = std::max(alignment, kHugePageBytes);
    // aligned_alloc wants a multiple of the alignment (the tail of the last page is unused), and
    // at least one byte.
    const std::size_t rounded =
        (std::max<std::size_t>(bytes, 1) + alignment - 1) & ~(alignment - 1);
    void* block = std::aligned_alloc(alignment, rounded);
    if (!block) throw std::bad_alloc();
    // Advice only: a kernel without transparent huge pages leaves the block as it is.
    if (huge) madvise(block, rounded, MADV_HUGEPAGE);
    return block;
}

void free_huge(void* block) noexcept {
    std::free(block);
}

}  // namespace tpsim::core
