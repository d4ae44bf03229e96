#include "sim/stats/registry.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
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

/// An entry with its name and texts; the caller sets how its value is read.
Entry leaf(std::string name, std::string description, std::string unit) {
    Entry entry;
    entry.name = std::move(name);
    entry.description = std::move(description);
    entry.unit = std::move(unit);
    return entry;
}

}  // namespace

bool matches(std::string_view pattern, std::string_view name) {
    while (true) {
        const size_t p_end = pattern.find('/');
        const size_t n_end = name.find('/');
        const std::string_view p_seg = pattern.substr(0, p_end);
        const std::string_view n_seg = name.substr(0, n_end);
        const bool one_tm = p_seg == "tm*" && n_seg.size() > 2 && n_seg.starts_with("tm") &&
                            n_seg.find_first_not_of("0123456789", 2) == std::string_view::npos;
        if (p_seg != "*" && !one_tm && p_seg != n_seg) return false;
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
    Entry entry = leaf(std::move(name), std::move(description), std::move(unit));
    entry.integer = [p] { return *p; };
    add(std::move(entry));
}

void Registry::add_level(std::string name, const uint64_t& level, std::string description,
                         std::string unit) {
    const uint64_t* p = &level;
    Entry entry = leaf(std::move(name), std::move(description), std::move(unit));
    entry.integer = [p] { return *p; };
    entry.additive = false;
    add(std::move(entry));
}

void Registry::add_number(std::string name, const double& number, std::string description,
                          std::string unit) {
    const double* p = &number;
    Entry entry = leaf(std::move(name), std::move(description), std::move(unit));
    entry.real = [p] { return *p; };
    add(std::move(entry));
}

void Registry::add_derived(std::string name, std::function<double()> derive,
                           std::string description, std::string unit) {
    Entry entry = leaf(std::move(name), std::move(description), std::move(unit));
    entry.real = std::move(derive);
    add(std::move(entry));
}

void Registry::add_formula(std::string name, const std::vector<std::string_view>& inputs,
                           std::function<double(std::span<const double>)> formula,
                           std::string description, std::string unit) {
    Entry entry = leaf(std::move(name), std::move(description), std::move(unit));
    std::vector<Entry> parts;  // copies: the live value stays valid however entries_ grows
    for (std::string_view input : inputs) {
        entry.inputs.push_back(index(input));
        parts.push_back(entries_[entry.inputs.back()]);
    }
    entry.real = [parts, formula] {
        std::vector<double> values;
        for (const Entry& part : parts)
            values.push_back(part.value());
        return formula(values);
    };
    entry.formula = std::move(formula);
    add(std::move(entry));
}

void Registry::add_ratio(std::string name, std::string_view numerator, std::string_view denominator,
                         std::string description, std::string unit) {
    add_formula(
        std::move(name), {numerator, denominator},
        [](std::span<const double> v) { return v[1] == 0 ? 0.0 : v[0] / v[1]; },
        std::move(description), std::move(unit));
}

void Registry::add_sum(std::string name, std::string_view pattern, std::string description,
                       std::string unit) {
    std::vector<Entry> parts;
    std::vector<size_t> inputs;
    for (size_t i = 0; i < entries_.size(); ++i)
        if (matches(pattern, entries_[i].name)) {
            parts.push_back(entries_[i]);
            inputs.push_back(i);
        }
    if (parts.empty())
        throw std::invalid_argument(
            fmt::format("statistic sum '{}': no registered statistic matches '{}'", name, pattern));
    const bool all_integer =
        std::all_of(parts.begin(), parts.end(), [](const Entry& e) { return e.is_integer(); });
    Entry entry = leaf(std::move(name), std::move(description), std::move(unit));
    if (all_integer)
        entry.integer = [parts] {
            uint64_t sum = 0;
            for (const Entry& e : parts)
                sum += e.integer();
            return sum;
        };
    else
        entry.real = [parts] {
            double sum = 0;
            for (const Entry& e : parts)
                sum += e.value();
            return sum;
        };
    entry.inputs = std::move(inputs);
    add(std::move(entry));
}

size_t Registry::index(std::string_view name) const {
    for (size_t i = 0; i < entries_.size(); ++i)
        if (entries_[i].name == name) return i;
    throw std::out_of_range(fmt::format("no statistic named '{}' is registered", name));
}

Snapshot Registry::derive(Snapshot values) const {
    std::vector<Value>& v = values.values();
    if (v.size() != entries_.size())
        throw std::invalid_argument("Registry::derive: the snapshot comes from another registry");
    std::vector<double> inputs;
    for (size_t i = 0; i < entries_.size(); ++i) {
        const Entry& e = entries_[i];
        if (e.inputs.empty()) continue;
        if (!e.formula && v[i].is_integer) {
            uint64_t sum = 0;
            for (size_t input : e.inputs)
                sum += v[input].integer;
            v[i].integer = sum;
            continue;
        }
        inputs.clear();
        for (size_t input : e.inputs)
            inputs.push_back(v[input].value());
        v[i].real =
            e.formula ? e.formula(inputs) : std::accumulate(inputs.begin(), inputs.end(), 0.0);
    }
    return values;
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
        Value v{e.name, e.description, e.unit, e.is_integer(), e.additive};
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
        if (v.is_integer && v.additive)
            v.integer -= earlier.values_[i].integer;
        else if (v.is_integer)
            continue;  // a level: its value at the end of the interval
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
