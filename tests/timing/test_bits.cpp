#include "sim/timing/bits.hpp"

#include <catch2/catch.hpp>

#include <vector>

using namespace tpsim::timing;

namespace {

// The indices of `set` in the order for_each_rotated_part visits them from `start`.
std::vector<uint32_t> visit(const std::vector<uint64_t>& set, uint32_t start) {
    std::vector<uint32_t> order;
    for_each_rotated_part(uint32_t(set.size()), start, [&](const RotatedPart& part) {
        for (uint64_t bits = part.of(set[part.w]); bits != 0; bits &= bits - 1)
            order.push_back(part.index(uint32_t(std::countr_zero(bits))));
    });
    return order;
}

}  // namespace

TEST_CASE("a rotated walk visits every index once, from the start, wrapping", "[bits]") {
    CHECK(visit({0b1011'0110}, 0) == std::vector<uint32_t>{1, 2, 4, 5, 7});
    CHECK(visit({0b1011'0110}, 4) == std::vector<uint32_t>{4, 5, 7, 1, 2});
    CHECK(visit({uint64_t{1} << 63 | 1}, 63) == std::vector<uint32_t>{63, 0});
    // Two words: the first word's bits from the start up, the second word, the first's rest.
    const std::vector<uint64_t> two = {0b101, uint64_t{1} << 5 | 1};
    CHECK(visit(two, 1) == std::vector<uint32_t>{2, 64, 69, 0});
    CHECK(visit(two, 66) == std::vector<uint32_t>{69, 0, 2, 64});
}

TEST_CASE("rotated bits go back to their places", "[bits]") {
    for_each_rotated_part(1, 5, [](const RotatedPart& part) {
        CHECK(part.back(part.of(0xdead'beef)) == 0xdead'beef);
        CHECK(part.index(0) == 5);
        CHECK(part.index(60) == 1);
    });
}
