// The energy and area estimate (sim/energy, docs/energy.md) checked against hand arithmetic:
// on a micro-kernel whose every event is known from its text, the estimate must be exactly the
// event counts times the configured costs; the SRAM scaling rule and the statistics that feed
// the estimate are checked apart.
#include "sim/energy/energy.hpp"

#include <catch2/catch.hpp>

#include "sim/core/elf_loader.hpp"
#include "sim/timing/machine_source.hpp"
#include "tests/timing/small_chips.hpp"

#include <cmath>
#include <memory>
#include <string>

using namespace tpsim;
using namespace tpsim::timing;

namespace {

/// programs/chain_fadd_64.elf on one TP of the default chip, its statistics registered as
/// tpsim render registers them (the chip's, registers/reads and registers/writes, energy).
struct ChainRun {
    std::unique_ptr<core::Machine> machine;
    std::unique_ptr<MachineSource> source;
    std::unique_ptr<Chip> chip;
    stats::Registry stats;
    energy::RegisterAccesses rf;

    explicit ChainRun(const ChipConfig& config) {
        core::MachineConfig machine_config = machine_config_for(config);
        machine_config.global_bytes = 1 << 20;
        machine = std::make_unique<core::Machine>(
            core::load_elf(std::string(TPSIM_TIMING_PROGRAMS) + "/chain_fadd_64.elf"),
            machine_config);
        source = std::make_unique<MachineSource>(*machine);
        chip = std::make_unique<Chip>(config, *source);
        chip->register_stats(stats);
        chip->run(10'000'000);
        rf = energy::register_accesses(machine->counters().per_op);
        stats.add_number("registers/reads", rf.reads, "test");
        stats.add_number("registers/writes", rf.writes, "test");
        energy::register_stats(config, stats);
    }
    double value(std::string_view name) const { return stats.value(name); }
};

}  // namespace

TEST_CASE("the estimate of a micro-kernel is its event counts times the configured costs",
          "[energy]") {
    const ChipConfig c = one_tp();
    const ChainRun run(c);
    // chain.S with STEPS = 64, by hand: li t1, li t2 (addi), fcvt.s.w x 2, fadd.s x 64,
    // fmv.x.w, add, li a0, li a7 (addi), ecall: 73 instructions.
    const double int_alu = 2 + 1 + 2 + 1;  // the four li, the add, the ecall (int_alu pool)
    const double fp_add = 64;
    const double fp_misc = 2 + 1;  // fcvt.s.w x 2, fmv.x.w
    const double instructions = int_alu + fp_add + fp_misc;
    // Sources: li 1 (x0) each, fcvt 1 each, fadd 2 each, fmv 1, add 2, ecall 0.
    const double reads = 4 * 1 + 2 * 1 + 64 * 2 + 1 + 2;
    const double writes = 4 + 2 + 64 + 1 + 1;  // everything but the ecall
    REQUIRE(run.value("chip/instructions") == instructions);
    CHECK(run.value("tm0/fu/int_alu/issued") == int_alu);
    CHECK(run.value("tm0/fu/fp_add/issued") == fp_add);
    CHECK(run.value("tm0/fu/fp_misc/issued") == fp_misc);
    CHECK(run.rf.reads == reads);
    CHECK(run.rf.writes == writes);

    const EnergyConfig& e = c.energy;
    const double pj = 1e-12;
    // No loads or stores: nothing in the local store, the caches or DRAM but background power.
    CHECK(run.value("energy/fu/int_alu") == Approx(int_alu * e.int_alu_pj * pj).epsilon(1e-12));
    CHECK(run.value("energy/fu/fp_add") == Approx(fp_add * e.fp_add_pj * pj).epsilon(1e-12));
    CHECK(run.value("energy/fu/fp_misc") == Approx(fp_misc * e.fp_misc_pj * pj).epsilon(1e-12));
    for (const char* idle : {"fu/int_muldiv", "fu/fp_mul", "fu/fp_divsqrt", "fu/branch",
                             "fu/load_store", "fu/atomic", "local_stores", "l1", "l2", "dram"})
        CHECK(run.value(std::string("energy/") + idle) == 0);
    CHECK(run.value("energy/register_files") ==
          Approx((reads + writes) * e.register_access_pj * pj).epsilon(1e-12));
    // The default chip's I-cache geometry: the cited figure, unscaled.
    CHECK(run.value("energy/icaches") ==
          Approx(instructions * e.icache_fetch_pj * pj).epsilon(1e-12));
    const double cycles = run.value("chip/cycles");
    const double seconds = cycles / (c.chip.clock_mhz * 1e6);
    CHECK(run.value("energy/dram_background") ==
          Approx(c.dram.channels * e.dram_background_mw * 1e-3 * seconds).epsilon(1e-12));
    const double total =
        (int_alu * e.int_alu_pj + fp_add * e.fp_add_pj + fp_misc * e.fp_misc_pj +
         (reads + writes) * e.register_access_pj + instructions * e.icache_fetch_pj) *
            pj +
        c.dram.channels * e.dram_background_mw * 1e-3 * seconds;
    CHECK(run.value("energy/total") == Approx(total).epsilon(1e-12));
    CHECK(run.value("energy/average_watts") == Approx(total / seconds).epsilon(1e-12));

    // Areas: one TM of the default pools, one TP, one I-cache, one L1 and one L2.
    const AreaConfig& a = c.area;
    const double mm2 = 1e-6;
    CHECK(run.value("area/fu/fp_add") == Approx(c.fu.fp_add.count * a.fp_add_um2 * mm2));
    CHECK(run.value("area/fu/int_alu") == Approx(c.fu.int_alu.count * a.int_alu_um2 * mm2));
    CHECK(run.value("area/register_files") == Approx(a.register_file_um2 * mm2));
    CHECK(run.value("area/local_stores") == Approx(a.local_store_um2 * mm2));
    CHECK(run.value("area/icaches") == Approx(a.icache_um2 * mm2));
    CHECK(run.value("area/l1") == Approx(a.l1_um2 * mm2));
    CHECK(run.value("area/l2") == Approx(a.l2_um2 * mm2));
    CHECK_FALSE(run.stats.contains("area/dram"));
    double area = 0;
    for (const stats::Entry& entry : run.stats.entries())
        if (entry.name.starts_with("area/") && entry.name != "area/total") area += entry.value();
    CHECK(run.value("area/total") == Approx(area).epsilon(1e-12));
}

