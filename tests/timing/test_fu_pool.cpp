#include "sim/timing/fu_pool.hpp"

#include <catch2/catch.hpp>

#include <vector>

using namespace tpsim::timing;

namespace {

// The requesters that won this cycle, lowest first.
std::vector<uint32_t> winners_of(FuPool& pool, uint64_t now, uint32_t requesters) {
    std::vector<uint64_t> words((requesters + 63) / 64, 0);
    pool.arbitrate(now, words.data());
    std::vector<uint32_t> ids;
    for (uint32_t id = 0; id < requesters; ++id)
        if (words[id / 64] >> (id % 64) & 1) ids.push_back(id);
    return ids;
}

// Every requester asks every cycle; returns grants per requester.
std::vector<uint64_t> saturate(FuPool& pool, uint32_t requesters, uint64_t cycles) {
    std::vector<uint64_t> grants(requesters, 0);
    for (uint64_t now = 0; now < cycles; ++now) {
        for (uint32_t id = 0; id < requesters; ++id)
            pool.request(id / 64, uint64_t{1} << (id % 64));
        for (uint32_t id : winners_of(pool, now, requesters))
            ++grants[id];
    }
    return grants;
}

}  // namespace

TEST_CASE("a pipelined pool starts `count` operations per cycle, shared fairly", "[fu]") {
    FuPool pool(FuConfig{1, 3, true}, 4);
    const auto grants = saturate(pool, 4, 100);
    CHECK(grants == std::vector<uint64_t>{25, 25, 25, 25});
    CHECK(pool.counters().issued == 100);
    CHECK(pool.counters().denied == 300);

    FuPool wide(FuConfig{3, 2, true}, 4);
    const auto wide_grants = saturate(wide, 4, 100);
    CHECK(wide.counters().issued == 300);  // 3 units, one issue each per cycle
    for (uint64_t g : wide_grants)
        CHECK(g == 75);
}

TEST_CASE("a blocking pool is busy for its latency", "[fu]") {
    FuPool pool(FuConfig{2, 4, false}, 3);
    const auto grants = saturate(pool, 3, 120);
    CHECK(pool.counters().issued == 2 * 120 / 4);  // throughput count / latency
    CHECK(pool.counters().unit_busy_cycles == 240);
    for (uint64_t g : grants)
        CHECK(g == 20);
}

TEST_CASE("a pool of more than 64 requesters shares fairly too", "[fu]") {
    FuPool pool(FuConfig{3, 1, true}, 100);
    const auto grants = saturate(pool, 100, 100);
    CHECK(grants == std::vector<uint64_t>(100, 3));
    CHECK(pool.counters().denied == 100 * 97);
}

TEST_CASE("fewer requests than units are all granted at once", "[fu]") {
    FuPool pool(FuConfig{4, 1, true}, 32);
    pool.request(0, uint64_t{1} << 30 | uint64_t{1} << 2);  // two requesters in one call
    CHECK(winners_of(pool, 7, 32) == std::vector<uint32_t>{2, 30});
    CHECK(pool.counters().denied == 0);
}

TEST_CASE("rotating priority: the last winner goes to the back", "[fu]") {
    FuPool pool(FuConfig{1, 1, true}, 3);
    std::vector<uint32_t> order;
    for (uint64_t now = 0; now < 6; ++now) {
        pool.request(0, uint64_t{1} << 2);  // request order must not matter
        pool.request(0, uint64_t{1} << 0);
        pool.request(0, uint64_t{1} << 1);
        for (uint32_t id : winners_of(pool, now, 3))
            order.push_back(id);
    }
    CHECK(order == std::vector<uint32_t>{0, 1, 2, 0, 1, 2});
}

TEST_CASE("scarce units go to the first requesters from the priority pointer", "[fu]") {
    FuPool pool(FuConfig{2, 1, true}, 5);
    std::vector<std::vector<uint32_t>> rounds;
    for (uint64_t now = 0; now < 4; ++now) {
        pool.request(0, 0b11110);  // requesters 1..4
        rounds.push_back(winners_of(pool, now, 5));
    }
    // The pointer starts at 0 and moves past the last winner, wrapping around.
    CHECK(rounds == std::vector<std::vector<uint32_t>>{{1, 2}, {3, 4}, {1, 2}, {3, 4}});
}

TEST_CASE("every FU class maps to the pool the milestone names", "[fu]") {
    using tpsim::isa::FuClass;
    CHECK(pool_of(FuClass::IntDiv) == Pool::IntMulDiv);
    CHECK(pool_of(FuClass::FpSqrt) == Pool::FpDivSqrt);
    CHECK(pool_of(FuClass::FpDiv) == Pool::FpDivSqrt);
    CHECK(pool_of(FuClass::Store) == Pool::LoadStore);
    CHECK(pool_of(FuClass::System) == Pool::IntAlu);
    CHECK_THROWS(pool_of(FuClass::Count));
    FuPoolsConfig pools;
    CHECK(&pool_config(pools, Pool::FpDivSqrt) == &pools.fp_divsqrt);
    CHECK(to_string(Pool::Atomic) == "atomic");
}
