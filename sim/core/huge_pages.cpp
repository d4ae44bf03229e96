#include "sim/core/huge_pages.hpp"

#include <algorithm>
#include <cstdlib>
#include <string>
#include <string_view>

#include <sys/mman.h>
#include <unistd.h>

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

void run_with_huge_page_malloc(char** argv) {
#ifdef __GLIBC__
    constexpr std::string_view kTunable = "glibc.malloc.hugetlb";
    const char* set = std::getenv("GLIBC_TUNABLES");
    if (set && std::string_view(set).find(kTunable) != std::string_view::npos) return;
    const std::string tunables =
        (set && *set ? std::string(set) + ":" : std::string()) + std::string(kTunable) + "=1";
    if (setenv("GLIBC_TUNABLES", tunables.c_str(), 1) != 0) return;
    execv("/proc/self/exe", argv);  // returns only if it failed: run without
#else
    (void)argv;
#endif
}

}  // namespace tpsim::core