TEST_CASE("every cost is a configuration field: doubling one doubles its part only", "[energy]") {
    ChipConfig c = one_tp();
    const ChainRun base(c);
    apply_override(c, "energy.fp_add_pj=1.438");
    apply_override(c, "area.l2_um2=11920490");
    const ChainRun doubled(c);
    CHECK(doubled.value("energy/fu/fp_add") ==
          Approx(2 * base.value("energy/fu/fp_add")).epsilon(1e-12));
    CHECK(doubled.value("energy/register_files") == base.value("energy/register_files"));
    CHECK(doubled.value("area/l2") == Approx(2 * base.value("area/l2")).epsilon(1e-12));
    CHECK(doubled.value("area/l1") == base.value("area/l1"));
}

TEST_CASE("SRAM costs scale from the default geometry by the fitted power law", "[energy]") {
    // An L1 of 8 KiB in 4 banks: (1/4)^0.355 x (1/2)^0.176 of the 32 KiB, 8-bank figure.
    CHECK(energy::scale_sram(220.453, 8192, 32768, 4, 8, 0.355, 0.176) ==
          Approx(220.453 * std::pow(0.25, 0.355) * std::pow(0.5, 0.176)).epsilon(1e-12));
    CHECK(energy::scale_sram(775049, 32768, 32768, 8, 8, 0.682, 0.446) == 775049);
    // Against the CACTI table it was fitted to (simtrax dcacheparams.txt, 65 nm): 8 KiB, 4
    // banks, 64 B lines is 0.118944 nJ and 0.207212 mm^2; the rule is within its stated error.
    const double e = energy::scale_sram(220.453, 8192, 32768, 4, 8, 0.355, 0.176);
    const double a = energy::scale_sram(775049, 8192, 32768, 4, 8, 0.682, 0.446);
    CHECK(e / 118.944 > 0.70);
    CHECK(e / 118.944 < 1.23);
    CHECK(a / 207212 > 0.52);
    CHECK(a / 207212 < 1.51);

    // Through the estimate: an L1 between the table's entries (24 KiB, 8 banks) charges each
    // access the scaled cost.
    ChipConfig c = one_tp();
    c.l1.size_bytes = 24576;
    c.l1.banks = 8;
    energy::Events events;
    events.l1_accesses = 1000;
    const energy::Estimate estimate = energy::estimate(c, events);
    const auto part = [&](std::string_view name) {
        for (const energy::Part& p : estimate.parts)
            if (p.name == name) return p;
        FAIL("no part " << name);
        return energy::Part{};
    };
    const double between_pj = energy::scale_sram(220.453, 24576, 32768, 8, 8, 0.355, 0.176);
    const double between_um2 = energy::scale_sram(775049, 24576, 32768, 8, 8, 0.682, 0.446);
    CHECK(part("l1").joules == Approx(1000 * between_pj * 1e-12).epsilon(1e-12));
    CHECK(part("l1").area_mm2 == Approx(between_um2 * 1e-6).epsilon(1e-12));
    CHECK_THAT(part("l1").energy_rule, Catch::Contains("by the power law (no CACTI table entry"));

    // The I-cache's cited 4 KiB is what an I-cache that never misses (size_bytes = 0) costs; a
    // finite one of 16 KiB scales from it.
    events = {};
    events.icache_fetches = 1000;
    const auto icache_part = [&](const ChipConfig& chip) {
        for (const energy::Part& p : energy::estimate(chip, events).parts)
            if (p.name == "icaches") return p;
        FAIL("no icaches part");
        return energy::Part{};
    };
    ChipConfig icache = one_tp();
    const energy::Part never_misses = icache_part(icache);
    icache.icache.size_bytes = 4096;
    CHECK(icache_part(icache).joules == never_misses.joules);
    icache.icache.size_bytes = 16384;
    CHECK(icache_part(icache).joules ==
          Approx(never_misses.joules * std::pow(4.0, c.energy.sram_size_exponent)).epsilon(1e-12));
    CHECK(icache_part(icache).area_mm2 ==
          Approx(never_misses.area_mm2 * std::pow(4.0, c.area.sram_size_exponent)).epsilon(1e-12));
}

