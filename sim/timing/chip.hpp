// The cycle loop of the whole chip: thread processors (in-order, single issue, scoreboard over
// the unified 65-entry register file), I-cache fetch banks, FU pools, L1 per TM, L2 per group
// of TMs, DRAM and the global-register unit.
//
// Functional-first: the timing model asks its InstructionSource to execute one instruction when
// a TP fetches it, and then only decides when that instruction issues and when its result is
// ready. Each TM touches only its own state; traffic to L2, DRAM and the global registers moves
// through cycle-stamped queues processed in a fixed order (TM id, then FIFO order), so results
// never depend on host scheduling.
//
// Parallel simulation (docs/hardware-model.md, "Parallel simulation"): the TMs run on the host
// threads in stretches of cycles, each with the fills and replies the shared parts (L2s, DRAM,
// global registers) had decided for it at least a lookahead earlier (the shortest way back from
// the shared parts to a TM); the shared parts run the same stretches a little behind on one
// host thread, taking the TMs' requests in (cycle, TM, FIFO) order. Everything crossing between
// a TM and the shared parts goes through mailboxes. An instruction that touches state other
// threads can see executes in its turn of the order (cycle, TM, fetch order), as it does when
// one host thread visits the TMs in id order: results never depend on the number of host
// threads.
#pragma once
#include "isa/isa.hpp"
#include "sim/core/machine.hpp"
#include "sim/stats/registry.hpp"
#include "sim/timing/attribution.hpp"
#include "sim/timing/cache.hpp"
#include "sim/timing/config.hpp"
#include "sim/timing/dram.hpp"
#include "sim/timing/fu_pool.hpp"
#include "sim/timing/global_registers.hpp"
#include "sim/timing/icache.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <deque>
#include <memory>
#include <vector>

namespace tpsim::timing {

/// What one executed instruction did: the functional core's own record, so the machine's
/// reports reach the chip without a conversion.
using StepInfo = core::StepRecord;

/// The functional side, as the timing model sees it. Threads are numbered tm * tps_per_tm + tp.
class InstructionSource {
public:
    virtual ~InstructionSource() = default;
    /// Address of the next instruction thread `thread` will execute.
    virtual uint32_t next_pc(uint32_t thread) const = 0;
    /// Executes that instruction and reports it in `out` (every field written).
    virtual void step(uint32_t thread, StepInfo& out) = 0;
    /// Whether step(thread) touches only the thread's own state (its registers, local store,
    /// the read-only scene): such steps may run on any host thread at any moment. The others
    /// (shared memory, atomics, synchronisation, printing, faults) run in the chip's fixed
    /// order. The default is safe for any source: no step is private.
    virtual bool next_is_private(uint32_t /*thread*/) const { return false; }
    /// The chip is about to tick thread `thread`'s TM for a few cycles: a hint to bring what
    /// its next step reads into the host's caches. The default does nothing.
    virtual void prefetch_next(uint32_t /*thread*/) const {}
    /// Every step fetched before cycle `cycle` has happened: what the source held back of
    /// them (MachineSource: stores to shared memory) may be made visible now. The chip says
    /// so every few hundred cycles and whenever a run pauses. The default does nothing.
    virtual void passed(uint64_t /*cycle*/) {}
};

class MachineSource;  // machine_source.hpp

class Chip {
public:
    /// Any instruction source (e.g. a test's scripted one), called through its virtuals.
    /// `layout` names the memory regions traffic is counted by (none: all is "other").
    /// Throws std::invalid_argument for overlapping, unnamed or reserved regions.
    Chip(const ChipConfig& config, InstructionSource& source, const ChipLayout& layout = {});
    /// The functional machine: its calls inline into the cycle loop, and its cycle CSRs read
    /// this chip's clock while the chip lives.
    Chip(const ChipConfig& config, MachineSource& source, const ChipLayout& layout = {});
    ~Chip();

    /// Simulates the TMs on up to `threads` host threads (at most one per TM; 1: on the calling
    /// thread only). Nothing the chip reports depends on it.
    void use_host_threads(uint32_t threads);
    /// Times the host threads' blocks of TMs were resized to balance their work, over the runs
    /// on the number of host threads last set above one.
    uint64_t lane_moves() const;

