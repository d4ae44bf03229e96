#include "sim/energy/energy.hpp"

#include <cmath>
#include <numeric>

#include <fmt/format.h>

#include "isa/isa.hpp"

namespace tpsim::energy {

namespace {

constexpr size_t kPools = size_t(timing::Pool::Count);

/// The source an input statistic feeds, if any.
const EventSource* source_of(std::string_view name) {
    for (const EventSource& source : event_sources())
        if (stats::matches(source.pattern, name)) return &source;
    return nullptr;
}

double pj(double picojoules) {
    return picojoules * 1e-12;
}

double mm2(double square_micrometres) {
    return square_micrometres * 1e-6;
}

}  // namespace

const std::vector<EventSource>& event_sources() {
    static const std::vector<EventSource> sources = [] {
        std::vector<EventSource> s;
        for (size_t p = 0; p < kPools; ++p)
            s.push_back(
                {fmt::format("tm*/fu/{}/issued", timing::to_string(timing::Pool(p))), nullptr, p});
        s.push_back({"registers/reads", &Events::register_reads});
        s.push_back({"registers/writes", &Events::register_writes});
        s.push_back({"tm*/local_store/loads", &Events::local_store_accesses});
        s.push_back({"tm*/local_store/stores", &Events::local_store_accesses});
        s.push_back({"tm*/icache/fetches", &Events::icache_fetches});
        for (const char* key : {"reads", "writes", "misses"}) {
            s.push_back({fmt::format("chip/l1/{}", key), &Events::l1_accesses});
            s.push_back({fmt::format("chip/l2/{}", key), &Events::l2_accesses});
        }
        s.push_back({"dram/activates", &Events::dram_activates});
        s.push_back({"dram/reads", &Events::dram_reads});
        s.push_back({"dram/writes", &Events::dram_writes});
        s.push_back({"chip/cycles", &Events::cycles});
        return s;
    }();
    return sources;
}

Events events_from(std::span<const std::string> names, std::span<const double> values) {
    Events events;
    for (size_t i = 0; i < names.size() && i < values.size(); ++i)
        if (const EventSource* source = source_of(names[i])) {
            if (source->count)
                events.*(source->count) += values[i];
            else
                events.fu_issued[source->pool] += values[i];
        }
    return events;
}

double scale_sram(double cost, double size_bytes, double default_size_bytes, double banks,
                  double default_banks, double size_exponent, double bank_exponent) {
    return cost * std::pow(size_bytes / default_size_bytes, size_exponent) *
           std::pow(banks / default_banks, bank_exponent);
}

double Estimate::area_mm2() const {
    return std::accumulate(parts.begin(), parts.end(), 0.0,
                           [](double sum, const Part& p) { return sum + p.area_mm2; });
}

Estimate estimate(const timing::ChipConfig& chip, const Events& events) {
    const timing::ChipConfig defaults;
    const timing::EnergyConfig& e = chip.energy;
    const timing::AreaConfig& a = chip.area;
    const double tms = chip.chip.num_tms;
    const double tps = tms * chip.chip.tps_per_tm;
    const double icaches =
        tms * double((chip.chip.tps_per_tm + chip.icache.threads_per_icache - 1) /
                     chip.icache.threads_per_icache);
    // Every SRAM scales from the geometry its cited figure is for: the default chip's.
    const auto energy_of = [&](double cost, double size, double default_size, double banks,
                               double default_banks) {
        return scale_sram(cost, size, default_size, banks, default_banks, e.sram_size_exponent,
                          e.sram_bank_exponent);
    };
    const auto area_of = [&](double cost, double size, double default_size, double banks,
                             double default_banks) {
        return scale_sram(cost, size, default_size, banks, default_banks, a.sram_size_exponent,
                          a.sram_bank_exponent);
    };

    Estimate out;
    out.seconds = events.cycles / (double(chip.chip.clock_mhz) * 1e6);
    const std::array<std::pair<double, double>, kPools> fu_costs = {{
        {e.int_alu_pj, a.int_alu_um2},
        {e.int_muldiv_pj, a.int_muldiv_um2},
        {e.fp_add_pj, a.fp_add_um2},
        {e.fp_mul_pj, a.fp_mul_um2},
        {e.fp_divsqrt_pj, a.fp_divsqrt_um2},
        {e.fp_misc_pj, a.fp_misc_um2},
        {e.branch_pj, a.branch_um2},
        {e.load_store_pj, a.load_store_um2},
        {e.atomic_pj, a.atomic_um2},
    }};
    for (size_t p = 0; p < kPools; ++p) {
        const timing::Pool pool = timing::Pool(p);
        const std::string name(timing::to_string(pool));
        out.parts.push_back(
            {"fu/" + name, fmt::format("{} functional units", name),
             fmt::format("operations issued x energy.{}_pj", name),
             fmt::format("units x TMs x area.{}_um2", name),
             events.fu_issued[p] * pj(fu_costs[p].first),
             tms * timing::pool_config(chip.fu, pool).count * mm2(fu_costs[p].second)});
    }
    out.parts.push_back(
        {"register_files", "register files", "reads and writes x energy.register_access_pj",
         "TPs x area.register_file_um2",
         (events.register_reads + events.register_writes) * pj(e.register_access_pj),
         tps * mm2(a.register_file_um2)});
    const double ls = chip.tp.local_store_bytes, ls_default = defaults.tp.local_store_bytes;
    const std::optional<double> ls_point = cacti_local_store_mm2(ls);
    const std::optional<double> ls_cited = cacti_local_store_mm2(ls_default);
    out.parts.push_back(
        {"local_stores", "local stores",
         "loads and stores x energy.local_store_access_pj scaled to tp.local_store_bytes",
         ls_point && ls_cited
             ? fmt::format("TPs x area.local_store_um2 scaled by simtrax's 65 nm figure for {} B",
                           ls)
             : "TPs x area.local_store_um2 scaled to tp.local_store_bytes by the power law",
         events.local_store_accesses * pj(energy_of(e.local_store_access_pj, ls, ls_default, 1, 1)),
         tps * mm2(ls_point && ls_cited ? a.local_store_um2 * (*ls_point / *ls_cited)
                                        : area_of(a.local_store_um2, ls, ls_default, 1, 1))});
    const double ib = chip.icache.banks, ib_default = defaults.icache.banks;
    // The cited I-cache holds 4 KiB (TRaX's, which never misses: icache.size_bytes = 0); a
    // finite I-cache scales from it.
    constexpr double kCitedIcacheBytes = 4096;
    const double is = chip.icache.finite() ? chip.icache.size_bytes : kCitedIcacheBytes;
    out.parts.push_back(
        {"icaches", "instruction caches",
         "fetches x energy.icache_fetch_pj scaled to icache.size_bytes and icache.banks",
         "I-caches x area.icache_um2 scaled to icache.size_bytes and icache.banks",
         events.icache_fetches *
             pj(energy_of(e.icache_fetch_pj, is, kCitedIcacheBytes, ib, ib_default)),
         icaches * mm2(area_of(a.icache_um2, is, kCitedIcacheBytes, ib, ib_default))});
    // A cache the CACTI table holds is costed from its entry (the cited figure times the
    // entry's ratio to the default geometry's); between entries, by the power law.
    const auto cache_part = [&](std::string name, const timing::CacheConfig& c,
                                const timing::CacheConfig& d, double accesses, double access_pj,
                                double um2, double count) {
        const std::optional<SramPoint> point = cacti_dcache_point(c.size_bytes, c.banks);
        const std::optional<SramPoint> cited = cacti_dcache_point(d.size_bytes, d.banks);
        const std::string scaled =
            point && cited ? fmt::format("scaled by the CACTI table's entry for {} KiB, {} banks",
                                         c.size_bytes / 1024, c.banks)
                           : fmt::format("scaled to {0}.size_bytes and {0}.banks by the power law "
                                         "(no CACTI table entry for {1} B, {2} banks)",
                                         name, c.size_bytes, c.banks);
        const double pj_each =
            point && cited ? access_pj * (point->energy_nj / cited->energy_nj)
                           : energy_of(access_pj, c.size_bytes, d.size_bytes, c.banks, d.banks);
        const double um2_each = point && cited
                                    ? um2 * (point->area_mm2 / cited->area_mm2)
                                    : area_of(um2, c.size_bytes, d.size_bytes, c.banks, d.banks);
        return Part{
            name,
            fmt::format("{} caches", name == "l1" ? "L1" : "L2"),
            fmt::format("loads, stores and line fills x energy.{}_access_pj {}", name, scaled),
            fmt::format("{0}s x area.{0}_um2 {1}", name, scaled),
            accesses * pj(pj_each),
            count * mm2(um2_each)};
    };
    out.parts.push_back(
        cache_part("l1", chip.l1, defaults.l1, events.l1_accesses, e.l1_access_pj, a.l1_um2, tms));
    out.parts.push_back(cache_part("l2", chip.l2, defaults.l2, events.l2_accesses, e.l2_access_pj,
                                   a.l2_um2, chip.num_l2()));
    // The DRAM figures are per 64-byte line (two 32-byte bursts of a 64-bit rank).
    const double lines_per_64 = chip.l2.line_bytes / 64.0;
    out.parts.push_back(
        {"dram", "DRAM accesses",
         "activates x energy.dram_activate_pj + lines read x energy.dram_read_pj "
         "+ lines written x energy.dram_write_pj (per 64 B of line)",
         "",
         events.dram_activates * pj(e.dram_activate_pj) +
             (events.dram_reads * pj(e.dram_read_pj) + events.dram_writes * pj(e.dram_write_pj)) *
                 lines_per_64,
         0});
    out.parts.push_back({"dram_background", "DRAM background (standby and refresh)",
                         "channels x energy.dram_background_mw x chip/frame_seconds", "",
                         chip.dram.channels * e.dram_background_mw * 1e-3 * out.seconds, 0});
    return out;
}

RegisterAccesses register_accesses(std::span<const uint64_t> executed_per_op) {
    RegisterAccesses out;
    for (size_t op = 0; op < executed_per_op.size() && op < isa::kNumInsns; ++op) {
        if (executed_per_op[op] == 0) continue;
        const isa::InsnInfo& info = isa::info(isa::Op(op));
        const isa::OperandInfo& o = info.operands;
        const int reads = (o.rs1 != isa::RegKind::None) + (o.rs2 != isa::RegKind::None) +
                          (info.format == isa::Format::R4);
        out.reads += double(executed_per_op[op]) * reads;
        out.writes += double(executed_per_op[op]) * (o.rd != isa::RegKind::None);
    }
    return out;
}

void register_stats(const timing::ChipConfig& chip, stats::Registry& registry) {
    // Copies of the names: registering grows the registry, which moves its entries' names.
    std::vector<std::string> names;
    for (const stats::Entry& entry : registry.entries())
        if (source_of(entry.name)) names.push_back(entry.name);
    const Estimate shape = estimate(chip, {});
    std::vector<std::string> part_keys;
    for (size_t i = 0; i < shape.parts.size(); ++i) {
        // Each part is a formula over the statistics it depends on only, so that a sampled
        // run's interval of one part is not made unknown by a rare event of another.
        std::vector<std::string> used;
        for (const std::string& name : names)
            if (estimate(chip, events_from(std::span(&name, 1), std::array{1.0})).parts[i].joules !=
                0)
                used.push_back(name);
        part_keys.push_back("energy/" + shape.parts[i].name);
        registry.add_formula(
            part_keys.back(), {used.begin(), used.end()},
            [chip, used, i](std::span<const double> v) {
                return estimate(chip, events_from(used, v)).parts[i].joules;
            },
            fmt::format("energy of the {}: {}", shape.parts[i].what, shape.parts[i].energy_rule),
            "J");
    }
    registry.add_formula(
        "energy/total", {part_keys.begin(), part_keys.end()},
        [](std::span<const double> v) { return std::accumulate(v.begin(), v.end(), 0.0); },
        "energy of the frame: the sum of the energy/<part> keys", "J");
    registry.add_ratio("energy/average_watts", "energy/total", "chip/frame_seconds",
                       "average power: energy/total / chip/frame_seconds", "W");
    if (registry.contains("image/pixels"))
        registry.add_ratio("energy/per_pixel", "energy/total", "image/pixels",
                           "energy/total / image/pixels", "J");
    if (registry.contains("rays/total")) {
        registry.add_ratio("energy/per_ray", "energy/total", "rays/total",
                           "energy/total / rays/total", "J");
        registry.add_formula(
            "energy/mrays_per_joule", {"rays/total", "energy/total"},
            [](std::span<const double> v) { return v[1] > 0 ? v[0] / v[1] / 1e6 : 0.0; },
            "rays/total / energy/total / 1e6", "Mrays/J");
    }
    // Areas depend on the configuration only.
    for (const Part& part : shape.parts)
        if (!part.area_rule.empty())
            registry.add_derived(
                "area/" + part.name, [a = part.area_mm2] { return a; },
                fmt::format("area of the {}: {}", part.what, part.area_rule), "mm^2");
    registry.add_derived(
        "area/total", [a = shape.area_mm2()] { return a; }, "chip area: the sum of area/*", "mm^2");
}

}  // namespace tpsim::energy
