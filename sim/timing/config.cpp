#include "sim/timing/config.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <toml++/toml.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <optional>
#include <type_traits>

#include "sim/core/input_file.hpp"
#include "sim/core/toml_nesting.hpp"

namespace tpsim::timing {

namespace {

/// A chip config is a page of keys; anything bigger is not one.
constexpr std::uintmax_t kMaxConfigBytes = 1 << 20;

struct Range {
    uint32_t min, max;
};

// The one list of configurable fields: key, storage and allowed range. Loading, overriding,
// validation and printing all walk it, so a field cannot be forgotten by one of them.
template <class Config, class Visit> void for_each_field(Config& c, Visit&& visit) {
    constexpr uint32_t kMaxLatency = 100000;
    visit("chip.clock_mhz", c.chip.clock_mhz, Range{1, 100000});
    visit("chip.num_tms", c.chip.num_tms, Range{1, 4096});
    visit("chip.tps_per_tm", c.chip.tps_per_tm, Range{1, 1024});
    visit("chip.tms_per_l2", c.chip.tms_per_l2, Range{1, 4096});
    visit("tp.branch_taken_penalty", c.tp.branch_taken_penalty, Range{0, 1000});
    visit("tp.branch_not_taken_penalty", c.tp.branch_not_taken_penalty, Range{0, 1000});
    // The functional machine's limits (sim/core/memory.cpp), so a bad size is reported here.
    visit("tp.local_store_bytes", c.tp.local_store_bytes, Range{256, 1u << 20});
    visit("tp.local_store_latency", c.tp.local_store_latency, Range{1, kMaxLatency});
    auto pool = [&](std::string_view name, auto& fu) {
        visit(fmt::format("fu.{}.count", name), fu.count, Range{1, 1024});
        visit(fmt::format("fu.{}.latency", name), fu.latency, Range{1, kMaxLatency});
        visit(fmt::format("fu.{}.pipelined", name), fu.pipelined, Range{0, 1});
    };
    pool("int_alu", c.fu.int_alu);
    pool("int_muldiv", c.fu.int_muldiv);
    pool("fp_add", c.fu.fp_add);
    pool("fp_mul", c.fu.fp_mul);
    pool("fp_divsqrt", c.fu.fp_divsqrt);
    pool("fp_misc", c.fu.fp_misc);
    pool("branch", c.fu.branch);
    pool("load_store", c.fu.load_store);
    pool("atomic", c.fu.atomic);
    visit("icache.threads_per_icache", c.icache.threads_per_icache, Range{1, 1024});
    visit("icache.banks", c.icache.banks, Range{1, 1024});
    visit("icache.size_bytes", c.icache.size_bytes, Range{0, 1u << 30});
    visit("icache.ways", c.icache.ways, Range{1, 64});
    visit("icache.line_bytes", c.icache.line_bytes, Range{4, 4096});
    visit("icache.mshrs", c.icache.mshrs, Range{1, 4096});
    auto cache = [&](std::string_view name, auto& cc) {
        visit(fmt::format("{}.size_bytes", name), cc.size_bytes, Range{64, 1u << 30});
        visit(fmt::format("{}.ways", name), cc.ways, Range{1, 64});
        visit(fmt::format("{}.line_bytes", name), cc.line_bytes, Range{4, 4096});
        visit(fmt::format("{}.banks", name), cc.banks, Range{1, 1024});
        visit(fmt::format("{}.hit_latency", name), cc.hit_latency, Range{1, kMaxLatency});
        visit(fmt::format("{}.mshrs", name), cc.mshrs, Range{1, 4096});
    };
    cache("l1", c.l1);
    cache("l2", c.l2);
    visit("l2.write_combining_lines", c.l2.write_combining_lines, Range{0, 4096});
    visit("dram.channels", c.dram.channels, Range{1, 256});
    visit("dram.banks", c.dram.banks, Range{1, 256});
    visit("dram.row_bytes", c.dram.row_bytes, Range{64, 1u << 20});
    visit("dram.queue_depth", c.dram.queue_depth, Range{1, 4096});
    visit("dram.tRCD", c.dram.tRCD, Range{1, 1000});
    visit("dram.tCL", c.dram.tCL, Range{1, 1000});
    visit("dram.tCWL", c.dram.tCWL, Range{1, 1000});
    visit("dram.tRP", c.dram.tRP, Range{1, 1000});
    visit("dram.tRAS", c.dram.tRAS, Range{1, 1000});
    visit("dram.tBURST", c.dram.tBURST, Range{1, 1000});
    visit("dram.tCCD", c.dram.tCCD, Range{1, 1000});
    visit("dram.tRRD", c.dram.tRRD, Range{1, 1000});
    visit("dram.tWR", c.dram.tWR, Range{1, 1000});
    visit("dram.tWTR", c.dram.tWTR, Range{1, 1000});
    visit("dram.tRTP", c.dram.tRTP, Range{1, 1000});
    visit("global_registers.latency", c.global_registers.latency, Range{1, kMaxLatency});
    visit("global_registers.per_cycle", c.global_registers.per_cycle, Range{1, 1024});
    visit("global_registers.link_latency", c.global_registers.link_latency, Range{1, kMaxLatency});
    // Costs are real numbers >= 0 (0 leaves a part out of the estimate); the exponents of the
    // SRAM scaling rule stay in 0..2 (CACTI's fitted ones are below 1).
    constexpr Range kCost{0, 1000000000};
    constexpr Range kExponent{0, 2};
    visit("energy.int_alu_pj", c.energy.int_alu_pj, kCost);
    visit("energy.int_muldiv_pj", c.energy.int_muldiv_pj, kCost);
    visit("energy.fp_add_pj", c.energy.fp_add_pj, kCost);
    visit("energy.fp_mul_pj", c.energy.fp_mul_pj, kCost);
    visit("energy.fp_divsqrt_pj", c.energy.fp_divsqrt_pj, kCost);
    visit("energy.fp_misc_pj", c.energy.fp_misc_pj, kCost);
    visit("energy.branch_pj", c.energy.branch_pj, kCost);
    visit("energy.load_store_pj", c.energy.load_store_pj, kCost);
    visit("energy.atomic_pj", c.energy.atomic_pj, kCost);
    visit("energy.register_access_pj", c.energy.register_access_pj, kCost);
    visit("energy.local_store_access_pj", c.energy.local_store_access_pj, kCost);
    visit("energy.icache_fetch_pj", c.energy.icache_fetch_pj, kCost);
    visit("energy.l1_access_pj", c.energy.l1_access_pj, kCost);
    visit("energy.l2_access_pj", c.energy.l2_access_pj, kCost);
    visit("energy.sram_size_exponent", c.energy.sram_size_exponent, kExponent);
    visit("energy.sram_bank_exponent", c.energy.sram_bank_exponent, kExponent);
    visit("energy.dram_activate_pj", c.energy.dram_activate_pj, kCost);
    visit("energy.dram_read_pj", c.energy.dram_read_pj, kCost);
    visit("energy.dram_write_pj", c.energy.dram_write_pj, kCost);
    visit("energy.dram_background_mw", c.energy.dram_background_mw, kCost);
    visit("area.int_alu_um2", c.area.int_alu_um2, kCost);
    visit("area.int_muldiv_um2", c.area.int_muldiv_um2, kCost);
    visit("area.fp_add_um2", c.area.fp_add_um2, kCost);
    visit("area.fp_mul_um2", c.area.fp_mul_um2, kCost);
    visit("area.fp_divsqrt_um2", c.area.fp_divsqrt_um2, kCost);
    visit("area.fp_misc_um2", c.area.fp_misc_um2, kCost);
    visit("area.branch_um2", c.area.branch_um2, kCost);
    visit("area.load_store_um2", c.area.load_store_um2, kCost);
    visit("area.atomic_um2", c.area.atomic_um2, kCost);
    visit("area.register_file_um2", c.area.register_file_um2, kCost);
    visit("area.local_store_um2", c.area.local_store_um2, kCost);
    visit("area.icache_um2", c.area.icache_um2, kCost);
    visit("area.l1_um2", c.area.l1_um2, kCost);
    visit("area.l2_um2", c.area.l2_um2, kCost);
    visit("area.sram_size_exponent", c.area.sram_size_exponent, kExponent);
    visit("area.sram_bank_exponent", c.area.sram_bank_exponent, kExponent);
}

template <class T> constexpr bool kIsBool = std::is_same_v<std::remove_cvref_t<T>, bool>;
template <class T> constexpr bool kIsReal = std::is_same_v<std::remove_cvref_t<T>, double>;

std::string range_text(bool is_bool, Range r) {
    return is_bool ? "true or false" : fmt::format("{}..{}", r.min, r.max);
}

/// A value read from TOML or an override, as whichever of the three kinds it parsed as.
struct Parsed {
    std::optional<bool> as_bool;
    std::optional<int64_t> as_int;
    std::optional<double> as_real;  ///< also set for an integer: a real field takes both
};

// Sets `key` to a parsed value; returns false if no such key.
// `where` prefixes every error ("file:line" or "override 'k=v'").
bool assign(ChipConfig& config, std::string_view key, const Parsed& value, std::string_view where) {
    bool found = false;
    const auto [as_bool, as_int, as_real] = value;
    for_each_field(config, [&](std::string_view name, auto& field, Range range) {
        if (name != key) return;
        found = true;
        if constexpr (kIsBool<decltype(field)>) {
            if (!as_bool)
                throw ConfigError(fmt::format("{}: {} must be true or false", where, key));
            field = *as_bool;
        } else if constexpr (kIsReal<decltype(field)>) {
            if (!as_real || !std::isfinite(*as_real))
                throw ConfigError(fmt::format("{}: {} must be a number in {}", where, key,
                                              range_text(false, range)));
            if (*as_real < range.min || *as_real > range.max)
                throw ConfigError(fmt::format("{}: {} = {} is out of range; allowed {}", where, key,
                                              *as_real, range_text(false, range)));
            field = *as_real;
        } else {
            if (!as_int)
                throw ConfigError(fmt::format("{}: {} must be an integer in {}", where, key,
                                              range_text(false, range)));
            if (*as_int < range.min || *as_int > range.max)
                throw ConfigError(fmt::format("{}: {} = {} is out of range; allowed {}", where, key,
                                              *as_int, range_text(false, range)));
            field = static_cast<uint32_t>(*as_int);
        }
    });
    return found;
}

/// The error for a key no field has, listing the valid keys of its section (or the sections).
[[noreturn]] void unknown_key(std::string_view where, std::string_view key) {
    const std::string_view section = key.substr(0, key.rfind('.') + 1);  // "l1." or ""
    std::vector<std::string> keys, sections;
    ChipConfig defaults;
    for_each_field(defaults, [&](std::string_view name, auto&, Range) {
        const std::string_view head = name.substr(0, name.rfind('.'));
        if (sections.empty() || sections.back() != head) sections.emplace_back(head);
        if (!section.empty() && name.starts_with(section))
            keys.emplace_back(name.substr(section.size()));
    });
    throw ConfigError(keys.empty() ? fmt::format("{}: unknown key '{}'; the sections are {}", where,
                                                 key, fmt::join(sections, ", "))
                                   : fmt::format("{}: unknown key '{}'; valid keys in [{}] are {}",
                                                 where, key, section.substr(0, section.size() - 1),
                                                 fmt::join(keys, ", ")));
}

void load_table(ChipConfig& config, const toml::table& table, const std::string& prefix,
                std::string_view source_name) {
    for (const auto& [k, node] : table) {
        const std::string key =
            prefix.empty() ? std::string(k.str()) : fmt::format("{}.{}", prefix, k.str());
        const std::string where = fmt::format("{}:{}", source_name, node.source().begin.line);
        if (const toml::table* sub = node.as_table()) {
            load_table(config, *sub, key, source_name);
            continue;
        }
        Parsed value;
        if (auto b = node.value_exact<bool>()) value.as_bool = *b;
        if (auto i = node.value_exact<int64_t>()) value.as_int = *i;
        if (auto r = node.value<double>()) value.as_real = *r;  // a float, or an integer
        if (!assign(config, key, value, where)) unknown_key(where, key);
    }
}

bool is_pow2(uint32_t v) {
    return std::has_single_bit(v);
}

void check(bool ok, std::string_view message) {
    if (!ok) throw ConfigError(std::string(message));
}

void validate_cache(const CacheConfig& c, std::string_view name) {
    check(is_pow2(c.line_bytes),
          fmt::format("{}.line_bytes = {} must be a power of two", name, c.line_bytes));
    const uint64_t set_bytes = uint64_t{c.ways} * c.line_bytes;
    check(c.size_bytes % set_bytes == 0 && is_pow2(static_cast<uint32_t>(c.size_bytes / set_bytes)),
          fmt::format("{0}.size_bytes = {1} must be a power-of-two multiple of {0}.ways x "
                      "{0}.line_bytes = {2}",
                      name, c.size_bytes, set_bytes));
}

}  // namespace

void validate(const ChipConfig& config) {
    // Ranges first (a config built in code may not have come through the loader).
    for_each_field(config, [](std::string_view name, const auto& field, Range range) {
        if constexpr (kIsReal<decltype(field)>)
            check(std::isfinite(field) && field >= range.min && field <= range.max,
                  fmt::format("{} = {} is out of range; allowed {}", name, field,
                              range_text(false, range)));
        else if constexpr (!kIsBool<decltype(field)>)
            check(field >= range.min && field <= range.max,
                  fmt::format("{} = {} is out of range; allowed {}", name, field,
                              range_text(false, range)));
    });
    validate_cache(config.l1, "l1");
    validate_cache(config.l2, "l2");
    if (config.icache.finite()) {
        validate_cache(icache_lines_config(config.icache), "icache");
        check(config.icache.line_bytes == config.l1.line_bytes,
              fmt::format("icache.line_bytes = {} must equal l1.line_bytes = {} (one line size "
                          "throughout the hierarchy)",
                          config.icache.line_bytes, config.l1.line_bytes));
    }
    check(config.l1.line_bytes == config.l2.line_bytes,
          fmt::format("l2.line_bytes = {} must equal l1.line_bytes = {} (one line size "
                      "throughout the hierarchy)",
                      config.l2.line_bytes, config.l1.line_bytes));
    check(is_pow2(config.dram.row_bytes) && config.dram.row_bytes >= config.l2.line_bytes,
          fmt::format("dram.row_bytes = {} must be a power of two >= l2.line_bytes = {}",
                      config.dram.row_bytes, config.l2.line_bytes));
    check(config.tp.local_store_bytes % 16 == 0,
          fmt::format("tp.local_store_bytes = {} must be a multiple of 16 (stack alignment)",
                      config.tp.local_store_bytes));
    check(config.dram.tRAS >= config.dram.tRCD,
          fmt::format("dram.tRAS = {} must be >= dram.tRCD = {}", config.dram.tRAS,
                      config.dram.tRCD));
    const std::vector<HostBytes> parts = host_bytes(config);
    uint64_t total = 0;
    for (const HostBytes& part : parts)
        total += part.bytes;
    constexpr double kGiB = double(uint64_t(1) << 30);
    check(total <= kMaxHostBytes,
          fmt::format("the chip needs about {:.1f} GiB of host memory, more than the {:.0f} GiB "
                      "tpsim allows; {:.1f} GiB of it is {}: reduce {}",
                      double(total) / kGiB, double(kMaxHostBytes) / kGiB,
                      double(parts.front().bytes) / kGiB, parts.front().part, parts.front().field));
}

std::vector<HostBytes> host_bytes(const ChipConfig& config) {
    // Per cache line: its tag/state entry (Cache::Way: line, valid, LRU stamp).
    constexpr uint64_t kPerLine = 16;
    // Per thread: the machine's thread state and the timing model's run-ahead buffer
    // (128 records of 24 bytes) and per-TP pipeline state, rounded up.
    constexpr uint64_t kPerThread = 4096;
    const uint64_t threads = uint64_t{config.chip.num_tms} * config.chip.tps_per_tm;
    std::vector<HostBytes> parts = {
        {uint64_t{config.chip.num_tms} * (config.l1.size_bytes / config.l1.line_bytes) * kPerLine,
         "the L1 caches' tag and state arrays", "l1.size_bytes (or chip.num_tms)"},
        {uint64_t{config.num_l2()} * (config.l2.size_bytes / config.l2.line_bytes) * kPerLine,
         "the L2 caches' tag and state arrays", "l2.size_bytes (or chip.tms_per_l2)"},
        {uint64_t{config.chip.num_tms} * config.icaches_per_tm() *
             (config.icache.size_bytes / config.icache.line_bytes) * kPerLine,
         "the I-caches' tag and state arrays", "icache.size_bytes (or chip.num_tms)"},
        {threads * config.tp.local_store_bytes, "the threads' local stores",
         "tp.local_store_bytes (or chip.num_tms, chip.tps_per_tm)"},
        {threads * kPerThread, "the threads' machine and pipeline state",
         "chip.num_tms or chip.tps_per_tm"},
    };
    std::stable_sort(parts.begin(), parts.end(),
                     [](const HostBytes& a, const HostBytes& b) { return a.bytes > b.bytes; });
    return parts;
}

ChipConfig parse_config(std::string_view toml_text, std::string_view source_name,
                        const ChipConfig& base) {
    ChipConfig config = base;
    check_toml_nesting(toml_text, source_name);
    toml::table table;
    try {
        table = toml::parse(toml_text, source_name);
    } catch (const toml::parse_error& e) {
        throw ConfigError(
            fmt::format("{}:{}: {}", source_name, e.source().begin.line, e.description()));
    }
    load_table(config, table, "", source_name);
    try {
        validate(config);
    } catch (const ConfigError& e) {
        throw ConfigError(fmt::format("{}: {}", source_name, e.what()));
    }
    return config;
}

ChipConfig load_config(const std::string& path) {
    return parse_config(read_input_file(path, "chip config", kMaxConfigBytes), path, ChipConfig{});
}

namespace {

/// Sets the field one "key=value" assignment names, range-checking the value; the cross-field
/// rules are left to validate(), which sees every override applied.
void assign_override(ChipConfig& config, std::string_view assignment) {
    const std::string where = fmt::format("override '{}'", assignment);
    const size_t eq = assignment.find('=');
    if (eq == std::string_view::npos)
        throw ConfigError(fmt::format("{}: expected key=value, e.g. l1.size_bytes=16384", where));
    auto trim = [](std::string_view s) {
        while (!s.empty() && s.front() == ' ')
            s.remove_prefix(1);
        while (!s.empty() && s.back() == ' ')
            s.remove_suffix(1);
        return s;
    };
    const std::string_view key = trim(assignment.substr(0, eq));
    const std::string_view text = trim(assignment.substr(eq + 1));
    Parsed value;
    if (text == "true") value.as_bool = true;
    if (text == "false") value.as_bool = false;
    int64_t number = 0;
    const bool hex = text.starts_with("0x");
    const std::string_view digits = hex ? text.substr(2) : text;
    const auto [end, ec] =
        std::from_chars(digits.data(), digits.data() + digits.size(), number, hex ? 16 : 10);
    if (ec == std::errc{} && end == digits.data() + digits.size() && !digits.empty()) {
        value.as_int = number;
        value.as_real = double(number);
    }
    double real = 0;
    const auto [real_end, real_ec] = std::from_chars(text.data(), text.data() + text.size(), real);
    if (!hex && real_ec == std::errc{} && real_end == text.data() + text.size() && !text.empty())
        value.as_real = real;
    if (!assign(config, key, value, where)) unknown_key(where, key);
}

}  // namespace

void apply_overrides(ChipConfig& config, std::span<const std::string> assignments) {
    ChipConfig updated = config;
    for (const std::string& assignment : assignments)
        assign_override(updated, assignment);
    try {
        validate(updated);
    } catch (const ConfigError& e) {
        throw ConfigError(fmt::format("{} '{}': {}",
                                      assignments.size() == 1 ? "override" : "overrides",
                                      fmt::join(assignments, "', '"), e.what()));
    }
    config = updated;
}

void apply_override(ChipConfig& config, std::string_view assignment) {
    const std::string one(assignment);
    apply_overrides(config, std::span(&one, 1));
}

std::string to_toml(const ChipConfig& config) {
    std::string out;
    std::string section;
    for_each_field(config, [&](std::string_view name, const auto& field, Range range) {
        const size_t dot = name.rfind('.');
        const std::string_view this_section = name.substr(0, dot);
        if (this_section != section) {
            section = this_section;
            out += fmt::format("{}[{}]\n", out.empty() ? "" : "\n", section);
        }
        const std::string value = fmt::format("{}", field);
        out += fmt::format("{:<26} = {:<8} # {}\n", name.substr(dot + 1), value,
                           range_text(kIsBool<decltype(field)>, range));
    });
    return out;
}

std::vector<ConfigField> config_fields(const ChipConfig& config) {
    std::vector<ConfigField> fields;
    for_each_field(config, [&](std::string_view name, const auto& field, Range) {
        if constexpr (kIsReal<decltype(field)>)
            fields.push_back({std::string(name), 0, false, true, field});
        else
            fields.push_back({std::string(name), uint32_t(field), kIsBool<decltype(field)>});
    });
    return fields;
}

std::string ConfigField::text() const {
    if (is_real) return fmt::format("{}", real);
    if (is_bool) return value ? "true" : "false";
    return std::to_string(value);
}

}  // namespace tpsim::timing
