#include "sim/stats/registry.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <sstream>
#include <string>

using namespace tpsim::stats;

TEST_CASE("counters are read by reference when printed, not when registered", "[stats]") {
    Registry r;
    uint64_t hits = 0;
    r.add_counter("tm0/l1/hits", hits, "L1 hits");
    hits = 41;
    ++hits;
    CHECK(r.at("tm0/l1/hits").integer() == 42);
    CHECK(r.value("tm0/l1/hits") == 42.0);
}

TEST_CASE("duplicate and malformed names are rejected", "[stats]") {
    Registry r;
    uint64_t c = 0;
    r.add_counter("a/b", c, "x");
    CHECK_THROWS_WITH(r.add_counter("a/b", c, "x"), Catch::Contains("registered twice"));
    CHECK_THROWS_WITH(r.add_counter("a//b", c, "x"), Catch::Contains("malformed"));
    CHECK_THROWS_WITH(r.add_counter("/a", c, "x"), Catch::Contains("malformed"));
    CHECK_THROWS_WITH(r.add_counter("a b", c, "x"), Catch::Contains("malformed"));
    CHECK_THROWS_AS(r.at("nope"), std::out_of_range);
}

TEST_CASE("pattern matching is by whole segments", "[stats]") {
    CHECK(matches("tm*/l1/misses", "tm*/l1/misses"));
    CHECK(matches("*/l1/misses", "tm3/l1/misses"));
    CHECK_FALSE(matches("*/l1/misses", "tm3/l1/misses/x"));
    CHECK_FALSE(matches("*/l1/misses", "l1/misses"));
    CHECK_FALSE(matches("*/l1/misses", "tm3/l2/misses"));
    CHECK(matches("tm*/l1/misses", "tm12/l1/misses"));
    CHECK_FALSE(matches("tm*/l1/misses", "chip/l1/misses"));
    CHECK_FALSE(matches("tm*/l1/misses", "tm/l1/misses"));
    CHECK_FALSE(matches("tm*/l1/misses", "tm3x/l1/misses"));
}

TEST_CASE("ratios and sums aggregate over components", "[stats]") {
    Registry r;
    uint64_t miss[3] = {1, 2, 3}, acc[3] = {10, 10, 20};
    for (int tm = 0; tm < 3; ++tm) {
        r.add_counter("tm" + std::to_string(tm) + "/l1/misses", miss[tm], "m");
        r.add_counter("tm" + std::to_string(tm) + "/l1/accesses", acc[tm], "a");
    }
    r.add_sum("chip/l1/misses", "*/l1/misses", "all misses");
    r.add_sum("chip/l1/accesses", "*/l1/accesses", "all accesses");
    r.add_ratio("chip/l1/miss_rate", "chip/l1/misses", "chip/l1/accesses", "rate");
    uint64_t zero = 0;
    r.add_counter("z", zero, "zero");
    r.add_ratio("zero_ratio", "chip/l1/misses", "z", "guarded");
    miss[2] = 7;  // sums are live, not snapshots
    CHECK(r.at("chip/l1/misses").is_integer());
    CHECK(r.at("chip/l1/misses").integer() == 10);
    CHECK(r.value("chip/l1/miss_rate") == Approx(10.0 / 40.0));
    CHECK(r.value("zero_ratio") == 0.0);
    CHECK_THROWS_WITH(r.add_sum("s", "nothing/*", "d"), Catch::Contains("no registered"));
}

TEST_CASE("a snapshot keeps the values of its moment; intervals subtract counters", "[stats]") {
    Registry r;
    uint64_t hits = 10, reads = 40;
    r.add_counter("l1/hits", hits, "hits");
    r.add_counter("l1/reads", reads, "reads");
    r.add_ratio("l1/hit_rate", "l1/hits", "l1/reads", "rate");
    const Snapshot before(r);
    hits = 25;
    reads = 50;
    const Snapshot after(r);
    CHECK(before.at("l1/hits").integer == 10);  // unchanged by the later increments
    CHECK(after.value("l1/hit_rate") == Approx(0.5));
    const Snapshot interval = after.since(before);
    CHECK(interval.at("l1/hits").integer == 15);
    CHECK(interval.at("l1/reads").integer == 10);
    CHECK(std::isnan(interval.value("l1/hit_rate")));  // ratios are not additive
    Registry other;
    other.add_counter("x", hits, "x");
    CHECK_THROWS_AS(after.since(Snapshot(other)), std::invalid_argument);
    CHECK_THROWS_AS(after.at("nope"), std::out_of_range);
}

TEST_CASE("JSON values are exact, ordered, and non-finite reals are null", "[stats]") {
    Registry r;
    uint64_t a = 5, big = UINT64_MAX;
    double host = 0.1;
    r.add_counter("b/first", a, "desc with \"quotes\"", "B");
    r.add_number("a/second", host, "host seconds", "s");
    r.add_derived(
        "c/nan", [] { return 0.0 / 0.0; }, "not a number");
    r.add_counter("d/big", big, "largest counter");
    const Snapshot snapshot(r);
    const std::string text = values_json(snapshot).dump();
    CHECK(text == R"({"b/first":5,"a/second":0.1,"c/nan":null,"d/big":18446744073709551615})");
    const auto parsed = nlohmann::json::parse(text);
    CHECK(parsed["d/big"].get<uint64_t>() == UINT64_MAX);
    CHECK(parsed["a/second"].get<double>() == 0.1);  // the shortest form round-trips
    CHECK(units_json(snapshot).dump() == R"({"b/first":"B","a/second":"s"})");
}

TEST_CASE("text output aligns values in one column", "[stats]") {
    Registry r;
    uint64_t a = 5, b = 12345;
    r.add_counter("short", a, "one");
    r.add_counter("a/much/longer/name", b, "two", "cycles");
    std::ostringstream out;
    print_text(Snapshot(r), out);
    std::istringstream lines(out.str());
    std::string first, second;
    std::getline(lines, first);
    std::getline(lines, second);
    // Values are right-aligned: both end at the same column.
    CHECK(first.find("5 ") == second.find("12345 ") + 4);
    CHECK(second.find("# two") == first.find("# one"));
}
