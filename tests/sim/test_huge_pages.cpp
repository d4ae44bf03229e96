#include <cstdint>
#include <fstream>
#include <numeric>
#include <sstream>
#include <string>

#include <catch2/catch.hpp>

#include "sim/core/huge_pages.hpp"

using namespace tpsim::core;

namespace {

bool aligned(const void* p, std::size_t alignment) {
    return reinterpret_cast<std::uintptr_t>(p) % alignment == 0;
}

/// The kilobytes of huge pages backing the mapping that holds `p` (/proc/self/smaps).
long huge_kib_at(const void* p) {
    const auto at = reinterpret_cast<std::uintptr_t>(p);
    std::ifstream smaps("/proc/self/smaps");
    std::string line;
    bool inside = false;
    while (std::getline(smaps, line)) {
        std::uintptr_t begin = 0, end = 0;
        char dash = 0;
        std::istringstream range(line);
        if (range >> std::hex >> begin >> dash >> end && dash == '-') {
            inside = begin <= at && at < end;
        } else if (inside && line.rfind("AnonHugePages:", 0) == 0) {
            return std::stol(line.substr(14));
        }
    }
    return -1;
}

/// Whether the kernel gives transparent huge pages to a block that asks for them.
bool kernel_gives_huge_pages() {
    std::ifstream enabled("/sys/kernel/mm/transparent_hugepage/enabled");
    std::string modes;
    std::getline(enabled, modes);
    return modes.find("[always]") != std::string::npos ||
           modes.find("[madvise]") != std::string::npos;
}

struct alignas(64) Line {
    uint64_t words[8];
};

}  // namespace

TEST_CASE("huge pages: a large vector starts on a huge page and holds its elements") {
    HugeVector<uint64_t> big(4 << 20);  // 32 MiB
    REQUIRE(aligned(big.data(), kHugePageBytes));
    std::iota(big.begin(), big.end(), uint64_t{0});
    CHECK(big[12345] == 12345);
    CHECK(big.back() == (4 << 20) - 1);
    if (kernel_gives_huge_pages()) CHECK(huge_kib_at(big.data()) >= 2048);

    // Growing moves it to a new block, shrinking to fit to an ordinary one: both keep values.
    big.push_back(7);
    REQUIRE(aligned(big.data(), kHugePageBytes));
    CHECK(big[4 << 20] == 7);
    big.resize(100);
    big.shrink_to_fit();
    CHECK(big[99] == 99);
    const HugeVector<uint64_t> copy = big;
    CHECK(copy == big);
}

TEST_CASE("huge pages: a small vector is ordinary memory with its type's alignment") {
    HugeVector<Line> lines(3);
    CHECK(aligned(lines.data(), alignof(Line)));
    lines[2].words[7] = 42;
    CHECK(lines[2].words[7] == 42);
    HugeVector<uint8_t> bytes(kHugePageBytes - 1, 1);
    CHECK(std::accumulate(bytes.begin(), bytes.end(), std::size_t{0}) == kHugePageBytes - 1);
}

TEST_CASE("huge pages: an array for a few elements or for many") {
    // A few: ordinary heap blocks with the type's alignment, as a vector's, not a huge page
    // each (two such blocks could not both start on one).
    const HugeArray<Line> few = make_huge_array<Line>(3), other = make_huge_array<Line>(3);
    REQUIRE(aligned(few.get(), alignof(Line)));
    REQUIRE(aligned(other.get(), alignof(Line)));
    CHECK_FALSE((aligned(few.get(), kHugePageBytes) && aligned(other.get(), kHugePageBytes)));
    few[2].words[7] = 5;
    CHECK(few[2].words[7] == 5);
    const HugeArray<float> many = make_huge_array<float>(3 << 20);
    REQUIRE(aligned(many.get(), kHugePageBytes));
    many[(3 << 20) - 1] = 1.5f;
    CHECK(many[(3 << 20) - 1] == 1.5f);
    CHECK_THROWS_AS(make_huge_array<uint64_t>(std::size_t(-1) / 4), std::bad_array_new_length);
}
