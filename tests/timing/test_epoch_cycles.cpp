#include "sim/timing/epoch_cycles.hpp"

#include <catch2/catch.hpp>

#include <array>

using namespace tpsim::timing;

TEST_CASE("epoch cycles: offsets keep their cycles across a move of the epoch") {
    EpochCycles epoch;
    const uint64_t before = 5'000'000'000;  // past 32 bits from cycle 0
    CHECK(epoch.due(EpochCycles::kSpan));
    CHECK_FALSE(epoch.due(EpochCycles::kSpan - 1));
    epoch.move_to(EpochCycles::kSpan, [](auto&&) {});
    epoch.move_to(2 * EpochCycles::kSpan, [](auto&&) {});  // the epoch is now 2^32
    REQUIRE(epoch.cycle(epoch.offset(before)) == before);

    // Readable long ago, just now, soon, at the end of a long latency, after a reply.
    const uint64_t now = before + 3 * EpochCycles::kSpan / 2;
    std::array<uint64_t, 5> cycles = {before, now, now + 1, now + 100'000, UINT64_MAX};
    std::array<uint32_t, 5> offsets{};
    for (size_t i = 0; i < cycles.size(); ++i)
        offsets[i] = epoch.offset(cycles[i]);
    REQUIRE(epoch.due(now));
    epoch.move_to(now, [&](auto&& shift) { shift(offsets); });
    CHECK_FALSE(epoch.due(now));
    CHECK(epoch.cycle(offsets[0]) == now);  // before now: now, as readable as it was
    for (size_t i = 1; i < cycles.size(); ++i)
        CHECK(epoch.cycle(offsets[i]) == cycles[i]);
    CHECK(offsets[4] == EpochCycles::kNever);
}