TEST_CASE("A cache the CACTI table holds is costed from its entry, not the fit", "[energy]") {
    // simtrax dcacheparams.txt, 65 nm, 64 B lines: 16 KiB in 8 banks is 0.204198 nJ and
    // 0.650707 mm^2 (the power law gives 172 pJ and 0.483 mm^2); 8 KiB in 4 banks 0.118944 nJ
    // and 0.207212 mm^2; a 1 MiB L2 in 16 banks 0.828002 nJ and 10.042545 mm^2.
    energy::Events events;
    events.l1_accesses = 1000;
    events.l2_accesses = 1000;
    const auto part = [&](const ChipConfig& chip, std::string_view name) {
        for (const energy::Part& p : energy::estimate(chip, events).parts)
            if (p.name == name) return p;
        FAIL("no part " << name);
        return energy::Part{};
    };
    ChipConfig c = one_tp();
    c.l1.size_bytes = 16384;
    CHECK(part(c, "l1").joules == Approx(1000 * 204.198e-12).epsilon(1e-9));
    CHECK(part(c, "l1").area_mm2 == Approx(0.650707).epsilon(1e-9));
    CHECK_THAT(part(c, "l1").area_rule,
               Catch::Contains("scaled by the CACTI table's entry for 16 KiB, 8 banks"));
    c.l1.size_bytes = 8192;
    c.l1.banks = 4;
    CHECK(part(c, "l1").joules == Approx(1000 * 118.944e-12).epsilon(1e-9));
    CHECK(part(c, "l1").area_mm2 == Approx(0.207212).epsilon(1e-9));
    c.l2.size_bytes = 1 << 20;
    CHECK(part(c, "l2").joules == Approx(1000 * 828.002e-12).epsilon(1e-9));
    CHECK(part(c, "l2").area_mm2 == Approx(10.042545).epsilon(1e-9));
    // The default geometry is the cited figure itself, and a changed cited figure scales
    // with it.
    const ChipConfig defaults = one_tp();
    CHECK(part(defaults, "l1").joules == 1000 * (defaults.energy.l1_access_pj * 1e-12));
    // The TRaX papers' 512-byte local store (simtrax 65nm_config.txt): 19,470 um^2.
    ChipConfig papers = one_tp();
    papers.tp.local_store_bytes = 512;
    CHECK(part(papers, "local_stores").area_mm2 == Approx(0.019470).epsilon(1e-9));
    ChipConfig doubled = one_tp();
    apply_override(doubled, "energy.l1_access_pj=440.906");
    doubled.l1.size_bytes = 16384;
    CHECK(part(doubled, "l1").joules == Approx(2 * 1000 * 204.198e-12).epsilon(1e-9));
}

TEST_CASE("DRAM energy is per activate and per line, scaled to the line size", "[energy]") {
    ChipConfig c = one_tp();
    energy::Events events;
    events.dram_activates = 10;
    events.dram_reads = 100;
    events.dram_writes = 7;
    events.cycles = 2000;
    const auto dram = [&](const ChipConfig& chip) {
        for (const energy::Part& p : energy::estimate(chip, events).parts)
            if (p.name == "dram") return p.joules;
        return -1.0;
    };
    const EnergyConfig& e = c.energy;
    CHECK(dram(c) ==
          Approx((10 * e.dram_activate_pj + 100 * e.dram_read_pj + 7 * e.dram_write_pj) * 1e-12)
              .epsilon(1e-12));
    c.l1.line_bytes = c.l2.line_bytes = 128;  // two 64-byte transfers a line
    CHECK(
        dram(c) ==
        Approx((10 * e.dram_activate_pj + 2 * (100 * e.dram_read_pj + 7 * e.dram_write_pj)) * 1e-12)
            .epsilon(1e-12));
}

TEST_CASE("events are read from the statistics they are documented to come from", "[energy]") {
    const std::vector<std::string> names = {
        "tm0/fu/fp_mul/issued",  "tm12/fu/fp_mul/issued",  "chip/fu/fp_mul/issued",
        "tm0/local_store/loads", "tm1/local_store/stores", "region/local_store/local_store/loads",
        "chip/l1/reads",         "chip/l1/writes",         "chip/l1/misses",
        "chip/l1/hits",          "tmx/icache/fetches",     "tm3/icache/fetches"};
    const std::vector<double> values = {1, 2, 1000, 3, 4, 1000, 5, 6, 7, 1000, 1000, 8};
    const energy::Events events = energy::events_from(names, values);
    CHECK(events.fu_issued[size_t(Pool::FpMul)] == 3);  // per TM only, not a chip sum
    CHECK(events.local_store_accesses == 7);
    CHECK(events.l1_accesses == 5 + 6 + 7);  // hits are among the reads
    CHECK(events.icache_fetches == 8);
}
