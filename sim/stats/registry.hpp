// Statistics registry: counters live as plain uint64_t fields inside the components that bump
// them (no lookups at run time); they are registered once, by address, under hierarchical names
// such as "tm3/l1/misses". A Snapshot reads them all at one moment as plain values, which can
// be subtracted (intervals) and are what the printers (text, JSON) and the analysis tools see.
#pragma once
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace tpsim::stats {

/// One registered statistic: an integer (counters and sums of counters, printed exactly) or a
/// real number (ratios, rates, host time). Values are read when printed, never cached.
struct Entry {
    std::string name;                   ///< hierarchical, '/'-separated, e.g. "tm0/l1/hits"
    std::string description;            ///< one line, shown in the text report
    std::string unit;                   ///< e.g. "cycles", "B/cycle"; empty if dimensionless
    std::function<uint64_t()> integer;  ///< set for integer entries
    std::function<double()> real;       ///< set for real entries
    /// Integers that add up over time (counters and their sums: an interval subtracts them)
    /// or a level read at one moment (a high-water mark).
    bool additive = true;
    /// A sum or formula: the entries (by index, registered earlier) it is computed from, and
    /// how (formulas; none: the sum of the inputs). Registry::derive() recomputes it from any
    /// snapshot's values, e.g. from estimated counters.
    std::vector<size_t> inputs;
    std::function<double(std::span<const double>)> formula;

    bool is_integer() const { return static_cast<bool>(integer); }
    double value() const { return integer ? static_cast<double>(integer()) : real(); }
};

class Snapshot;

/// Registered statistics in registration order (that order is the print order, so output is
/// deterministic). Entries point at storage owned elsewhere: keep the owners alive while
/// printing.
class Registry {
public:
    /// Registers an integer counter. Throws std::invalid_argument on a malformed or duplicate name.
    void add_counter(std::string name, const uint64_t& counter, std::string description,
                     std::string unit = "");
    /// Registers a real-valued quantity that the caller updates (e.g. host seconds).
    void add_number(std::string name, const double& number, std::string description,
                    std::string unit = "");
    /// Registers an integer level, not a count: a high-water mark. An interval keeps its
    /// later value.
    void add_level(std::string name, const uint64_t& level, std::string description,
                   std::string unit = "");
    /// Registers a value read when printed that depends on no other statistic (a property of
    /// the run: scene size, host seconds).
    void add_derived(std::string name, std::function<double()> derive, std::string description,
                     std::string unit = "");
    /// Registers a value computed from already registered entries (rates, utilisations):
    /// `formula` gets their values in the order of `inputs`. Throws std::out_of_range for an
    /// unknown input.
    void add_formula(std::string name, const std::vector<std::string_view>& inputs,
                     std::function<double(std::span<const double>)> formula,
                     std::string description, std::string unit = "");
    /// numerator / denominator of two already registered entries; 0 when the denominator is 0.
    void add_ratio(std::string name, std::string_view numerator, std::string_view denominator,
                   std::string description, std::string unit = "");
    /// Sum of every already registered entry whose name matches `pattern` (matches: "*/l1/misses",
    /// "tm*/l1/misses"). An integer when all parts are integers.
    /// Throws std::invalid_argument if nothing matches.
    void add_sum(std::string name, std::string_view pattern, std::string description,
                 std::string unit = "");

    const std::vector<Entry>& entries() const { return entries_; }
    /// `values` (a snapshot of this registry whose counters may have been replaced, e.g. by
    /// estimates) with every sum and formula recomputed from them, in registration order.
    Snapshot derive(Snapshot values) const;
    /// The entry called `name`; throws std::out_of_range naming it if absent.
    const Entry& at(std::string_view name) const;
    /// Index of the entry called `name` in entries(); throws std::out_of_range naming it.
    size_t index(std::string_view name) const;
    bool contains(std::string_view name) const;
    double value(std::string_view name) const { return at(name).value(); }

private:
    void add(Entry entry);
    std::vector<Entry> entries_;
};

/// True when `name` matches `pattern` segment by segment: '*' matches any one segment, "tm*"
/// one TM's ("tm" and digits, so never a chip-wide "chip/..." sum).
bool matches(std::string_view pattern, std::string_view name);

/// One statistic's value at one moment.
struct Value {
    std::string name, description, unit;
    bool is_integer = false;
    bool additive = true;  ///< Entry::additive
    uint64_t integer = 0;  ///< when is_integer
    double real = 0;       ///< otherwise

    double value() const { return is_integer ? static_cast<double>(integer) : real; }
};

/// Every registered statistic read at one moment, in registration order.
class Snapshot {
public:
    Snapshot() = default;
    explicit Snapshot(const Registry& registry);

    const std::vector<Value>& values() const { return values_; }
    std::vector<Value>& values() { return values_; }
    /// The value called `name`; throws std::out_of_range naming it if absent.
    const Value& at(std::string_view name) const;
    double value(std::string_view name) const { return at(name).value(); }

    /// The interval from `earlier` to this snapshot of the same registry: counters and their
    /// sums subtract, levels keep this snapshot's value; reals (ratios, rates, host times) are
    /// not additive and become NaN (Registry::derive() recomputes the formulas).
    Snapshot since(const Snapshot& earlier) const;

private:
    std::vector<Value> values_;
};

/// Aligned human-readable report: name, value, unit, description; one line per value.
void print_text(const Snapshot& snapshot, std::ostream& out);
/// {"name": value, ...} in registration order: integers exact, reals in their shortest
/// round-trip form, non-finite ones null (the "stats" object of the statistics file).
nlohmann::ordered_json values_json(const Snapshot& snapshot);
/// {"name": "unit", ...} for every value that has a unit (the "units" object).
nlohmann::ordered_json units_json(const Snapshot& snapshot);

}  // namespace tpsim::stats