    /// How often callers looping over run_until() usually report progress.
    static constexpr uint64_t kProgressInterval = 1 << 16;

    /// Runs cycles until `cycle` (exclusive) or until the chip has finished (every thread
    /// exited, all memory traffic drained); returns finished(). Calls continue where the last
    /// one stopped, so a run can pause and resume at any cycle with the same result. Throws
    /// std::runtime_error if nothing issues or returns for a long time (deadlock).
    bool run_until(uint64_t cycle);
    bool finished() const { return finished_; }
    /// Runs to the end; returns the cycle count. Throws std::runtime_error on a deadlock or if
    /// the chip has not finished by cycle `max_cycles`.
    uint64_t run(uint64_t max_cycles = UINT64_MAX);

    /// Sampled simulation (sim/render/sampled_run.hpp) switches between this cycle-level
    /// model and functional warming, through a quiescent chip:
    /// drain() stops fetching and runs cycles until no fetched instruction and no memory or
    /// atomic request is in flight (threads waiting at a barrier or for a semaphore may stay
    /// waiting); returns finished(). Calls to run_until() fetch again.
    bool drain();
    /// What warm() did.
    struct Warming {
        uint64_t instructions = 0;  ///< instructions executed
        bool reached_exit = false;  ///< a thread's next instruction is its exit
    };
    /// Functional warming of a drained chip: the threads execute about `instructions` in all,
    /// round-robin in short turns, without cycles; every global load and store updates the
    /// state it would leave behind in the cycle-level model (L1 and L2 tags and LRU order, DRAM
    /// open rows), so the next cycle-level stretch starts warm. A thread whose next instruction
    /// is its exit or a synchronisation instruction stops there holding it, for the cycle-level
    /// model to issue; warming ends early when a thread reaches its exit (the run's ragged end
    /// begins) or every thread has stopped. No counter moves.
    Warming warm(uint64_t instructions);

    /// Instructions executed by warm() so far.
    uint64_t warmed_instructions() const { return warmed_instructions_; }

