// Chip configuration: one plain struct per component, defaults in exactly one place (the member
// initialisers below, which are the TRaX-like chip of configs/trax.toml), loaded from TOML,
// overridable field by field, validated with messages naming the key and its allowed range.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "sim/core/error.hpp"

namespace tpsim::timing {

/// Thrown for any configuration problem; the message names the file:line or override, the key
/// and the allowed range.
struct ConfigError : Error {
    using Error::Error;
};

/// [chip] The shape of the whole chip.
struct ChipShape {
    uint32_t clock_mhz = 1000;  ///< core clock; converts cycles to seconds in reports
    uint32_t num_tms = 4;       ///< thread multiprocessors on the chip
    uint32_t tps_per_tm = 32;   ///< thread processors (one hardware thread each) per TM
    uint32_t tms_per_l2 = 4;    ///< TMs sharing one L2; the last group may be smaller
    bool operator==(const ChipShape&) const = default;
};

/// [tp] One thread processor: in-order, single issue.
struct ThreadConfig {
    uint32_t branch_taken_penalty = 1;      ///< bubble cycles after a taken branch or jump
    uint32_t branch_not_taken_penalty = 0;  ///< bubble cycles after a branch that falls through
    uint32_t local_store_bytes = 4096;      ///< private local store (stack) per thread
    uint32_t local_store_latency = 1;       ///< cycles for a load from the local store
    bool operator==(const ThreadConfig&) const = default;
};

/// One pool of identical functional units shared by the TPs of a TM.
struct FuConfig {
    uint32_t count = 1;     ///< units in the pool (per TM)
    uint32_t latency = 1;   ///< cycles from issue until the result can be read
    bool pipelined = true;  ///< a pipelined unit accepts a new operation every cycle; otherwise
                            ///< it is busy for `latency` cycles
    bool operator==(const FuConfig&) const = default;
};

/// [fu.*] The functional-unit pools of one TM (TRaX: ~1 FP add and 1 FP multiply per 8
/// threads, 1 FP divide per TM, 1 integer multiply per 16 threads).
struct FuPoolsConfig {
    FuConfig int_alu{32, 1, true};     ///< add, logic, shifts, compares, lui/auipc, CSR, fence
    FuConfig int_muldiv{2, 2, true};   ///< mul*, div*, rem*
    FuConfig fp_add{4, 2, true};       ///< fadd, fsub
    FuConfig fp_mul{4, 2, true};       ///< fmul and the fused multiply-add family
    FuConfig fp_divsqrt{1, 16, true};  ///< fdiv, fsqrt
    FuConfig fp_misc{8, 1, true};      ///< compare, min/max, sign injection, move, convert
    FuConfig branch{8, 1, true};       ///< conditional branches and jumps
    FuConfig load_store{8, 1, true};   ///< address generation; the cache adds its own latency
    FuConfig atomic{1, 1, true};       ///< issue slot of global-register atomics
    bool operator==(const FuPoolsConfig&) const = default;
};

/// [icache] Instruction fetch. Bank conflicts between threads fetching in the same cycle are
/// always modelled. By default (size_bytes = 0) the I-cache never misses, as in TRaX; a finite
/// I-cache (size_bytes > 0) misses, and its misses are line requests to the L2
/// (docs/hardware-model.md).
struct ICacheConfig {
    uint32_t threads_per_icache = 16;  ///< TPs sharing one instruction cache
    uint32_t banks = 16;               ///< banks per instruction cache, interleaved by word
    uint32_t size_bytes = 0;           ///< capacity of each I-cache; 0: it never misses (TRaX)
    uint32_t ways = 4;                 ///< associativity (LRU) of a finite I-cache
    uint32_t line_bytes = 64;          ///< line size; equals l1.line_bytes (one line size)
    uint32_t mshrs = 8;                ///< outstanding missed lines per I-cache
    bool finite() const { return size_bytes != 0; }
    bool operator==(const ICacheConfig&) const = default;
};

/// [l1] and [l2] A banked, set-associative (LRU), non-blocking data cache.
struct CacheConfig {
    uint32_t size_bytes = 32768;  ///< capacity
    uint32_t ways = 4;            ///< associativity
    uint32_t line_bytes = 64;     ///< line size; power of two, the same at every level
    uint32_t banks = 8;           ///< one access per bank per cycle; bank = line number % banks
    uint32_t hit_latency = 1;     ///< cycles from access to data on a hit
    uint32_t mshrs = 16;          ///< outstanding missed lines; misses to one line merge
    bool operator==(const CacheConfig&) const = default;
};

/// A finite I-cache's tags as a Cache: its size, ways, line and MSHRs; one bank (ICacheBanks
/// arbitrates the fetch banks) and a lookup of one cycle, after which a miss leaves for the L2.
inline CacheConfig icache_lines_config(const ICacheConfig& c) {
    return {c.size_bytes, c.ways, c.line_bytes, 1, 1, c.mshrs};
}

/// [l2] The L2 adds a store policy to the cache above (docs/hardware-model.md).
struct L2Config : CacheConfig {
    /// 0: write-around (TRaX), every store goes to DRAM as one line write. N > 0: a buffer of
    /// N lines per L2 merges stores to a line; a line goes to DRAM as one write when all its
    /// bytes are written, when it is the oldest and a new line needs room, before a load miss
    /// to it, or at the end of the run.
    uint32_t write_combining_lines = 0;
    bool operator==(const L2Config&) const = default;
};

/// [dram] Channels x banks with row buffers (open-page, FR-FCFS). All times are in core cycles
/// (a GDDR part at 2x the core clock has half its own cycle counts).
struct DramConfig {
    uint32_t channels = 8;      ///< independent channels, each with its own data bus
    uint32_t banks = 16;        ///< banks per channel, each with one row buffer
    uint32_t row_bytes = 2048;  ///< bytes per row (page) of one bank
    uint32_t queue_depth = 32;  ///< pending requests per channel before back-pressure
    uint32_t tRCD = 12;         ///< activate to read/write, same bank
    uint32_t tCL = 12;          ///< read command to first data
    uint32_t tCWL = 4;          ///< write command to first data
    uint32_t tRP = 12;          ///< precharge to activate, same bank
    uint32_t tRAS = 28;         ///< activate to precharge, same bank
    uint32_t tBURST = 2;        ///< data-bus cycles to move one cache line
    uint32_t tCCD = 2;          ///< column command to column command, same channel
    uint32_t tRRD = 5;          ///< activate to activate, different banks of a channel
    uint32_t tWR = 12;          ///< end of write data to precharge (write recovery)
    uint32_t tWTR = 5;          ///< end of write data to read command (turnaround)
    uint32_t tRTP = 4;          ///< read command to precharge
    bool operator==(const DramConfig&) const = default;
};

/// [global_registers] The chip-wide unit serving atomic increments (work distribution).
struct GlobalRegisterConfig {
    uint32_t latency = 4;       ///< cycles from arrival at the unit to the reply
    uint32_t per_cycle = 1;     ///< requests served per cycle, in (cycle, TM, sequence) order
    uint32_t link_latency = 2;  ///< cycles each way between a TM and the unit
    bool operator==(const GlobalRegisterConfig&) const = default;
};

/// [energy] What each event costs, in picojoules, at 65 nm (the node of the TRaX figures), for
/// the post-run estimate in sim/energy (docs/energy.md has every source and rule). The SRAM
/// costs are those of the default chip's geometry; sim/energy scales them to the configured
/// size and banks by the power law fitted to the same CACTI table.
struct EnergyConfig {
    // Per operation issued to a pool: simtrax samples/configs/default.config (65 nm Synopsys
    // DesignWare units, Spjut et al. TCAD 2009, Kopta et al. HPG 2013), its last column.
    double int_alu_pj = 0.101;     ///< INTADD (and BITWISE) 0.101
    double int_muldiv_pj = 2.97;   ///< INTMUL 2.97
    double fp_add_pj = 0.719;      ///< FPADD 0.719
    double fp_mul_pj = 3.15;       ///< FPMUL 3.15 (a fused multiply-add costs one multiply)
    double fp_divsqrt_pj = 45.55;  ///< FPINV 45.55 (TRaX's inverse/sqrt unit)
    double fp_misc_pj = 0.13;      ///< FPMIN and FPCMP 0.13
    double branch_pj = 0.13;       ///< BLT 0.13
    double load_store_pj = 0.101;  ///< address generation: an integer add (INTADD)
    double atomic_pj = 0.101;      ///< the request's increment: an integer add (INTADD)
    /// Per register read or write: simtrax SimpleRegisterFile.cc, 0.00789613 nJ (CACTI, 65 nm,
    /// a 128-entry 32-bit file).
    double register_access_pj = 7.89613;
    /// Per local-store load or store: CACTI 65 nm, 4 KiB, 1 bank, 4 B lines, 0.015990 nJ
    /// (simtrax samples/configs/icacheparams.txt; includes a tag array the store does not need).
    double local_store_access_pj = 15.990;
    /// Per instruction fetch: CACTI 65 nm I-cache, 4 KiB, 16 banks, 4 B lines, 0.013490 nJ
    /// (simtrax icacheparams.txt; TRaX: one I-cache per 16 threads).
    double icache_fetch_pj = 13.490;
    /// Per L1 access (load, store, line fill): CACTI 65 nm, 32 KiB, 8 banks, 64 B lines,
    /// 0.220453 nJ (simtrax samples/configs/dcacheparams.txt).
    double l1_access_pj = 220.453;
    /// Per L2 access (line request, store, line fill): CACTI 65 nm, 512 KiB, 16 banks, 64 B
    /// lines, 0.611974 nJ (dcacheparams.txt).
    double l2_access_pj = 611.974;
    /// SRAM energy per access grows as (size / default size)^this and (banks / default
    /// banks)^sram_bank_exponent: least-squares fit to dcacheparams.txt (64 B lines, 8 KiB to
    /// 4 MiB, 4 to 64 banks), within -30 % / +23 % of every entry.
    double sram_size_exponent = 0.355;
    double sram_bank_exponent = 0.176;  ///< see sram_size_exponent
    /// DRAM, per rank of four x16 1 Gb DDR3 devices (a 64-bit channel), from the IDD currents
    /// of simtrax samples/configs/usimm_configs/1Gb_x16_amd2GHz.vi with USIMM's power model
    /// (Micron TN-41-01): per ACT (and its PRE) 4 x (IDD0 tRC - IDD3N tRAS - IDD2N (tRC - tRAS))
    /// x VDD = 4 x 3.83 nJ.
    double dram_activate_pj = 15330;
    /// Per 64 B line read: 4 x ((IDD4R - IDD3N) VDD + 32 mW read termination) x 2 ns.
    double dram_read_pj = 2452;
    /// Per 64 B line written: 4 x (IDD4W - IDD3N) VDD x 2 ns.
    double dram_write_pj = 2196;
    /// Background power per channel, in milliwatts: 4 x (IDD2N VDD precharge standby + (IDD5 -
    /// IDD3N) VDD tRFC / tREFI refresh) = 4 x 109.1 mW.
    double dram_background_mw = 436.4;
    bool operator==(const EnergyConfig&) const = default;
};

/// [area] Silicon area of each component, in square micrometres, at 65 nm (docs/energy.md).
struct AreaConfig {
    // Per unit of a pool: simtrax samples/configs/default.config and sim/ReadConfig.cc
    // ("65nm sp"), Synopsys DesignWare.
    double int_alu_um2 = 450;       ///< INTADD 450
    double int_muldiv_um2 = 9184;   ///< INTMUL 9184
    double fp_add_um2 = 3311;       ///< FPADD 3311
    double fp_mul_um2 = 10327;      ///< FPMUL 10327
    double fp_divsqrt_um2 = 57936;  ///< FPINV 57936
    double fp_misc_um2 = 722;       ///< FPMIN / FPCMP 722 (ReadConfig.cc)
    double branch_um2 = 722;        ///< BLT 722 (ReadConfig.cc: "same as compare")
    double load_store_um2 = 450;    ///< an integer adder (INTADD)
    double atomic_um2 = 450;        ///< an integer adder (INTADD)
    /// Per TP: simtrax SimpleRegisterFile.cc, 0.0147665 mm^2 (128 x 32 bit).
    double register_file_um2 = 14766.5;
    /// Per TP: CACTI 65 nm, 4 KiB, 1 bank, 4 B lines, 0.090296 mm^2 (icacheparams.txt).
    double local_store_um2 = 90296;
    /// Per I-cache: CACTI 65 nm, 4 KiB, 16 banks, 4 B lines, 0.130596 mm^2 (icacheparams.txt).
    double icache_um2 = 130596;
    /// Per L1: CACTI 65 nm, 32 KiB, 8 banks, 64 B lines, 0.775049 mm^2 (dcacheparams.txt).
    double l1_um2 = 775049;
    /// Per L2: CACTI 65 nm, 512 KiB, 16 banks, 64 B lines, 5.960245 mm^2 (dcacheparams.txt).
    double l2_um2 = 5960245;
    /// SRAM area grows as (size / default size)^this and (banks / default banks)^
    /// sram_bank_exponent: least-squares fit to dcacheparams.txt as for energy, within
    /// -48 % / +51 % of every entry.
    double sram_size_exponent = 0.682;
    double sram_bank_exponent = 0.446;  ///< see sram_size_exponent
    bool operator==(const AreaConfig&) const = default;
};

/// The resolved configuration of one chip.
struct ChipConfig {
    ChipShape chip;
    ThreadConfig tp;
    FuPoolsConfig fu;
    ICacheConfig icache;
    CacheConfig l1;
    L2Config l2{{524288, 8, 64, 16, 8, 64}};
    DramConfig dram;
    GlobalRegisterConfig global_registers;
    EnergyConfig energy;
    AreaConfig area;
    bool operator==(const ChipConfig&) const = default;

