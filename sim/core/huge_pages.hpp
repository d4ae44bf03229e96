// Large arrays on the host's transparent huge pages. Filling a fresh array of hundreds of
// megabytes costs one page fault per 4 KiB page, and on a virtual machine a page fault is dear
// (the sweep builder spent 17 % of a 1.5 M-triangle build in them); one 2 MiB page per fault
// costs 512 times fewer, and fewer TLB entries cover the array afterwards. Where the kernel
// gives huge pages only on request (/sys/kernel/mm/transparent_hugepage/enabled: madvise, as on
// Debian), an array must ask for them: std::vector<T, HugePageAllocator<T>> (HugeVector<T>)
// and make_huge_array<T>(n) (n uninitialised elements, whose pages are touched only as used)
// do, for blocks of at least one huge page; smaller ones are ordinary heap blocks.
#pragma once
#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>
#include <vector>

namespace tpsim::core {

/// The huge-page size asked for (x86-64 and most AArch64 kernels).
inline constexpr std::size_t kHugePageBytes = std::size_t{2} << 20;

/// Every heap block on huge pages too: glibc's malloc asks for them only when its
/// glibc.malloc.hugetlb tunable says so at the process's start. Loading a scene faults once per
/// 4 KiB otherwise (the mesh importer zeroes two 16 MiB buffers for an OBJ file), a third of a
/// render's fixed cost on a virtual machine (docs/performance.md, "Start-up page faults"). If the
/// environment does not set the tunable, this adds it and executes the program again with the
/// same arguments (`argv`); where that cannot be done it returns, and the program runs as it is.
/// (Under a tool that does not follow exec, valgrind without --trace-children=yes say, set the
/// tunable: GLIBC_TUNABLES=glibc.malloc.hugetlb=0.)
void run_with_huge_page_malloc(char** argv);

/// Allocates `bytes` aligned to `alignment` (a power of two). A block of at least one huge
/// page is aligned to a huge page, in whole huge pages, and the kernel is asked to back it with
/// huge pages (a request: without them it is ordinary memory); a smaller one is an ordinary heap
/// block. Either is freed by free_huge.
void* allocate_huge(std::size_t bytes, std::size_t alignment);
void free_huge(void* block) noexcept;

struct FreeHuge {
    void operator()(void* block) const noexcept { free_huge(block); }
};
template <class T> using HugeArray = std::unique_ptr<T[], FreeHuge>;

template <class T> HugeArray<T> make_huge_array(std::size_t n) {
    static_assert(std::is_trivial_v<T>, "elements are left uninitialised");
    if (n > std::size_t(-1) / sizeof(T)) throw std::bad_array_new_length();
    return HugeArray<T>(static_cast<T*>(allocate_huge(n * sizeof(T), alignof(T))));
}

template <class T> struct HugePageAllocator {
    using value_type = T;

    HugePageAllocator() = default;
    template <class U> HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

    T* allocate(std::size_t n) {
        if (n > max_size()) throw std::bad_array_new_length();
        return static_cast<T*>(allocate_huge(n * sizeof(T), alignof(T)));
    }
    void deallocate(T* p, std::size_t) noexcept { free_huge(p); }
    static constexpr std::size_t max_size() { return std::size_t(-1) / sizeof(T); }

    template <class U> bool operator==(const HugePageAllocator<U>&) const noexcept { return true; }
};

template <class T> using HugeVector = std::vector<T, HugePageAllocator<T>>;

}  // namespace tpsim::core
