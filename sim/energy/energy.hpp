// Energy and area estimates: a pure function of a run's event counts and the chip
// configuration's [energy] and [area] costs, evaluated after the run (the cycle loop counts
// events only). docs/energy.md lists every cost, its source and what the model leaves out.
#pragma once
#include <array>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "sim/stats/registry.hpp"
#include "sim/timing/config.hpp"
#include "sim/timing/fu_pool.hpp"

namespace tpsim::energy {

/// The events the estimate charges, summed over the whole chip.
struct Events {
    std::array<double, size_t(timing::Pool::Count)> fu_issued{};  ///< operations per pool
    double register_reads = 0;
    double register_writes = 0;
    double local_store_accesses = 0;  ///< loads + stores
    double icache_fetches = 0;
    double l1_accesses = 0;  ///< loads + stores accepted + line fills (misses)
    double l2_accesses = 0;  ///< line requests + stores accepted + line fills (misses)
    double dram_activates = 0;
    double dram_reads = 0;   ///< lines
    double dram_writes = 0;  ///< lines
    double cycles = 0;       ///< the frame, for background power
};

/// Which statistic feeds which event: each count is the sum of the statistics whose names
/// match its patterns (stats::matches), so the same rule reads a live registry and a
/// statistics file.
struct EventSource {
    std::string pattern;  ///< e.g. "tm*/fu/fp_add/issued"
    double Events::*count = nullptr;
    size_t pool = 0;  ///< for fu_issued: the pool index
};
const std::vector<EventSource>& event_sources();

/// The events of the named statistics (names and values in the same order); statistics no
/// source matches are ignored.
Events events_from(std::span<const std::string> names, std::span<const double> values);

/// One component of the chip: its energy over the run and its silicon area (0 when the model
/// has no cited figure for it, docs/energy.md).
struct Part {
    std::string name;         ///< "fu/fp_add", "l1", "dram_background", ...
    std::string what;         ///< "L1 caches"
    std::string energy_rule;  ///< how joules is computed, naming the config fields
    std::string area_rule;    ///< how area_mm2 is computed; empty: the part has no area
    double joules = 0;
    double area_mm2 = 0;
};

/// The estimate of one run: its parts in a fixed order.
struct Estimate {
    std::vector<Part> parts;
    double seconds = 0;       ///< the frame time at chip.clock_mhz
    double area_mm2() const;  ///< the chip's: the sum of the parts'
};

/// The estimate for a run of `chip` that counted `events`.
Estimate estimate(const timing::ChipConfig& chip, const Events& events);

/// An SRAM's cost scaled from the default chip's geometry (the one its cited figure is for) to
/// (size_bytes, banks) by the power law (size / default size)^size_exponent x (banks / default
/// banks)^bank_exponent.
double scale_sram(double cost, double size_bytes, double default_size_bytes, double banks,
                  double default_banks, double size_exponent, double bank_exponent);

/// An entry of the CACTI table the cache figures are cited from.
struct SramPoint {
    double size_bytes = 0, banks = 0;
    double area_mm2 = 0, energy_nj = 0;  ///< per cache; per access
};

/// The 65 nm CACTI table's entry for a cache of this size and bank count (simtrax
/// dcacheparams.txt, 64-byte lines), if it has one.
std::optional<SramPoint> cacti_dcache_point(double size_bytes, double banks);

/// The area of one local store of this size that simtrax's 65 nm figures give (4 KiB from its
/// CACTI table icacheparams.txt, 512 B from 65nm_config.txt, the TRaX papers' TM), if they do.
std::optional<double> cacti_local_store_mm2(double size_bytes);

/// Register reads and writes of every executed instruction, from its opcode's operands:
/// rs1, rs2 and rs3 read, rd written (x0 included: the format names a register).
struct RegisterAccesses {
    double reads = 0;
    double writes = 0;
};
RegisterAccesses register_accesses(std::span<const uint64_t> executed_per_op);

/// Registers energy/..., area/... and the derived rates (docs/statistics.md) as formulas over
/// the registered counters, so that a sampled run's estimates (and their intervals) carry
/// through. Needs the chip's statistics and registers/reads, registers/writes registered;
/// rays/total and image/pixels when present.
void register_stats(const timing::ChipConfig& chip, stats::Registry& registry);

}  // namespace tpsim::energy