    uint64_t cycles() const { return cycles_; }
    /// Threads that have not exited yet.
    uint32_t running_threads() const;
    const ChipLayout& layout() const { return layout_; }
    /// Each thread's cycles, issued instructions and DRAM bytes, charged to the work item it
    /// held (docs/statistics.md, "Work items"). Complete once the chip has finished; while
    /// paused, an item still in progress is not charged yet.
    const WorkItemCosts& work_items() const { return work_items_; }
    /// Costs by instruction address (docs/statistics.md, "Profile"); empty unless
    /// ChipLayout::profile. Complete once finished, as work_items().
    const PcProfile& profile() const { return profile_; }
    /// Registers every counter under tm<i>/..., l2/<j>/..., dram/..., global_registers/...,
    /// chip-wide sums under chip/... and traffic by region under region/... (whose L1 figures
    /// are summed over the TMs when run_until() returns). The chip and `registry` must outlive
    /// the printing.
    void register_stats(stats::Registry& registry) const;

private:
    struct Tm;
    struct WarmingObserver;
    struct HostThreads;
    // The cycle loop is instantiated for the concrete MachineSource (its calls inline) and for
    // any other InstructionSource (tests' scripted sources); the constructor picks one.
    template <class Source> bool run_cycles(uint64_t end);
    template <class Source> Warming warm_threads(uint64_t instructions);
    /// The state one global access would leave behind in TM `tm`'s L1, its L2 and DRAM;
    /// returns roughly how long a load would wait below the L1 (0 for a hit or a store).
    uint32_t warm_access(Tm& tm, uint32_t addr, bool store);
    /// No fetched instruction and no memory or atomic request in flight (drain()).
    bool quiescent() const;
    /// Anything in flight at the start of cycle `at`, except lines in write-combining buffers
    /// (a TM whose threads have all exited by then is idle).
    bool busy(uint64_t at) const;
    bool drained() const;
    /// Index of the region holding `addr` in layout_.regions, or other_region_.
    uint8_t region_of(uint32_t addr) const;
    /// The per-TM totals summed chip-wide (and the local-store high-water mark), once per
    /// run_until() call.
    void collect();
    WorkItemCounters& item_costs(uint32_t item) {
        return item < work_items_.items.size() ? work_items_.items[item] : work_items_.unassigned;
    }
    void charge_item(uint32_t item, uint64_t cycles, uint64_t instructions) {
        WorkItemCounters& costs = item_costs(item);
        costs.cycles += cycles;
        costs.instructions += instructions;
    }
    /// The shared parts' work in cycle `now`: DRAM and L2 fills, the TMs' requests to the
    /// L2s (and on to DRAM), the global-register unit. Runs after the TMs' ticks of `now`.
    void tick_shared(uint64_t now);
    /// The first and last cycle anything issued or returned in a stretch (the deadlock
    /// detector's).
    struct Progress {
        uint64_t first = UINT64_MAX, last = 0;
        void add(uint64_t cycle) {
            first = std::min(first, cycle);
            last = std::max(last, cycle);
        }
        void add(const Progress& p) {
            first = std::min(first, p.first);
            last = std::max(last, p.last);
        }
    };
    /// The shared parts' share of cycles [first, end), after the TMs' ticks of them (whose
    /// `progress` they report): the TMs' hand-overs (requests, work-item charges), the shared
    /// parts' ticks (and those of TMs whose threads have all exited) until `end` or the chip's
    /// end, the deadlock detector, and the delivery of the fills and replies decided.
    template <class Source>
    void shared_stretch(uint64_t first, uint64_t end, Progress progress, Source& source);
    /// What each TM handed over since the last call: its requests join the shared parts' own
    /// queues, its work-item charges the chip's costs.
    void take_hand_overs();
    /// Every fill and reply the shared parts have decided goes to its TM's inbox (each arrives
    /// a lookahead or more after it was decided).
    void deliver();
    /// run_cycles() on the host threads: stretches of TM ticks on every lane, the shared parts'
    /// stretches a stretch or two behind, on lane 0 or a lane that would wait for them.
    template <class Source> void run_pipelined(uint64_t end, Source& source);
    /// TMs [from, to), host thread `lane`'s, tick cycles [first, end): they take their mail
    /// first and hand over what they sent after. Returns their progress.
    template <class Source>
    Progress tick_tms(uint32_t lane, uint32_t from, uint32_t to, uint64_t first, uint64_t end,
                      Source& source);
    /// tick_tms() of stretch `stretch` on a lane of run_pipelined(); false if it failed or
    /// stopped at another lane's earlier failure (recorded in HostThreads).
    template <class Source>
    bool tick_lane(uint32_t lane, uint32_t from, uint32_t to, uint64_t stretch, uint64_t first,
                   uint64_t end, Source& source);
    /// Lane 0 of run_pipelined() after stretch `stretch`: resizes the lanes' blocks of TMs from
    /// stretch + 3 on if their measured host time says so (core::balance_lanes).
    void resize_blocks(uint64_t stretch);
    /// Host thread `lane` ticks TMs [from, to) from now on, those still running (the shared
    /// parts tick the others).
    void take_tms(uint32_t lane, uint32_t from, uint32_t to);
    /// TM `tm` is host thread `lane`'s: its turns and its profile counts.
    void join_lane(Tm& tm, uint32_t lane);
    /// The TMs host thread `lane` of `lanes` ticks at first are [first_tm(lane),
    /// first_tm(lane + 1)): blocks of consecutive ids, so that two host threads' TMs are
    /// neighbours in memory only at the blocks' ends. The blocks are resized as the run goes.
    uint32_t first_tm(uint32_t lane, uint32_t lanes) const {
        return uint32_t(uint64_t{tms_.size()} * lane / lanes);
    }
    /// One cycle of one TM: what it receives, then (while it has threads) its tick.
    template <class Source> void tm_cycle(Tm& tm, uint64_t now, Source& source);
    /// Waits until every TM simulated on another host thread has passed TM `tm`'s position in
    /// cycle `now` (OrderedTurns), before a step that is not private.
    void wait_turn(const Tm& tm, uint64_t now);
    /// A synchronisation instruction of TP i issues: its request goes to the global-register
    /// unit, and the TP sleeps until the reply. Cold: out of the issue loop.
    [[gnu::cold, gnu::noinline]] void send_sync(Tm& tm, uint32_t i, const StepInfo& s,
                                                uint64_t now);
    /// A finite I-cache's lookups of the fetches in `granted` (bits of `part`, their banks
    /// granted): returns the hits; a TP that missed waits for its line (Tm::wake_from_fetch).
    template <class Source, bool kProfile>
    [[gnu::noinline]] uint64_t fetch_lines(Tm& tm, const RotatedPart& part, uint64_t granted,
                                           uint64_t now, Source& source);
    // kWords: words per TP bit set, 0 = any; kProfile: collect the PcProfile.
    template <class Source, uint32_t kWords, bool kProfile>
    void tick_tm(Tm& tm, uint64_t now, Source& source);

