#include "stats/registry.hpp"

#include <catch2/catch.hpp>

#include <cctype>
#include <sstream>
#include <string>

using namespace tpsim::stats;

namespace {

// A strict recursive-descent recogniser for the JSON subset print_json may emit (objects,
// strings, numbers, null), so the test fails if the printer ever emits invalid JSON.
struct JsonChecker {
    std::string_view s;
    size_t i = 0;
    void ws() { while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i; }
    bool lit(std::string_view t) {
        if (s.substr(i, t.size()) != t) return false;
        i += t.size();
        return true;
    }
    bool string() {
        if (!lit("\"")) return false;
        while (i < s.size() && s[i] != '"') {
            if (static_cast<unsigned char>(s[i]) < 0x20) return false;
            if (s[i] == '\\') ++i;
            ++i;
        }
        return lit("\"");
    }
    bool number() {
        const size_t start = i;
        if (i < s.size() && s[i] == '-') ++i;
        while (i < s.size() && (std::isdigit(static_cast<unsigned char>(s[i])) || s[i] == '.' ||
                                s[i] == 'e' || s[i] == 'E' || s[i] == '+' || s[i] == '-'))
            ++i;
        return i > start && std::isdigit(static_cast<unsigned char>(s[i - 1]));
    }
    bool value() {
        ws();
        if (i < s.size() && s[i] == '"') return string();
        if (lit("null")) return true;
        if (i < s.size() && s[i] == '{') return object();
        return number();
    }
    bool object() {
        if (!lit("{")) return false;
        ws();
        if (lit("}")) return true;
        do {
            ws();
            if (!string()) return false;
            ws();
            if (!lit(":") || !value()) return false;
            ws();
        } while (lit(","));
        return lit("}");
    }
    bool document() {
        const bool ok = value();
        ws();
        return ok && i == s.size();
    }
};

}  // namespace

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

TEST_CASE("JSON output is valid, ordered, and escapes names", "[stats]") {
    Registry r;
    uint64_t a = 5;
    double host = 0.25;
    r.add_counter("b/first", a, "desc with \"quotes\"");
    r.add_number("a/second", host, "host seconds", "s");
    r.add_derived("c/nan", [] { return 0.0 / 0.0; }, "not a number");
    std::ostringstream out;
    print_json(r, out);
    const std::string json = out.str();
    CHECK(JsonChecker{json}.document());
    CHECK(json.find("\"b/first\": 5") < json.find("\"a/second\": 0.25"));
    CHECK(json.find("\"c/nan\": null") != std::string::npos);
    CHECK_FALSE(JsonChecker{"{\"a\": }"}.document());  // the checker itself can fail
}

TEST_CASE("text output aligns values in one column", "[stats]") {
    Registry r;
    uint64_t a = 5, b = 12345;
    r.add_counter("short", a, "one");
    r.add_counter("a/much/longer/name", b, "two", "cycles");
    std::ostringstream out;
    print_text(r, out);
    std::istringstream lines(out.str());
    std::string first, second;
    std::getline(lines, first);
    std::getline(lines, second);
    // Values are right-aligned: both end at the same column.
    CHECK(first.find("5 ") == second.find("12345 ") + 4);
    CHECK(second.find("# two") == first.find("# one"));
}
