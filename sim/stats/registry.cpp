#include "sim/stats/registry.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <ostream>
#include <stdexcept>

namespace tpsim::stats {

namespace {

bool valid_name(std::string_view name) {
    if (name.empty() || name.front() == '/' || name.back() == '/' ||
        name.find("//") != std::string_view::npos)
        return false;
    return std::all_of(name.begin(), name.end(), [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
               c == '_' || c == '/' || c == '-' || c == '.';
    });
}

// Integers print exactly; reals with the shortest representation that round-trips, so the
// output is identical for identical inputs on any host.
std::string format_value(const Value& v) {
    return v.is_integer ? fmt::format("{}", v.integer) : fmt::format("{}", v.real);
}

}  // namespace

bool matches(std::string_view pattern, std::string_view name) {
    while (true) {
        const size_t p_end = pattern.find('/');
        const size_t n_end = name.find('/');
        const std::string_view p_seg = pattern.substr(0, p_end);
        const std::string_view n_seg = name.substr(0, n_end);
        if (p_seg != "*" && p_seg != n_seg) return false;
        if (p_end == std::string_view::npos || n_end == std::string_view::npos)
            return p_end == n_end;
        pattern.remove_prefix(p_end + 1);
        name.remove_prefix(n_end + 1);
    }
}

void Registry::add(Entry entry) {
    if (!valid_name(entry.name))
        throw std::invalid_argument(fmt::format(
            "statistic name '{}' is malformed: use '/'-separated segments of [A-Za-z0-9_.-]",
            entry.name));
    if (contains(entry.name))
        throw std::invalid_argument(fmt::format(
            "statistic '{}' is registered twice: register each counter once", entry.name));
    entries_.push_back(std::move(entry));
}

void Registry::add_counter(std::string name, const uint64_t& counter, std::string description,
                           std::string unit) {
    const uint64_t* p = &counter;
    add({std::move(name), std::move(description), std::move(unit), [p] { return *p; }, {}});
}

void Registry::add_number(std::string name, const double& number, std::string description,
                          std::string unit) {
    const double* p = &number;
    add({std::move(name), std::move(description), std::move(unit), {}, [p] { return *p; }});
}

void Registry::add_derived(std::string name, std::function<double()> derive,
                           std::string description, std::string unit) {
    add({std::move(name), std::move(description), std::move(unit), {}, std::move(derive)});
}

void Registry::add_ratio(std::string name, std::string_view numerator, std::string_view denominator,
                         std::string description, std::string unit) {
    // Copy the accessors so the ratio stays valid however entries_ grows.
    const Entry num = at(numerator);
    const Entry den = at(denominator);
    add_derived(
        std::move(name),
        [num, den] {
            const double d = den.value();
            return d == 0 ? 0.0 : num.value() / d;
        },
        std::move(description), std::move(unit));
}

void Registry::add_sum(std::string name, std::string_view pattern, std::string description,
                       std::string unit) {
    std::vector<Entry> parts;
    for (const Entry& e : entries_)
        if (matches(pattern, e.name)) parts.push_back(e);
    if (parts.empty())
        throw std::invalid_argument(
            fmt::format("statistic sum '{}': no registered statistic matches '{}'", name, pattern));
    const bool all_integer =
        std::all_of(parts.begin(), parts.end(), [](const Entry& e) { return e.is_integer(); });
    if (all_integer) {
        add({std::move(name),
             std::move(description),
             std::move(unit),
             [parts] {
                 uint64_t sum = 0;
                 for (const Entry& e : parts)
                     sum += e.integer();
                 return sum;
             },
             {}});
    } else {
        add_derived(
            std::move(name),
            [parts] {
                double sum = 0;
                for (const Entry& e : parts)
                    sum += e.value();
                return sum;
            },
            std::move(description), std::move(unit));
    }
}

const Entry& Registry::at(std::string_view name) const {
    for (const Entry& e : entries_)
        if (e.name == name) return e;
    throw std::out_of_range(fmt::format("no statistic named '{}' is registered", name));
}

bool Registry::contains(std::string_view name) const {
    return std::any_of(entries_.begin(), entries_.end(),
                       [&](const Entry& e) { return e.name == name; });
}

Snapshot::Snapshot(const Registry& registry) {
    values_.reserve(registry.entries().size());
    for (const Entry& e : registry.entries()) {
        Value v{e.name, e.description, e.unit, e.is_integer()};
        if (v.is_integer)
            v.integer = e.integer();
        else
            v.real = e.real();
        values_.push_back(std::move(v));
    }
}

const Value& Snapshot::at(std::string_view name) const {
    for (const Value& v : values_)
        if (v.name == name) return v;
    throw std::out_of_range(fmt::format("no statistic named '{}' in the snapshot", name));
}

Snapshot Snapshot::since(const Snapshot& earlier) const {
    if (earlier.values_.size() != values_.size())
        throw std::invalid_argument(
            "Snapshot::since: the snapshots come from different registries");
    Snapshot interval = *this;
    for (size_t i = 0; i < values_.size(); ++i) {
        Value& v = interval.values_[i];
        if (earlier.values_[i].name != v.name)
            throw std::invalid_argument(
                fmt::format("Snapshot::since: '{}' against '{}': different registries", v.name,
                            earlier.values_[i].name));
        if (v.is_integer)
            v.integer -= earlier.values_[i].integer;
        else
            v.real = std::numeric_limits<double>::quiet_NaN();
    }
    return interval;
}

void print_text(const Snapshot& snapshot, std::ostream& out) {
    size_t name_width = 0, value_width = 0, unit_width = 0;
    std::vector<std::string> values;
    for (const Value& v : snapshot.values()) {
        values.push_back(format_value(v));
        name_width = std::max(name_width, v.name.size());
        value_width = std::max(value_width, values.back().size());
        unit_width = std::max(unit_width, v.unit.size());
    }
    for (size_t i = 0; i < values.size(); ++i) {
        const Value& v = snapshot.values()[i];
        out << fmt::format("{:<{}}  {:>{}} {:<{}}  # {}\n", v.name, name_width, values[i],
                           value_width, v.unit, unit_width, v.description);
    }
}

nlohmann::ordered_json values_json(const Snapshot& snapshot) {
    // nlohmann writes doubles in their shortest round-trip form and non-finite ones as null.
    nlohmann::ordered_json values = nlohmann::ordered_json::object();
    for (const Value& v : snapshot.values()) {
        if (v.is_integer)
            values[v.name] = v.integer;
        else
            values[v.name] = v.real;
    }
    return values;
}

nlohmann::ordered_json units_json(const Snapshot& snapshot) {
    nlohmann::ordered_json units = nlohmann::ordered_json::object();
    for (const Value& v : snapshot.values())
        if (!v.unit.empty()) units[v.name] = v.unit;
    return units;
}

}  // namespace tpsim::stats