    /// Number of L2 caches: one per group of chip.tms_per_l2 TMs.
    uint32_t num_l2() const { return (chip.num_tms + chip.tms_per_l2 - 1) / chip.tms_per_l2; }
    /// I-caches per TM: one per icache.threads_per_icache TPs; the last may serve fewer.
    uint32_t icaches_per_tm() const {
        return (chip.tps_per_tm + icache.threads_per_icache - 1) / icache.threads_per_icache;
    }
};

/// Reads a TOML file over the defaults; every key is optional, unknown keys are errors.
ChipConfig load_config(const std::string& path);
/// Parses TOML text (`source_name` appears in error messages) over `base`.
ChipConfig parse_config(std::string_view toml_text, std::string_view source_name,
                        const ChipConfig& base = {});
/// Applies "key.path=value" overrides (e.g. "l1.size_bytes=16384") in order, then validates the
/// result once, so that overrides which only agree together (dram.tRCD and dram.tRAS) are taken.
/// Throws ConfigError naming the overrides; a rejected list leaves `config` untouched.
void apply_overrides(ChipConfig& config, std::span<const std::string> assignments);
/// apply_overrides() with one override.
void apply_override(ChipConfig& config, std::string_view assignment);
/// Checks every range and cross-field rule, and that a run fits in kMaxHostBytes
/// (host_bytes); throws ConfigError naming the first violation.
void validate(const ChipConfig& config);

/// The most host memory a chip may need (docs/hardware-model.md, "Chip and determinism"): more is
/// refused up front instead of ending in std::bad_alloc after minutes of allocating.
constexpr uint64_t kMaxHostBytes = uint64_t(8) << 30;

/// One part of a chip's host memory, and the field that sizes it.
struct HostBytes {
    uint64_t bytes = 0;
    const char* part = "";   ///< e.g. "the L1 caches' tag and state arrays"
    const char* field = "";  ///< the config field to change, e.g. "l1.size_bytes"
};
/// The host memory a run of `config` needs for what grows with the chip: the caches' tag and
/// state entries, every thread's local store, machine and run-ahead state; largest part first.
std::vector<HostBytes> host_bytes(const ChipConfig& config);
/// The resolved configuration as TOML, every key present, with its allowed range as a comment.
std::string to_toml(const ChipConfig& config);
/// One configurable field's resolved value.
struct ConfigField {
    std::string key;  ///< e.g. "l1.size_bytes"
    uint32_t value;   ///< 0 or 1 when is_bool; 0 when is_real
    bool is_bool;
    bool is_real = false;  ///< a real number (energies, areas): `real` holds it
    double real = 0;
    /// The value as TOML writes it: "32768", "true", "0.719".
    std::string text() const;
    bool operator==(const ConfigField&) const = default;
};
/// Every configurable field of `config`, in print order (statistics file, help text, tests).
std::vector<ConfigField> config_fields(const ChipConfig& config);

}  // namespace tpsim::timing