    ChipConfig config_;
    ChipLayout layout_;
    InstructionSource& source_;
    bool (Chip::*run_cycles_)(uint64_t end) = &Chip::run_cycles<InstructionSource>;
    Warming (Chip::*warm_threads_)(uint64_t instructions) = &Chip::warm_threads<InstructionSource>;
    bool fetching_ = true;                      // false while drain() empties the chip
    core::Machine* clocked_machine_ = nullptr;  // reads the TMs' clocks through its cycle CSRs
    // The cycle each TM is simulating, for the cycle CSRs; written every tick (kTmSpacing).
    struct alignas(core::kTmSpacing) TmClock {
        uint64_t now = 0;
    };
    std::vector<TmClock> clocks_;
    uint64_t lookahead_ = 1;                     // cycles (at least 1)
    std::unique_ptr<HostThreads> host_threads_;  // none: every TM on the calling thread
    uint32_t lanes_ = 0;                         // host threads the TMs run on; 0: not yet set
    // The TMs are running on the host threads: a step that is not private waits for its turn.
    bool tms_in_parallel_ = false;
    std::vector<std::unique_ptr<Tm>> tms_;
    std::array<Pool, size_t(isa::FuClass::Count)> pool_of_{};
    std::array<uint32_t, size_t(Pool::Count)> latency_of_{};
    // Region lookup: the regions sorted by address, as [begin, end) and their layout index.
    struct RegionBounds {
        uint32_t begin, end;
        uint8_t index;
    };
    std::vector<RegionBounds> region_bounds_;
    uint8_t other_region_ = 0;  // index of "other": layout_.regions.size()
    uint8_t fetch_region_ = 0;  // of a finite I-cache's line requests: other_region_ + 1
    // What the shared parts write while the TMs run on other host threads starts on a cache
    // line of its own: the TMs' ticks read the fields above.
    alignas(core::kHostSpacing) std::vector<Cache> l2s_;
    Dram dram_;
    GlobalRegisterUnit global_registers_;
    uint64_t cycles_ = 0;
    uint64_t warmed_instructions_ = 0;
    // The deadlock detector: the last cycle anything issued or returned, and in the shared
    // parts' current stretch, the first and last such cycle.
    uint64_t last_progress_cycle_ = 0;
    Progress shared_progress_;
    bool finished_ = false;
    uint64_t local_store_high_water_ = 0;  // bytes, max over threads
    // Traffic by region (index as MemRequest::region); l1_traffic_ sums the TMs' in collect().
    // The L2 and DRAM also count fetch_region_'s.
    std::vector<LevelTraffic> l1_traffic_, l2_traffic_, dram_traffic_;
    uint64_t local_payload_bytes_ = 0;  // summed in collect()
    WorkItemCosts work_items_;
    PcProfile profile_;  // the lanes' sum, in collect()
    // Each host thread counts its TMs' profile in its own lane, the shared parts (and the TMs
    // they tick) in the last; outside_text takes the share of a pc about to fault and is never
    // read.
    struct alignas(core::kHostSpacing) ProfileLane {
        PcProfile profile;
        PcCounters outside_text;
    };
    std::vector<ProfileLane> profile_lanes_;
};

}  // namespace tpsim::timing
