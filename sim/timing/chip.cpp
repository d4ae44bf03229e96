#include "sim/timing/chip.hpp"

#include "kernel/memory_map.hpp"
#include "sim/core/lane_balance.hpp"
#include "sim/core/ordered_turns.hpp"
#include "sim/timing/bits.hpp"
#include "sim/timing/epoch_cycles.hpp"
#include "sim/timing/machine_source.hpp"

#include <fmt/format.h>

#include <fmt/ranges.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <exception>
#include <functional>
#include <iterator>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <utility>

namespace tpsim::timing {

namespace {

constexpr uint64_t kNever = UINT64_MAX;
/// wake_at of a TP waiting at the barrier or for a semaphore: only the global-register unit's
/// reply wakes it (Tm::wake_from_sync), not the replies wake() serves.
constexpr uint64_t kSyncWait = kNever - 1;
/// wake_at of a TP waiting for an instruction line (a finite I-cache's miss): only the I-cache's
/// reply wakes it (Tm::wake_from_fetches).
constexpr uint64_t kFetchWait = kNever - 2;
constexpr uint64_t kDeadlockCycles = 1'000'000;
/// Cycles between the shared parts' InstructionSource::passed calls (MachineSource: a TM of
/// 32 TPs holds about 8,192 stores meanwhile at most, a few more on several host threads, whose
/// lanes run up to a lookahead ahead).
constexpr uint64_t kPassedEvery = 256;
constexpr size_t kPools = static_cast<size_t>(Pool::Count);
constexpr size_t kStalls = static_cast<size_t>(Stall::Count);

/// The longest a TP can sleep until a known cycle: an operand wait (at most the longest FU
/// latency plus the local-store latency) or a branch bubble.
uint64_t longest_timed_sleep(const ChipConfig& c) {
    uint64_t fu = 0;
    for (size_t p = 0; p < kPools; ++p)
        fu = std::max<uint64_t>(fu, pool_config(c.fu, Pool(p)).latency);
    const uint64_t bubble = std::max(c.tp.branch_taken_penalty, c.tp.branch_not_taken_penalty);
    return std::max(fu + c.tp.local_store_latency, bubble + 1);
}

/// Counts an accepted cache access in its region's traffic; `payload` and `moved` are the bytes
/// docs/statistics.md defines for the level.
void count_access(LevelTraffic& t, CacheOutcome outcome, uint64_t payload, uint64_t moved) {
    t.payload_bytes += payload;
    t.moved_bytes += moved;
    switch (outcome) {
    case CacheOutcome::Hit:
        ++t.reads, ++t.hits;
        break;
    case CacheOutcome::Miss:
        ++t.reads, ++t.misses;
        break;
    case CacheOutcome::MergedMiss:
        ++t.reads, ++t.merged_misses;
        break;
    default:
        ++t.writes;
        break;  // WriteForward, WriteCombined
    }
}

/// Moves every element of `from` to the back of `to`, in order.
template <class Queue> void move_to_back(Queue& to, Queue& from) {
    if (from.empty()) return;  // the usual case: not even a call into the deque
    to.insert(to.end(), std::make_move_iterator(from.begin()), std::make_move_iterator(from.end()));
    from.clear();
}

using HostClock = std::chrono::steady_clock;

uint64_t nanoseconds_since(HostClock::time_point start) {
    return uint64_t(
        std::chrono::duration_cast<std::chrono::nanoseconds>(HostClock::now() - start).count());
}

/// Lowers `count` to `to` if it is above (several host threads may).
void lower(std::atomic<uint64_t>& count, uint64_t to) {
    uint64_t now = count.load();
    while (to < now && !count.compare_exchange_weak(now, to)) {
    }
}

/// Region names that the chip's own region/ keys use.
constexpr std::string_view kReservedRegions[] = {"other", "local_store", "instruction_fetch"};

}  // namespace

// On its own cache lines: TMs ticked on different host threads never share one.
struct alignas(core::kHostSpacing) Chip::Tm {
    // Per-TP flags the cycle loop tests for many TPs at once are bit sets over the TPs (bit
    // i of word i / 64); the rest of a TP's state is in Tp.
    using TpBits = std::vector<uint64_t>;
    struct Tp {
        // The hot part first: read for every awake TP in every cycle.
        StepInfo pending;  // fetched, not yet issued (bit in pending_tps)
        Pool pending_pool{};
        Pool asleep_on{};  // the producing pool a reply-wait is attributed to
        // Cycle each register becomes readable, as an offset from the TM's epoch; the extra last
        // slot is isa::kNoReg (an unused operand) and stays 0, so the scoreboard check needs no
        // branch per operand.
        std::array<uint32_t, isa::kNumRegs + 1> reg_ready{};
        uint64_t wake_at = 0;      // asleep until this cycle (kNever: until a reply for it)
        uint64_t asleep_from = 0;  // first uncounted cycle of a reply-wait
        uint64_t mem_at = 0;       // a granted load/store's first cycle at the L1
        MemRequest mem_request;
        uint32_t lowest_local = trax::map::kLocalTop;  // for the local-store high-water mark
        // The work item held (the last atomicinc(0) result; none before the first), since
        // which cycle, and the instructions issued for it since then (Chip::work_items).
        uint32_t item = UINT32_MAX;
        uint64_t item_since = 0;
        uint64_t item_instructions = 0;
        std::array<Pool, isa::kNumRegs> reg_producer{};  // pool that will write it
    };
    struct Counters {
        uint64_t instructions = 0;
        uint64_t active_tp_cycles = 0;  // TP-cycles of threads not yet exited
        std::array<uint64_t, kStalls> stalls{};
        std::array<uint64_t, kPools> operand_stalls{};  // by producing pool
        std::array<uint64_t, size_t(isa::FuClass::Count)> per_class{};
        uint64_t local_loads = 0;
        uint64_t local_stores = 0;
        uint64_t local_payload_bytes = 0;
    };

    Tm(const ChipConfig& c, uint32_t id, size_t regions)
        : id(id), words((c.chip.tps_per_tm + 63) / 64), tps(c.chip.tps_per_tm),
          icache(c.icache, c.chip.tps_per_tm),
          lines(c.icache.finite()
                    ? std::make_unique<ICacheLines>(c.icache, c.chip.tps_per_tm, uint8_t(regions))
                    : nullptr),
          l1(c.l1), awake_tps(words), pending_tps(words), needs_port_tps(words),
          mem_waiting_tps(words), issuing_tps(words), asking_tps(words), shared_next_tps(words),
          wheel_slots(std::min(std::bit_ceil(longest_timed_sleep(c) + 1), kMaxWheelSlots)),
          sleeps_outlast_wheel(longest_timed_sleep(c) >= wheel_slots), wheel(wheel_slots * words),
          l1_traffic(regions) {
        for (uint32_t i = 0; i < c.chip.tps_per_tm; ++i)
            set_bit(awake_tps, i);
        for (size_t p = 0; p < kPools; ++p)
            pools.emplace_back(pool_config(c.fu, Pool(p)), c.chip.tps_per_tm);
    }

    /// Start of cycle `now`: every two billion cycles, the scoreboards' epoch moves.
    void keep_epoch_near(uint64_t now) {
        if (epoch.due(now)) [[unlikely]]
            epoch.move_to(now, [&](auto&& shift) {
                for (Tp& tp : tps)
                    shift(tp.reg_ready);
            });
    }
    void add_operand_stalls(Pool blocking, uint64_t cycles) {
        counters.active_tp_cycles += cycles;
        counters.stalls[size_t(Stall::Operand)] += cycles;
        counters.operand_stalls[size_t(blocking)] += cycles;
    }
    /// A reply for `tp` arrived: a TP asleep until then gets its stall cycles and runs again.
    void wake(uint32_t i, uint64_t now) {
        Tp& tp = tps[i];
        if (tp.wake_at != kNever) return;
        set_bit(awake_tps, i);
        add_operand_stalls(tp.asleep_on, now - tp.asleep_from);
        if (profile)
            if (PcCounters* pc = profile->at(tp.pending.pc))
                pc->stalls[size_t(Stall::Operand)] += now - tp.asleep_from;
        tp.wake_at = now;
    }
    /// The global-register unit's reply to a synchronisation instruction: the TP, asleep since
    /// it issued the instruction, gets its sync stall cycles and runs again.
    void wake_from_sync(uint32_t i, uint64_t now) {
        Tp& tp = tps[i];
        set_bit(awake_tps, i);
        const uint64_t waited = now - tp.asleep_from;
        counters.active_tp_cycles += waited;
        counters.stalls[size_t(Stall::Sync)] += waited;
        if (profile)
            if (PcCounters* pc = profile->at(tp.pending.pc))
                pc->stalls[size_t(Stall::Sync)] += waited;
        tp.wake_at = now;
    }
    /// A finite I-cache's replies by `now`: the line each TP missed on has arrived (forwarded
    /// to it), so it fetches again, with fetch-miss stall cycles from the cycle of its miss.
    /// Out of line: receive() stays small without a finite I-cache.
    [[gnu::noinline]] void wake_from_fetches(uint64_t now) {
        MemReply reply;
        while (lines->pop_reply(now, reply)) {
            Tp& tp = tps[reply.request.source];
            set_bit(awake_tps, reply.request.source);
            const uint64_t waited = now - tp.asleep_from;
            counters.active_tp_cycles += waited;
            counters.stalls[size_t(Stall::FetchMiss)] += waited;
            if (profile)
                if (PcCounters* pc = profile->at(reply.request.pc))
                    pc->stalls[size_t(Stall::FetchMiss)] += waited;
            tp.wake_at = now;
            ++progress;
        }
    }
    /// Before the TM's ticks of a stretch of cycles, on the host thread that ticks it: the
    /// fills and replies delivered to it so far.
    void take_mail() {
        if (!inbox.holds_mail.load(std::memory_order_acquire)) return;
        std::lock_guard hold(inbox.lock);
        move_to_back(fills, inbox.fills);
        move_to_back(replies, inbox.replies);
        inbox.holds_mail.store(false, std::memory_order_relaxed);
    }
    /// After the TM's ticks of a stretch of cycles, on the host thread that ticked it: what it
    /// sent to the shared parts and its work-item charges.
    void hand_over() {
        std::deque<OutboundRequest>& sent = l1.outbound();
        if (sent.empty() && atomics_out.empty() && charges.empty()) return;
        std::lock_guard hold(outbox.lock);
        move_to_back(outbox.requests, sent);
        move_to_back(outbox.atomics, atomics_out);
        outbox.charges.insert(outbox.charges.end(), charges.begin(), charges.end());
        charges.clear();
        outbox.holds_mail.store(true, std::memory_order_release);
    }
    /// Any memory or global-register traffic of this TM in flight (an idle TM: one whose
    /// threads have all exited, ticked by the shared parts' host thread only).
    bool holds_traffic() const {
        return l1.outstanding_misses() || !l1.outbound().empty() || !outbox.requests.empty() ||
               !at_shared.requests.empty() || !replies.empty() || !inbox.replies.empty();
    }
    /// Start of cycle `now`: L2 fills, global-register replies, then the L1's and the finite
    /// I-cache's replies.
    void receive(uint64_t now) {
        for (; !fills.empty() && fills.front().cycle <= now; fills.pop_front())
            if (fills.front().icache == kDataLine) [[likely]]
                l1.fill(now, fills.front().line);
            else
                lines->fill(now, fills.front().icache, fills.front().line);  // out of line
        for (; !replies.empty() && replies.front().ready <= now; replies.pop_front()) {
            const AtomicRequest& atomic = replies.front().request;
            if (atomic.kind == GlobalRequest::Increment) [[likely]] {
                tps[atomic.tp].reg_ready[atomic.tag] = epoch.offset(now);
                wake(atomic.tp, now);
            } else {
                wake_from_sync(atomic.tp, now);
            }
            ++progress;
        }
        MemReply reply;
        while (l1.pop_reply(now, reply)) {
            tps[reply.request.source].reg_ready[reply.request.tag] = epoch.offset(now);
            wake(reply.request.source, now);
            ++progress;
        }
        if (lines) [[unlikely]]
            wake_from_fetches(now);
    }
    /// TP i leaves the awake set until cycle `at` (> now), when the wheel puts it back. A
    /// sleep longer than the wheel (configs with huge latencies) waits in the wheel's last slot
    /// and is put back to sleep by wake_timed.
    void sleep_until(uint32_t i, uint64_t at, uint64_t now) {
        tps[i].wake_at = at;
        clear_bit(awake_tps, i);
        const uint64_t slot =
            (at - now < wheel_slots ? at : now + wheel_slots - 1) & (wheel_slots - 1);
        set_bit(wheel, uint32_t(slot) * 64 * words + i);
    }
    /// Start of cycle `now`: the TPs whose timed sleep ends join the awake set.
    [[gnu::always_inline]] void wake_timed(uint64_t now) {
        uint64_t* slot = &wheel[(now & (wheel_slots - 1)) * words];
        for (uint32_t w = 0; w < words; ++w) {
            uint64_t due = std::exchange(slot[w], 0);
            if (sleeps_outlast_wheel)
                for (uint64_t bits = due; bits != 0; bits &= bits - 1) {
                    const uint32_t i = (w << 6) + static_cast<uint32_t>(std::countr_zero(bits));
                    if (tps[i].wake_at > now) {
                        due &= ~(uint64_t{1} << (i & 63));
                        sleep_until(i, tps[i].wake_at, now);
                    }
                }
            awake_tps[w] |= due;
        }
    }

    /// Whether any thread's next instruction is not private.
    bool steps_shared_next() const {
        return std::any_of(shared_next_tps.begin(), shared_next_tps.end(),
                           [](uint64_t word) { return word != 0; });
    }

    uint32_t id;
    uint32_t lane = 0;  // the host thread that ticks it (Chip::first_tm)
    // A stretch's cycles from which the TM ticks in the order (cycle, TM), and a fault thrown by
    // its tick of that cycle before, to be raised there (Chip::tick_tms).
    uint64_t ordered_from = 0;
    std::exception_ptr fault_due;
    uint32_t words;     // 64-bit words of a TpBits
    EpochCycles epoch;  // of the TPs' scoreboards
    std::vector<Tp> tps;
    std::vector<FuPool> pools;
    ICacheBanks icache;
    std::unique_ptr<ICacheLines> lines;  // a finite I-cache's contents; none: it never misses
    Cache l1;
    uint32_t rotation = 0;  // TP that goes first this cycle (fetch and L1 priority)
    uint32_t atomic_sequence = 0;
    // Sent to the global-register unit, in order; the shared parts take each one the cycle
    // after it was sent.
    std::deque<AtomicRequest> atomics_out;
    uint32_t running = 0;
    // Received in the cycle they arrive: L2 fills of L1 (or I-cache) lines and global-register
    // replies, each in the order the shared parts produced them (from the inbox).
    static constexpr uint32_t kDataLine = UINT32_MAX;
    struct Fill {
        uint64_t cycle;
        uint32_t line;
        uint32_t icache;  // the I-cache in the TM the line is for, or kDataLine (the L1)
    };
    std::deque<Fill> fills;
    std::deque<AtomicReply> replies;
    // Work-item charges made in a stretch of cycles, added to the chip's costs after it.
    struct ItemCharge {
        uint32_t item;
        uint64_t cycles, instructions;
    };
    std::vector<ItemCharge> charges;
    // Deadlock detector: events (issues, replies) so far, and the stretch's first and last
    // cycle with any.
    uint64_t progress = 0;
    Progress progress_cycles;
    // What the shared parts' host thread reads of the TM while another host thread may tick it
    // is on cache lines of its own, which the ticks do not write (docs/hardware-model.md,
    // "Parallel simulation"). First the cycle with every thread exited: from then on the shared
    // parts tick the TM (it only receives).
    alignas(core::kHostSpacing) std::atomic<uint64_t> idle_from = kNever;
    // Then a mailbox each way, each under its own lock.
    struct alignas(
        core::kHostSpacing) Outbox {  // filled by hand_over(), emptied by Chip::take_hand_overs
        std::mutex lock;
        std::atomic<bool> holds_mail{false};
        std::deque<OutboundRequest> requests;  // to the L2: the L1's and I-cache's, FIFO
        std::deque<AtomicRequest> atomics;     // to the global-register unit
        std::vector<ItemCharge> charges;
    } outbox;
    struct alignas(core::kHostSpacing) Inbox {  // filled by Chip::deliver, emptied by take_mail()
        std::mutex lock;
        std::atomic<bool> holds_mail{false};
        std::deque<Fill> fills;
        std::deque<AtomicReply> replies;
        void post(const Fill& fill) { post_to(fills, fill); }
        void post(const AtomicReply& reply) { post_to(replies, reply); }

    private:
        template <class Queue, class Mail> void post_to(Queue& queue, const Mail& mail) {
            std::lock_guard hold(lock);
            queue.push_back(mail);
            holds_mail.store(true, std::memory_order_release);
        }
    } inbox;
    // The TM's requests once the shared parts have taken them, until the L2 or the
    // global-register unit accepts each (the shared parts' own).
    struct alignas(core::kHostSpacing) AtShared {
        std::deque<OutboundRequest> requests;
        std::deque<AtomicRequest> atomics;
    } at_shared;
    // Visited by the cycle loop: not exited, not asleep (timed sleepers wait in the wheel,
    // reply-waits return through wake()).
    TpBits awake_tps;
    TpBits pending_tps;      // holding a fetched instruction
    TpBits needs_port_tps;   // ... that is a load/store to global memory (needs the L1 port)
    TpBits mem_waiting_tps;  // a granted load/store waits for its L1 access
    TpBits issuing_tps;      // won a unit this cycle
    TpBits asking_tps;       // asked for a unit this cycle (kept only when profiling)
    // Its thread's next instruction is not private (InstructionSource::next_is_private): while
    // none is, the TM's cycles need no place in the order (cycle, TM) (Chip::tick_tms).
    TpBits shared_next_tps;
    // Timed sleeps: wheel_slots TpBits (a power of two above the longest sleep, at most
    // kMaxWheelSlots), the one for cycle t at t % wheel_slots.
    static constexpr uint64_t kMaxWheelSlots = 1024;
    uint64_t wheel_slots;
    bool sleeps_outlast_wheel;
    TpBits wheel;
    Counters counters;
    std::vector<LevelTraffic> l1_traffic;  // by region
    PcProfile* profile = nullptr;          // its host thread's lane, when the chip profiles
    PcCounters* outside_text = nullptr;    // ... and that lane's share of a pc outside the text
};

Chip::Chip(const ChipConfig& config, InstructionSource& source, const ChipLayout& layout)
    : config_(config), layout_(layout), source_(source), dram_(config.dram, config.l2.line_bytes),
      global_registers_(config.global_registers) {
    validate(config_);
    if (layout.regions.size() >= UINT8_MAX)
        throw std::invalid_argument(fmt::format("Chip: {} regions; at most {} fit a request's tag",
                                                layout.regions.size(), UINT8_MAX - 1));
    for (size_t r = 0; r < layout.regions.size(); ++r) {
        const Region& region = layout.regions[r];
        const bool reserved = std::find(std::begin(kReservedRegions), std::end(kReservedRegions),
                                        region.name) != std::end(kReservedRegions);
        if (region.name.empty() || region.name.find('/') != std::string::npos || reserved ||
            region.begin >= region.end)
            throw std::invalid_argument(fmt::format(
                "Chip: region '{}' [{:#x}, {:#x}) needs a name (not {}) without '/' and bytes",
                region.name, region.begin, region.end, fmt::join(kReservedRegions, ", ")));
        for (size_t q = 0; q < r; ++q)
            if (layout.regions[q].name == region.name)
                throw std::invalid_argument(
                    fmt::format("Chip: two regions are called '{}'", region.name));
        region_bounds_.push_back({region.begin, region.end, uint8_t(r)});
    }
    std::sort(region_bounds_.begin(), region_bounds_.end(),
              [](const RegionBounds& a, const RegionBounds& b) { return a.begin < b.begin; });
    for (size_t r = 1; r < region_bounds_.size(); ++r)
        if (region_bounds_[r].begin < region_bounds_[r - 1].end)
            throw std::invalid_argument(
                fmt::format("Chip: regions '{}' and '{}' overlap",
                            layout.regions[region_bounds_[r - 1].index].name,
                            layout.regions[region_bounds_[r].index].name));
    other_region_ = uint8_t(layout.regions.size());
    fetch_region_ = uint8_t(other_region_ + 1);
    work_items_.items.resize(layout.work_items);
    if (layout.profile) {
        profile_.text = layout.text;
        for (const TextRange& range : layout.text)
            profile_.words.resize(profile_.words.size() + range.words);
    }
    const size_t regions = layout.regions.size() + 1;
    l1_traffic_.resize(regions);
    l2_traffic_.resize(regions + 1);  // and fetch_region_
    dram_traffic_.resize(regions + 1);

    for (size_t fu = 0; fu < pool_of_.size(); ++fu)
        pool_of_[fu] = pool_of(isa::FuClass(fu));
    for (size_t p = 0; p < kPools; ++p)
        latency_of_[p] = pool_config(config.fu, Pool(p)).latency;
    for (uint32_t t = 0; t < config.chip.num_tms; ++t) {
        tms_.push_back(std::make_unique<Tm>(config, t, regions));
        tms_.back()->running = config.chip.tps_per_tm;
    }
    for (uint32_t g = 0; g < config.num_l2(); ++g)
        l2s_.emplace_back(config.l2, config.l2.write_combining_lines);
    clocks_.resize(config.chip.num_tms);
    // The lookahead: a TM's request reaches the shared parts at the earliest the cycle after
    // it was sent, and what they send back arrives no sooner than an L2 hit's or a
    // global-register reply's latency later; so the replies a TM receives in the next
    // `lookahead_` cycles are decided before those cycles begin.
    lookahead_ =
        std::min<uint64_t>(config.l2.hit_latency,
                           config.global_registers.latency + config.global_registers.link_latency);
    use_host_threads(1);
    for (auto& tm : tms_)
        for (uint32_t i = 0; i < config.chip.tps_per_tm; ++i)
            if (!source.next_is_private(tm->id * config.chip.tps_per_tm + i))
                set_bit(tm->shared_next_tps, i);
}

/// The TMs' host threads: lane 0 is the calling thread, lanes 1.. wait for work between runs.
struct Chip::HostThreads {
    explicit HostThreads(uint32_t lanes)
        : turns(lanes), lane(new Lane[lanes]), seen(lanes), start(lanes), done(lanes) {
        for (uint32_t lane = 1; lane < lanes; ++lane)
            threads.emplace_back([this, lane] {
                for (;;) {
                    start.arrive_and_wait();
                    if (stop) return;
                    (*job)(lane);
                    done.arrive_and_wait();
                }
            });
    }
    ~HostThreads() {
        stop = true;
        start.arrive_and_wait();
        for (std::thread& t : threads)
            t.join();
    }
    /// Runs job(lane) on every lane and returns when all are done; `job` must not throw.
    void run(const std::function<void(uint32_t)>& work) {
        job = &work;
        start.arrive_and_wait();
        work(0);
        done.arrive_and_wait();
    }
    uint32_t lanes() const { return turns.lanes(); }
    /// Whether every lane has ticked its TMs through the stretches before `stretch`.
    bool ticked_before(uint64_t stretch) const {
        for (uint32_t l = 0; l < lanes(); ++l)
            if (lane[l].ticked.value.load(std::memory_order_acquire) < stretch) return false;
        return true;
    }

    core::OrderedTurns turns;
    // A lane that failed: where in the order, and what (the earliest is rethrown).
    struct Failure {
        uint64_t position = core::OrderedTurns::kDone;
        std::exception_ptr error;
    };
    std::vector<Failure> failures = std::vector<Failure>(turns.lanes());
    std::atomic<uint64_t> first_failure{core::OrderedTurns::kDone};
    // The pipeline of a run (Chip::run_pipelined), counted in stretches of cycles from its
    // start: how many each lane has ticked its TMs through (and their progress in stretch k,
    // in progress[k % 2]: a lane is never more than one stretch ahead of the shared parts'
    // next), how many of the shared parts' stretches a lane has taken on and how many have run,
    // and how many of each may run at all (fewer once the chip has finished or something has
    // failed).
    struct alignas(core::kHostSpacing) Count {
        std::atomic<uint64_t> value{0};
    };
    // Each lane also measures its host time in one stretch of kTimedEvery, ticking its TMs
    // (less what it waited for turns) and running the shared parts (written by the lane, read
    // by lane 0 to balance the lanes).
    struct Busy {
        std::atomic<uint64_t> tm_ns{0}, shared_ns{0};
        uint64_t turn_ns = 0;  // the lane's own: waiting for turns, in every stretch
    };
    struct alignas(core::kHostSpacing) Lane {
        Count ticked;  // publishes `progress`
        std::array<Progress, 2> progress;
        Busy busy;
    };
    static constexpr uint64_t kTimedEvery = 8;
    std::unique_ptr<Lane[]> lane;
    Count shared_taken, shared;
    Count lane_limit, shared_limit;
    // Which TMs each lane ticks: lane l the block [bounds[l], bounds[l + 1]) (Chip::first_tm at
    // first). Every kBalanceStretches stretches (over runs) lane 0 may resize the blocks
    // (Chip::resize_blocks): every lane takes its block of next_bounds from stretch `switch_at`
    // of the run on (the next run's first if this one ends before: `pending`), once every lane
    // has ticked the stretch before. Only lane 0 reads the rest while the lanes run.
    static constexpr uint64_t kBalanceStretches = 1024;
    std::vector<uint32_t> bounds, next_bounds;
    Count switch_at;
    bool pending = false;
    uint64_t stretches = 0;  // lane 0's, over runs
    uint64_t moves = 0;
    std::vector<std::pair<uint64_t, uint64_t>> seen;  // each lane's Busy at lane 0's last look
    // Between runs the lanes sleep (after a short spin: runs follow each other closely).
    core::SpinBarrier<> start, done;
    bool stop = false;
    const std::function<void(uint32_t)>* job = nullptr;
    std::vector<std::thread> threads;
};

void Chip::use_host_threads(uint32_t threads) {
    const uint32_t lanes = std::clamp<uint32_t>(threads, 1, config_.chip.num_tms);
    if (lanes == lanes_) return;
    lanes_ = lanes;
    if (layout_.profile) collect();  // the lanes' counts so far go on in lane 0
    // An unset --threads alternates between one host thread and all (render::run_timing): the
    // host threads, with their blocks of TMs as balanced so far, wait through the runs on one.
    if (lanes > 1 && !(host_threads_ && host_threads_->lanes() == lanes)) {
        host_threads_ = std::make_unique<HostThreads>(lanes);
        for (uint32_t lane = 0; lane <= lanes; ++lane)
            host_threads_->bounds.push_back(first_tm(lane, lanes));
    }
    profile_lanes_.assign(layout_.profile ? lanes + 1 : 0, {});  // the last: the shared parts'
    for (ProfileLane& lane : profile_lanes_) {
        lane.profile.text = layout_.text;
        lane.profile.words.resize(profile_.words.size());
    }
    if (!profile_lanes_.empty()) profile_lanes_[0].profile.words = profile_.words;
    // Between runs: every TM, idle or not, has its lane's profile (the old lanes are gone).
    const std::vector<uint32_t> bounds =
        lanes > 1 ? host_threads_->bounds : std::vector<uint32_t>{0, uint32_t(tms_.size())};
    for (uint32_t lane = 0; lane < lanes; ++lane)
        for (uint32_t t = bounds[lane]; t < bounds[lane + 1]; ++t)
            join_lane(*tms_[t], lane);
}

void Chip::join_lane(Tm& tm, uint32_t lane) {
    tm.lane = lane;
    if (layout_.profile) {
        tm.profile = &profile_lanes_[lane].profile;
        tm.outside_text = &profile_lanes_[lane].outside_text;
    }
}

uint64_t Chip::lane_moves() const {
    return host_threads_ ? host_threads_->moves : 0;
}

void Chip::take_tms(uint32_t lane, uint32_t from, uint32_t to) {
    // A TM whose threads have all exited is the shared parts' (shared_stretch): not touched.
    for (uint32_t t = from; t < to; ++t)
        if (Tm& tm = *tms_[t]; tm.idle_from.load(std::memory_order_relaxed) == kNever)
            join_lane(tm, lane);
}

void Chip::resize_blocks(uint64_t stretch) {
    HostThreads& host = *host_threads_;
    const uint32_t lanes = host.lanes();
    // The last change must have reached every lane.
    if (host.pending) return;
    const uint64_t switched = host.switch_at.value.load(std::memory_order_relaxed);
    if (switched != kNever && !host.ticked_before(switched + 1)) return;
    std::vector<core::LaneLoad> loads(lanes);
    std::vector<bool> running(tms_.size());
    for (uint32_t t = 0; t < tms_.size(); ++t)
        running[t] = tms_[t]->idle_from.load(std::memory_order_relaxed) == kNever;
    for (uint32_t lane = 0; lane < lanes; ++lane) {
        const HostThreads::Busy& busy = host.lane[lane].busy;
        const auto now = std::pair{busy.tm_ns.load(std::memory_order_relaxed),
                                   busy.shared_ns.load(std::memory_order_relaxed)};
        auto& [tm_ns, shared_ns] = host.seen[lane];
        loads[lane] = {1e-9 * double(now.first - tm_ns),
                       uint32_t(std::count(running.begin() + host.bounds[lane],
                                           running.begin() + host.bounds[lane + 1], true)),
                       1e-9 * double(now.second - shared_ns)};
        host.seen[lane] = now;
    }
    // 2 %: what moving a TM's state to another core costs is paid back within the interval.
    std::vector<uint32_t> bounds = core::balance_lanes(host.bounds, loads, running, 0.02);
    if (bounds == host.bounds) return;
    host.next_bounds = std::move(bounds);
    host.pending = true;
    // No lane has begun stretch + 3: a lane ticks stretch k only once the shared parts have
    // run stretch k - 2, which waits for lane 0's stretch k - 2.
    host.switch_at.value.store(stretch + 3, std::memory_order_release);
}

Chip::Chip(const ChipConfig& config, MachineSource& source, const ChipLayout& layout)
    : Chip(config, static_cast<InstructionSource&>(source), layout) {
    run_cycles_ = &Chip::run_cycles<MachineSource>;
    warm_threads_ = &Chip::warm_threads<MachineSource>;
    // During TM t's tick of cycle `now`, clocks_[t] == now, so an instruction sees the cycle it
    // is fetched (and executed) in.
    clocked_machine_ = &source.machine();
    clocked_machine_->clock_by(&clocks_[0].now, sizeof(TmClock) / sizeof(uint64_t));
}

Chip::~Chip() {
    if (clocked_machine_) clocked_machine_->clock_by(nullptr, 0);
}

bool Chip::run_until(uint64_t cycle) {
    fetching_ = true;
    return (this->*run_cycles_)(cycle);
}

bool Chip::quiescent() const {
    for (const auto& tm : tms_) {
        for (uint32_t w = 0; w < tm->words; ++w)
            if (tm->pending_tps[w] | tm->mem_waiting_tps[w]) return false;
        // A TP asleep until a reply still has a load, an atomic or an instruction line in
        // flight.
        for (const Tm::Tp& tp : tm->tps)
            if (tp.wake_at == kNever || tp.wake_at == kFetchWait) return false;
        if (tm->holds_traffic() || !tm->atomics_out.empty() || !tm->outbox.atomics.empty() ||
            !tm->at_shared.atomics.empty())
            return false;
    }
    for (const Cache& l2 : l2s_)
        if (l2.outstanding_misses() || !l2.outbound().empty()) return false;
    return dram_.idle() && global_registers_.idle();
}

bool Chip::drain() {
    fetching_ = false;
    while (!finished_ && !quiescent())
        (this->*run_cycles_)(cycles_ + 1);
    // Branch bubbles and timed operand waits end within the longest timed sleep.
    for (uint64_t end = cycles_ + longest_timed_sleep(config_) + 1; !finished_ && cycles_ < end;)
        (this->*run_cycles_)(cycles_ + 1);
    fetching_ = true;
    return finished_;
}

Chip::Warming Chip::warm(uint64_t instructions) {
    for (TmClock& clock : clocks_)
        clock.now = cycles_;
    return (this->*warm_threads_)(instructions);
}

uint32_t Chip::warm_access(Tm& tm, uint32_t addr, bool store) {
    if (tm.l1.warm(addr, store)) return 0;
    Cache& l2 = l2s_[tm.id / config_.chip.tms_per_l2];
    // Stores go around the L1 (write-around) and reach DRAM as line writes; a load that
    // misses both caches opens its row. A store waits for nothing.
    const bool l2_hit = l2.warm(addr, store);
    if (!l2_hit || store) dram_.warm(addr);
    if (store) return 0;
    const uint32_t to_l2 = config_.l1.hit_latency + config_.l2.hit_latency;
    return l2_hit ? to_l2 : to_l2 + config_.dram.tRCD + config_.dram.tCL + config_.dram.tBURST;
}

namespace {

/// Functional warming's step for any instruction source: one step() at a time, as
/// MachineSource::warm does it in bulk.
template <class Observer>
bool warm_thread(InstructionSource& source, uint32_t thread, uint64_t budget, uint64_t& executed,
                 StepInfo& last, Observer& observer) {
    for (executed = 0; executed < budget;) {
        StepInfo s;
        source.step(thread, s);
        ++executed;
        if (MachineSource::replay(s, last, observer)) return true;
    }
    return false;
}

template <class Observer>
bool warm_thread(MachineSource& source, uint32_t thread, uint64_t budget, uint64_t& executed,
                 StepInfo& last, Observer& observer) {
    return source.warm(thread, budget, executed, last, observer);
}

}  // namespace

/// What functional warming does with one thread's accesses (core::ThreadEnv's observer).
struct Chip::WarmingObserver {
    Chip& chip;
    Tm& tm;
    Tm::Tp& tp;

    uint64_t waited = 0;  // cycles the thread's loads would wait below its L1 (roughly)

    void access(uint32_t addr, uint8_t, bool store) {
        if (core::in_local_store(addr))
            tp.lowest_local = std::min(tp.lowest_local, addr);
        else
            waited += chip.warm_access(tm, addr, store);
    }
    void atomic(uint32_t global_register, uint32_t old) {
        if (global_register != 0) return;
        // A new work item, as when the cycle-level model issues the increment.
        chip.charge_item(tp.item, chip.cycles_ - tp.item_since, tp.item_instructions);
        tp.item = old;
        tp.item_since = chip.cycles_;
        tp.item_instructions = 0;
    }
};

template <class Source> Chip::Warming Chip::warm_threads(uint64_t instructions) {
    Source& source = static_cast<Source&>(source_);
    // Threads take short turns. What the next cycle-level unit inherits is the L1's content,
    // and an L1 filled by turns of hundreds of instructions holds each thread's lines in long
    // runs, not interleaved as cycle by cycle: the units then overestimate the L1 hit rate
    // (bunny 256x256: +0.8 % with turns of 256, outside its +-0.3 % interval; +0.05 % with 32,
    // which costs 15-20 % of the warming speed; ending a long-turn warming with short turns
    // did not remove the bias).
    constexpr uint64_t kTurn = 32;
    Warming done;
    const uint32_t n = config_.chip.tps_per_tm;
    // Threads that may run: awake (not exited or waiting at a barrier), holding nothing.
    std::vector<uint8_t> may_run(size_t(n) * tms_.size());
    uint64_t runnable = 0;
    for (auto& tm : tms_)
        for (uint32_t i = 0; i < n; ++i) {
            const bool free = test_bit(tm->awake_tps, i) && !test_bit(tm->pending_tps, i);
            may_run[tm->id * n + i] = free;
            runnable += free;
        }
    // Each thread's progress in rough cycles: an instruction each, plus what its loads would
    // wait below the L1. A thread takes its turn only while behind the round's horizon, so the
    // threads keep roughly the relative progress they would have cycle by cycle (one in costly
    // pixels falls behind), which the next cycle-level unit inherits (bunny 256x256: operand
    // stalls -0.4 % without, +0.1 % with, +-0.5 %).
    std::vector<uint64_t> clock(may_run.size(), 0);
    // Until the budget is spent, every thread has stopped, or one has reached its exit: the
    // frame's ragged end, where threads run out of work, is left to the cycle-level model.
    for (uint64_t horizon = kTurn;
         runnable != 0 && done.instructions < instructions && !done.reached_exit; horizon += kTurn)
        for (auto& tm : tms_)
            for (uint32_t i = 0; i < n && !done.reached_exit; ++i) {
                const uint32_t thread = tm->id * n + i;
                if (!may_run[thread] || clock[thread] >= horizon) continue;
                Tm::Tp& tp = tm->tps[i];
                WarmingObserver observer{*this, *tm, tp};
                uint64_t executed = 0;
                const bool stopped =
                    warm_thread(source, thread, kTurn, executed, tp.pending, observer);
                clear_bit(tm->shared_next_tps, i);
                if (!(stopped && tp.pending.exited) && !source.next_is_private(thread))
                    set_bit(tm->shared_next_tps, i);
                if (stopped) {
                    // The cycle-level model issues it: the exit counts the thread out, a
                    // synchronisation instruction goes to the global-register unit.
                    tp.pending_pool = pool_of_[size_t(tp.pending.insn->fu)];
                    set_bit(tm->pending_tps, i);
                    may_run[thread] = 0;
                    --runnable;
                    done.reached_exit |= tp.pending.exited;
                    --executed;  // the cycle-level model counts it when it issues
                }
                done.instructions += executed;
                clock[thread] += executed + observer.waited;
            }
    warmed_instructions_ += done.instructions;
    return done;
}

uint64_t Chip::run(uint64_t max_cycles) {
    if (!run_until(max_cycles))
        throw std::runtime_error(fmt::format(
            "timing: the chip did not finish within {} cycles; raise the cycle limit", max_cycles));
    return cycles_;
}

bool Chip::busy(uint64_t at) const {
    // A TM still running may be ticking on another host thread: only its idle_from is read.
    // A global-register reply delivered to a TM but not received yet is still in flight.
    for (const auto& tm : tms_)
        if (tm->idle_from.load(std::memory_order_relaxed) > at || tm->holds_traffic()) return true;
    for (const Cache& l2 : l2s_)
        if (l2.outstanding_misses() || !l2.outbound().empty()) return true;
    return !dram_.idle() || !global_registers_.idle();
}

bool Chip::drained() const {
    return !busy(cycles_) && std::none_of(l2s_.begin(), l2s_.end(), [](const Cache& l2) {
        return l2.holds_combined_lines();
    });
}

uint8_t Chip::region_of(uint32_t addr) const {
    // The last region starting at or below addr, if addr is inside it.
    const auto after =
        std::upper_bound(region_bounds_.begin(), region_bounds_.end(), addr,
                         [](uint32_t a, const RegionBounds& r) { return a < r.begin; });
    if (after == region_bounds_.begin() || addr >= after[-1].end) return other_region_;
    return after[-1].index;
}

void Chip::collect() {
    std::fill(l1_traffic_.begin(), l1_traffic_.end(), LevelTraffic{});
    local_payload_bytes_ = 0;
    for (const auto& tm : tms_) {
        for (size_t r = 0; r < l1_traffic_.size(); ++r) {
            LevelTraffic& sum = l1_traffic_[r];
            const LevelTraffic& t = tm->l1_traffic[r];
            sum.reads += t.reads, sum.writes += t.writes, sum.hits += t.hits;
            sum.misses += t.misses, sum.merged_misses += t.merged_misses;
            sum.payload_bytes += t.payload_bytes, sum.moved_bytes += t.moved_bytes;
        }
        local_payload_bytes_ += tm->counters.local_payload_bytes;
        for (const Tm::Tp& tp : tm->tps)
            local_store_high_water_ =
                std::max<uint64_t>(local_store_high_water_, trax::map::kLocalTop - tp.lowest_local);
    }
    if (!profile_lanes_.empty()) {
        std::fill(profile_.words.begin(), profile_.words.end(), PcCounters{});
        for (const ProfileLane& lane : profile_lanes_)
            for (size_t w = 0; w < profile_.words.size(); ++w) {
                PcCounters& sum = profile_.words[w];
                const PcCounters& c = lane.profile.words[w];
                sum.executions += c.executions;
                for (size_t k = 0; k < kStalls; ++k)
                    sum.stalls[k] += c.stalls[k];
                sum.l1_misses += c.l1_misses;
                sum.dram_bytes += c.dram_bytes;
            }
    }
}

// Stretches of cycles: the TMs' ticks (on the host threads), then the shared parts' ticks of
// the same cycles (docs/hardware-model.md, "Parallel simulation").
template <class Source> bool Chip::run_cycles(uint64_t end) {
    // The constructor chose Source to be the source's own type.
    Source& source = static_cast<Source&>(source_);
    // A short run (drain() runs one cycle at a time) is not worth waking the host threads;
    // either way gives the same result.
    constexpr uint64_t kShortestParallelRun = 256;
    if (lanes_ > 1 && end >= cycles_ + kShortestParallelRun && !finished_) {
        run_pipelined(end, source);
    } else {
        while (cycles_ < end && !finished_) {
            const uint64_t first = cycles_;
            const uint64_t stretch_end = std::min(end, first + lookahead_);
            const Progress progress =
                tick_tms(0, 0, uint32_t(tms_.size()), first, stretch_end, source);
            shared_stretch(first, stretch_end, progress, source);
        }
    }
    source.passed(cycles_);  // a paused chip's steps are all visible
    finished_ = finished_ || drained();
    collect();
    return finished_;
}

template <class Source> void Chip::run_pipelined(uint64_t end, Source& source) {
    HostThreads& host = *host_threads_;
    tms_in_parallel_ = true;
    struct Serial {
        bool& parallel;
        ~Serial() { parallel = false; }
    } serial_after{tms_in_parallel_};
    const uint32_t lanes = host.lanes();
    // Stretches of half the lookahead: the shared parts run stretch s once every lane has
    // ticked it, while the lanes' TMs run stretch s + 1 or s + 2. What a TM receives in
    // stretch k was decided a lookahead earlier, by stretch k - 2 at the latest; so no lane
    // waits for another unless one falls more than a stretch behind. (A lookahead of 1 leaves
    // stretches of 1 cycle, each after the shared parts' last.)
    const uint64_t stretch = std::max<uint64_t>(lookahead_ / 2, 1);
    const uint64_t lag = lookahead_ >= 2 ? 1 : 0;
    const uint64_t first = cycles_;
    const auto begin = [&](uint64_t k) { return first + k * stretch; };
    const auto finish = [&](uint64_t k) { return std::min(end, begin(k) + stretch); };
    const auto load = [](const HostThreads::Count& c) {
        return c.value.load(std::memory_order_acquire);
    };
    for (uint32_t lane = 0; lane < lanes; ++lane)
        host.lane[lane].ticked.value = 0;
    host.shared_taken.value = host.shared.value = 0;
    host.lane_limit.value = host.shared_limit.value = kNever;
    host.switch_at.value = host.pending ? 0 : kNever;
    const auto add_time = [](std::atomic<uint64_t>& sum, uint64_t ns) {
        sum.store(sum.load(std::memory_order_relaxed) + ns, std::memory_order_relaxed);
    };
    const uint32_t spins = core::spins_for(lanes);
    std::exception_ptr shared_error;

    // The shared parts' next stretch, once every lane has ticked it, on one lane at a time:
    // lane 0 after its TMs' stretch (their state stays in its core's caches), or a lane that
    // would otherwise wait for it (lane 0 carries the serial work on top of its TMs').
    // Returns whether it ran one.
    const auto run_shared = [&](uint32_t lane) {
        const uint64_t s = load(host.shared);
        if (begin(s) >= end || s >= load(host.shared_limit)) return false;
        if (!host.ticked_before(s + 1)) return false;
        uint64_t untaken = s;  // no lane has taken stretch s on (nor is running an earlier one)
        if (!host.shared_taken.value.compare_exchange_strong(untaken, s + 1)) return false;
        Progress progress;
        for (uint32_t l = 0; l < lanes; ++l)
            progress.add(host.lane[l].progress[s % 2]);
        const bool timed = s % HostThreads::kTimedEvery == 0;
        const HostClock::time_point start = timed ? HostClock::now() : HostClock::time_point{};
        try {
            shared_stretch(begin(s), finish(s), progress, source);
            if (timed) add_time(host.lane[lane].busy.shared_ns, nanoseconds_since(start));
        } catch (...) {  // nothing from stretch s on counts: the lanes stop
            shared_error = std::current_exception();
            lower(host.lane_limit.value, s);
            lower(host.shared_limit.value, s);
            return true;
        }
        if (finished_) {  // the lanes' later stretches have only idle TMs: they stop
            lower(host.lane_limit.value, s + 1);
            lower(host.shared_limit.value, s + 1);
        }
        host.shared.value.store(s + 1, std::memory_order_release);
        return true;
    };
    const auto lane_work = [&](uint32_t lane) {
        uint32_t from = host.bounds[lane], to = host.bounds[lane + 1];
        for (uint64_t k = 0; begin(k) < end; ++k) {
            // Stretch k receives what the shared parts' stretch k - lag - 1 decided.
            const auto may_tick = [&] {
                return load(host.shared) + lag >= k || k >= load(host.lane_limit);
            };
            core::spin_until([&] { return may_tick() || (run_shared(lane) && may_tick()); }, spins);
            // New blocks from this stretch on: each lane's TMs must have left stretch k - 1
            // behind first.
            const bool new_blocks = k == load(host.switch_at);
            if (new_blocks)
                core::spin_until(
                    [&] {
                        if (host.ticked_before(k) || k >= load(host.lane_limit)) return true;
                        run_shared(lane);
                        return false;
                    },
                    spins);
            if (k >= load(host.lane_limit)) {  // stopped early: other lanes' steps wait no more
                host.turns.reach(lane, core::OrderedTurns::kDone);
                break;
            }
            if (new_blocks) {
                from = host.next_bounds[lane], to = host.next_bounds[lane + 1];
                take_tms(lane, from, to);
                if (lane == 0) {
                    host.bounds = host.next_bounds;
                    host.pending = false;
                    ++host.moves;
                }
            }
            HostThreads::Busy& busy = host.lane[lane].busy;
            const bool timed = k % HostThreads::kTimedEvery == 0;
            const HostClock::time_point start = timed ? HostClock::now() : HostClock::time_point{};
            const uint64_t waited = busy.turn_ns;
            if (!tick_lane(lane, from, to, k, begin(k), finish(k), source)) break;
            if (timed) add_time(busy.tm_ns, nanoseconds_since(start) - (busy.turn_ns - waited));
            if (lane == 0) {
                run_shared(lane);
                if (++host.stretches % HostThreads::kBalanceStretches == 0) resize_blocks(k);
            }
        }
        // The shared parts' stretches left, on whichever lanes come for them.
        core::spin_until(
            [&] {
                run_shared(lane);
                const uint64_t s = load(host.shared);
                return begin(s) >= end || s >= load(host.shared_limit);
            },
            spins);
    };
    host.run(lane_work);
    if (shared_error) std::rethrow_exception(shared_error);
    if (const uint64_t failed = host.first_failure.load(); failed != core::OrderedTurns::kDone)
        for (const HostThreads::Failure& failure : host.failures)
            if (failure.position == failed) std::rethrow_exception(failure.error);
}

template <class Source>
void Chip::shared_stretch(uint64_t first, uint64_t end, Progress progress, Source& source) {
    take_hand_overs();
    // TMs whose threads have all exited by the end of the stretch are ticked here from then on
    // (they only receive their fills and replies), with their profile counts in this host
    // thread's lane.
    const auto idle_in_stretch = [&](const Tm& tm) {
        return tm.idle_from.load(std::memory_order_relaxed) < end;
    };
    for (auto& tm : tms_)
        if (idle_in_stretch(*tm)) {
            tm->take_mail();
            if (tm->profile) {
                tm->profile = &profile_lanes_.back().profile;
                tm->outside_text = &profile_lanes_.back().outside_text;
            }
        }
    shared_progress_ = {};
    uint64_t now = first;
    for (; now < end; ++now) {
        if (!busy(now)) {
            // Every thread has exited: the write-combining buffers drain, then the chip is
            // done. (No TM has ticked this cycle: each stops when its last thread exits.)
            bool drained_lines = false;
            for (Cache& l2 : l2s_)
                drained_lines |= l2.drain_write_buffer(now);
            if (!drained_lines) {
                finished_ = true;
                break;
            }
        }
        for (auto& tm : tms_)
            if (tm->idle_from.load(std::memory_order_relaxed) <= now) tm_cycle(*tm, now, source);
        tick_shared(now);
    }
    cycles_ = now;
    // Every TM has ticked the stretch: every few hundred cycles, the source makes visible what
    // it held back of the steps before it (so that it holds little).
    if (now / kPassedEvery != first / kPassedEvery) source.passed(now);
    for (auto& tm : tms_)
        if (idle_in_stretch(*tm)) progress.add(std::exchange(tm->progress_cycles, {}));
    progress.add(shared_progress_);
    // The first cycle the serial loop would have found without progress for too long.
    const uint64_t stuck = last_progress_cycle_ + kDeadlockCycles + 1;
    if (stuck < cycles_ && progress.first > stuck)
        throw std::runtime_error(
            fmt::format("timing: deadlock, nothing issued or returned for {} cycles (cycle {}); "
                        "this is a simulator bug, please report it with the config",
                        kDeadlockCycles, stuck));
    if (progress.first != kNever) last_progress_cycle_ = progress.last;
    deliver();
}

void Chip::take_hand_overs() {
    for (auto& tm : tms_) {
        Tm::Outbox& box = tm->outbox;
        if (!box.holds_mail.load(std::memory_order_acquire)) continue;
        std::lock_guard hold(box.lock);
        box.holds_mail.store(false, std::memory_order_relaxed);
        move_to_back(tm->at_shared.requests, box.requests);
        move_to_back(tm->at_shared.atomics, box.atomics);
        for (const Tm::ItemCharge& c : box.charges)
            charge_item(c.item, c.cycles, c.instructions);
        box.charges.clear();
    }
}

void Chip::deliver() {
    MemReply reply;
    for (Cache& l2 : l2s_)
        while (l2.pop_reply(kNever, reply))
            tms_[reply.request.source]->inbox.post(Tm::Fill{
                reply.ready, reply.request.addr,
                reply.request.region == fetch_region_ ? reply.request.tag : Tm::kDataLine});
    AtomicReply atomic;
    while (global_registers_.pop_reply(kNever, atomic))
        tms_[atomic.request.tm]->inbox.post(atomic);
}

template <class Source>
Chip::Progress Chip::tick_tms(uint32_t lane, uint32_t from, uint32_t to, uint64_t first,
                              uint64_t end, Source& source) {
    const uint64_t tms = tms_.size();
    // Each TM ticks the stretch's cycles in a row, its state hot in the host's caches, until a
    // thread's next instruction is not private: from that cycle on, the TM ticks in the order
    // (cycle, TM), where steps other threads can see must happen. A fault on the way is raised
    // at its place in that order, as one in order would be.
    uint64_t ordered_from = end;
    for (uint32_t t = from; t < to; ++t) {
        Tm& tm = *tms_[t];
        if (tm.running == 0) continue;
        tm.take_mail();
        for (uint32_t i = 0, n = config_.chip.tps_per_tm; i < n; ++i)
            source.prefetch_next(tm.id * n + i);
        uint64_t now = first;
        try {
            for (; now < end && tm.running != 0 && !tm.steps_shared_next(); ++now)
                tm_cycle(tm, now, source);
        } catch (...) {
            tm.fault_due = std::current_exception();
        }
        tm.ordered_from = now;
        ordered_from = std::min(ordered_from, now);
    }
    for (uint64_t now = ordered_from; now < end; ++now)
        for (uint32_t t = from; t < to; ++t) {
            Tm& tm = *tms_[t];
            if (tm.running == 0 || tm.ordered_from > now) continue;
            if (tms_in_parallel_)
                host_threads_->turns.reach(lane, core::chip_position(now, t, tms));
            if (tm.fault_due) std::rethrow_exception(std::exchange(tm.fault_due, nullptr));
            tm_cycle(tm, now, source);
        }
    if (tms_in_parallel_) host_threads_->turns.reach(lane, core::chip_position(end, 0, tms));
    // Every TM that ticked in the stretch (one idle before it is the shared parts').
    Progress progress;
    for (uint32_t t = from; t < to; ++t)
        if (Tm& tm = *tms_[t]; tm.idle_from.load(std::memory_order_relaxed) > first) {
            tm.hand_over();
            progress.add(std::exchange(tm.progress_cycles, {}));
        }
    return progress;
}

template <class Source>
bool Chip::tick_lane(uint32_t lane, uint32_t from, uint32_t to, uint64_t stretch, uint64_t first,
                     uint64_t end, Source& source) {
    HostThreads& host = *host_threads_;
    try {
        host.lane[lane].progress[stretch % 2] = tick_tms(lane, from, to, first, end, source);
        host.lane[lane].ticked.value.store(stretch + 1, std::memory_order_release);
        return true;
    } catch (const core::OrderedTurns::Abandoned&) {
    } catch (...) {
        // What failed first in the order is what one host thread would have seen: wait until
        // everything before it has happened, so that a fault reports the output printed so far.
        const uint64_t position = host.turns.position(lane);
        host.turns.wait_turn(lane, position);
        std::exception_ptr error = std::current_exception();
        try {
            throw;
        } catch (const core::Fault& f) {
            if (clocked_machine_)
                error = std::make_exception_ptr(f.with_output(clocked_machine_->output()));
        } catch (...) {
        }
        host.failures[lane] = {position, error};
        // The lanes tick up to this stretch (an earlier failure may yet come), the shared parts
        // run only the stretches before it.
        lower(host.lane_limit.value, stretch + 1);
        lower(host.shared_limit.value, stretch);
        lower(host.first_failure, position);
    }
    host.turns.reach(lane, core::OrderedTurns::kDone);
    return false;
}

void Chip::wait_turn(const Tm& tm, uint64_t now) {
    HostThreads& host = *host_threads_;
    const uint64_t position = core::chip_position(now, tm.id, tms_.size());
    if (!host.turns.passed(tm.lane, position)) {  // the time waited is not the lane's work
        const HostClock::time_point start = HostClock::now();
        host.turns.wait_turn(tm.lane, position);
        host.lane[tm.lane].busy.turn_ns += nanoseconds_since(start);
    }
    if (host.first_failure.load() < position) throw core::OrderedTurns::Abandoned{};
}

template <class Source> void Chip::tm_cycle(Tm& tm, uint64_t now, Source& source) {
    clocks_[tm.id].now = now;
    const uint64_t progress = tm.progress;
    tm.keep_epoch_near(now);
    tm.receive(now);
    // TMs of up to 64 TPs (one word per bit set) take a loop without word loops; the
    // profile's bookkeeping is compiled in only where it is collected.
    const bool one_word = config_.chip.tps_per_tm <= 64;
    if (tm.running == 0)
        ;  // every thread has exited: it only receives
    else if (layout_.profile)
        one_word ? tick_tm<Source, 1, true>(tm, now, source)
                 : tick_tm<Source, 0, true>(tm, now, source);
    else
        one_word ? tick_tm<Source, 1, false>(tm, now, source)
                 : tick_tm<Source, 0, false>(tm, now, source);
    if (tm.progress != progress) tm.progress_cycles.add(now);
}

uint32_t Chip::running_threads() const {
    uint32_t running = 0;
    for (const auto& tm : tms_)
        running += tm->running;
    return running;
}

// Shared parts, in a fixed order: DRAM -> L2 fills, then requests L1 -> L2 -> DRAM (so a
// request reaches DRAM in the cycle it leaves L2), then the global registers. TMs are always
// visited in id order, each TM's queue in FIFO order. (L2 -> L1 fills and global-register
// replies reach the TMs through deliver().)
void Chip::tick_shared(uint64_t now) {
    MemReply reply;
    while (dram_.pop_reply(now, reply)) {
        l2s_[reply.request.source].fill(now, reply.request.addr);
        shared_progress_.add(now);
    }

    const uint32_t line_bytes = config_.l2.line_bytes;
    for (uint32_t t = 0; t < tms_.size(); ++t) {
        auto& out = tms_[t]->at_shared.requests;
        Cache& l2 = l2s_[t / config_.chip.tms_per_l2];
        while (!out.empty() && out.front().cycle <= now) {
            MemRequest request = out.front().request;
            request.source = t;
            const CacheOutcome outcome = l2.access(now, request);
            if (!accepted(outcome)) break;  // retry next cycle, keep FIFO order
            count_access(l2_traffic_[request.region], outcome,
                         request.write ? request.bytes : line_bytes, 0);
            out.pop_front();
        }
    }
    for (uint32_t g = 0; g < l2s_.size(); ++g) {
        auto& out = l2s_[g].outbound();
        while (!out.empty() && out.front().cycle <= now) {
            MemRequest request = out.front().request;
            request.source = g;
            if (!dram_.enqueue(now, request)) break;
            l2_traffic_[request.region].moved_bytes += line_bytes;
            out.pop_front();
        }
    }
    dram_.tick(now);
    PcProfile* profile = profile_lanes_.empty() ? nullptr : &profile_lanes_.back().profile;
    for (const MemRequest& served : dram_.served()) {
        LevelTraffic& t = dram_traffic_[served.region];
        ++(served.write ? t.writes : t.reads);
        t.payload_bytes += served.write ? served.bytes : line_bytes;
        t.moved_bytes += line_bytes;
        item_costs(served.item).dram_bytes += line_bytes;
        if (profile)
            if (PcCounters* pc = profile->at(served.pc)) pc->dram_bytes += line_bytes;
    }
    dram_.served().clear();
    // Requests sent in an earlier cycle (the TMs have already ticked this one).
    for (auto& tm : tms_)
        for (auto& out = tm->at_shared.atomics; !out.empty() && out.front().sent < now;
             out.pop_front())
            global_registers_.submit(out.front());
    global_registers_.tick(now);
}

void Chip::send_sync(Tm& tm, uint32_t i, const StepInfo& s, uint64_t now) {
    const isa::Op op = s.insn->op;
    const GlobalRequest kind = op == isa::Op::tp_barrier  ? GlobalRequest::Barrier
                               : op == isa::Op::tp_semacq ? GlobalRequest::SemAcquire
                                                          : GlobalRequest::SemRelease;
    tm.atomics_out.push_back({now, tm.id, tm.atomic_sequence++, i, 0, kind, s.value,
                              tm.id * config_.chip.tps_per_tm + i});
    // Asleep until the unit's reply (wake_from_sync): the TP fetches nothing meanwhile.
    Tm::Tp& tp = tm.tps[i];
    clear_bit(tm.awake_tps, i);
    tp.wake_at = kSyncWait;
    tp.asleep_from = now + 1;
}

template <class Source, uint32_t kWords, bool kProfile>
void Chip::tick_tm(Tm& tm, uint64_t now, Source& source) {
    const uint32_t words = kWords != 0 ? kWords : tm.words;  // kWords: known at compile time
    const uint32_t n = static_cast<uint32_t>(tm.tps.size());
    // The profile's share of a stall or event: the instruction at `pc`.
    const auto profile_at = [&](uint32_t pc) -> PcCounters& {
        PcCounters* counters = tm.profile->at(pc);
        return counters ? *counters : *tm.outside_text;
    };

    // Granted loads/stores take their L1 bank in rotating order.
    for_each_rotated_part(words, tm.rotation, [&](const RotatedPart& part) {
        uint64_t accessed = 0;
        for (uint64_t bits = part.of(tm.mem_waiting_tps[part.w]); bits != 0; bits &= bits - 1) {
            const auto bit = static_cast<uint32_t>(std::countr_zero(bits));
            const Tm::Tp& tp = tm.tps[part.index(bit)];
            if (tp.mem_at > now) continue;
            const MemRequest& request = tp.mem_request;
            const CacheOutcome outcome = tm.l1.access(now, request);
            if (!accepted(outcome)) continue;
            accessed |= uint64_t{1} << bit;
            const uint64_t moved = outcome == CacheOutcome::Miss ? tm.l1.config().line_bytes
                                   : request.write               ? request.bytes
                                                                 : 0;
            count_access(tm.l1_traffic[request.region], outcome, request.bytes, moved);
            if constexpr (kProfile)
                profile_at(request.pc).l1_misses += outcome == CacheOutcome::Miss;
        }
        tm.mem_waiting_tps[part.w] &= ~part.back(accessed);
    });

    // Every awake TP: fetch if it holds no instruction, check the scoreboard, request a unit.
    // Done in passes over bit sets, each pass a short loop with few data-dependent branches.
    // Only fetch depends on the order (I-cache banks, and the functional step, whose
    // shared-memory effects must happen in fetch order): it goes in rotating order. On several
    // host threads, the first step that is not private waits for this TM's turn in the cycle.
    tm.wake_timed(now);
    const uint32_t now_offset = tm.epoch.offset(now);
    Tm::Tp* const tps = tm.tps.data();
    const uint32_t first_thread = tm.id * n;
    auto& counters = tm.counters;
    bool my_turn = !tms_in_parallel_;
    // Forced inline (GCC keeps a lambda called from two sites out of line): out of line, its
    // captures are reloaded through memory at every use.
    const auto fetch_part = [&](const RotatedPart& part) __attribute__((always_inline)) {
        const uint32_t w = part.w;
        const uint64_t fetching = part.of(tm.awake_tps[w] & ~tm.pending_tps[w]);
        const uint64_t granted = tm.icache.fetch(
            now, fetching, [&](uint32_t bit) { return part.index(bit); },
            [&](uint32_t i) { return source.next_pc(first_thread + i); });
        counters.stalls[size_t(Stall::FetchConflict)] += count_bits(fetching & ~granted);
        if constexpr (kProfile)
            for (uint64_t bits = fetching & ~granted; bits != 0; bits &= bits - 1) {
                const uint32_t thread = first_thread + part.index(uint32_t(std::countr_zero(bits)));
                ++profile_at(source.next_pc(thread)).stalls[size_t(Stall::FetchConflict)];
            }
        const uint64_t fetched =
            tm.lines ? fetch_lines<Source, kProfile>(tm, part, granted, now, source) : granted;
        uint64_t needs_port = 0, shared_next = 0;
        for (uint64_t bits = fetched; bits != 0; bits &= bits - 1) {
            const auto bit = static_cast<uint32_t>(std::countr_zero(bits));
            const uint32_t i = part.index(bit);
            Tm::Tp& tp = tps[i];
            if (!my_turn && !source.next_is_private(first_thread + i)) [[unlikely]] {
                wait_turn(tm, now);
                my_turn = true;
            }
            source.step(first_thread + i, tp.pending);
            shared_next |= uint64_t{!tp.pending.exited && !source.next_is_private(first_thread + i)}
                           << bit;
            tp.pending_pool = pool_of_[size_t(tp.pending.insn->fu)];
            const bool global_access =  // bitwise &: no branch on an unpredictable outcome
                (tp.pending_pool == Pool::LoadStore) &
                !core::in_local_store(tp.pending.mem_address);
            needs_port |= uint64_t{global_access} << bit;
        }
        tm.needs_port_tps[w] |= part.back(needs_port);
        tm.shared_next_tps[w] =
            (tm.shared_next_tps[w] & ~part.back(fetched)) | part.back(shared_next);
        tm.pending_tps[w] |= part.back(fetched);
    };
    if (fetching_) for_each_rotated_part(words, tm.rotation, fetch_part);

    uint32_t requested_pools = 0;  // bit per pool with a request this cycle
    for (uint32_t w = 0; w < words; ++w) {
        const uint64_t visiting = tm.awake_tps[w];
        counters.active_tp_cycles += count_bits(visiting);

        // Scoreboard: ready when every operand (and rd: no write-after-write reorder) is. A
        // ready TP asks its pool for a unit, unless it is a global load/store and the previous
        // one has not reached its L1 bank yet (one L1 access at a time per TP).
        const uint64_t holding = visiting & tm.pending_tps[w];
        const uint64_t port_taken = tm.needs_port_tps[w] & tm.mem_waiting_tps[w];
        uint64_t ready = 0;
        std::array<uint64_t, kPools> asking{};  // this word's requesters, by pool
        for_each_bit(w, holding, [&](uint32_t i) {
            const isa::Decoded& d = *tps[i].pending.insn;
            const uint32_t* at = tps[i].reg_ready.data();
            const uint32_t operands_at =
                std::max(std::max(at[d.rs1], at[d.rs2]), std::max(at[d.rs3], at[d.rd]));
            const uint64_t bit = uint64_t{operands_at <= now_offset} << (i & 63);
            ready |= bit;
            asking[size_t(tps[i].pending_pool)] |= bit & ~port_taken;  // no branch either way
        });
        for_each_bit(w, holding & ~ready, [&](uint32_t i) {
            Tm::Tp& tp = tps[i];
            const isa::Decoded& d = *tp.pending.insn;
            const std::array<uint8_t, 4> regs = {d.rs1, d.rs2, d.rs3, d.rd};
            uint32_t last_ready = 0;
            for (uint8_t r : regs)
                last_ready = std::max(last_ready, tp.reg_ready[r]);
            Pool blocking = Pool::IntAlu;  // producer of the first operand that is ready last
            for (uint8_t r : regs)
                if (r != isa::kNoReg && tp.reg_ready[r] == last_ready) {
                    blocking = tp.reg_producer[r];
                    break;
                }
            const uint64_t operands_at = tm.epoch.cycle(last_ready);
            ++counters.stalls[size_t(Stall::Operand)];
            ++counters.operand_stalls[size_t(blocking)];
            if constexpr (kProfile)
                profile_at(tp.pending.pc).stalls[size_t(Stall::Operand)] +=
                    operands_at == kNever ? 1 : operands_at - now;
            // Nothing can change this wait before operands_at but a reply for this TP, which
            // wakes it; so the cycles in between are operand stalls on `blocking`.
            if (operands_at == kNever) {
                tp.wake_at = kNever;
                clear_bit(tm.awake_tps, i);
                tp.asleep_from = now + 1;
                tp.asleep_on = blocking;
            } else {
                tm.add_operand_stalls(blocking, operands_at - now - 1);
                tm.sleep_until(i, operands_at, now);
            }
        });

        counters.stalls[size_t(Stall::MemoryPort)] += count_bits(ready & port_taken);
        if constexpr (kProfile) {
            for_each_bit(w, ready & port_taken, [&](uint32_t i) {
                ++profile_at(tps[i].pending.pc).stalls[size_t(Stall::MemoryPort)];
            });
            tm.asking_tps[w] = ready & ~port_taken;
        }
        for (size_t p = 0; p < kPools; ++p)
            if (asking[p] != 0) {
                tm.pools[p].request(w, asking[p]);
                requested_pools |= 1u << p;
            }
    }

    // Requests the pools refuse are the FU-busy stalls (the TP keeps its instruction); the
    // winners of every pool issue in one pass.
    for (; requested_pools != 0; requested_pools &= requested_pools - 1) {
        const auto p = static_cast<size_t>(std::countr_zero(requested_pools));
        const FuPool::Grants grants = tm.pools[p].arbitrate(now, tm.issuing_tps.data());
        counters.stalls[size_t(Stall::FuBusy)] += grants.denied;
        counters.instructions += grants.granted;
        tm.progress += grants.granted;
    }
    for (uint32_t w = 0; w < words; ++w) {
        const uint64_t issuing = std::exchange(tm.issuing_tps[w], 0);
        if constexpr (kProfile)
            for_each_bit(w, tm.asking_tps[w] & ~issuing, [&](uint32_t i) {
                ++profile_at(tps[i].pending.pc).stalls[size_t(Stall::FuBusy)];
            });
        tm.pending_tps[w] &= ~issuing;
        tm.needs_port_tps[w] &= ~issuing;
        for_each_bit(w, issuing, [&](uint32_t i) {
            Tm::Tp& tp = tps[i];
            const StepInfo& s = tp.pending;
            const isa::Decoded& d = *s.insn;
            const isa::FuClass fu = d.fu;
            const Pool pool = tp.pending_pool;
            const uint64_t ready = now + latency_of_[size_t(pool)];
            ++counters.per_class[size_t(fu)];
            // atomicinc(0) hands out the next work item; it is the first instruction of it.
            if (fu == isa::FuClass::Atomic && d.imm == 0) [[unlikely]] {
                tm.charges.push_back({tp.item, now - tp.item_since, tp.item_instructions});
                tp.item = s.value;
                tp.item_since = now;
                tp.item_instructions = 0;
            }
            ++tp.item_instructions;
            if constexpr (kProfile) ++profile_at(s.pc).executions;
            uint64_t result_at = ready;
            if (pool == Pool::Atomic) [[unlikely]] {
                if (fu == isa::FuClass::Atomic) {
                    result_at = kNever;  // set by the global-register reply
                    tm.atomics_out.push_back({now, tm.id, tm.atomic_sequence++, i, d.rd});
                } else {
                    send_sync(tm, i, s, now);
                }
            } else if (s.mem_bytes != 0 && core::in_local_store(s.mem_address)) {
                tp.lowest_local = std::min(tp.lowest_local, s.mem_address);
                ++(s.mem_store ? counters.local_stores : counters.local_loads);
                counters.local_payload_bytes += s.mem_bytes;
                result_at = ready + config_.tp.local_store_latency;
            } else if (s.mem_bytes != 0) {
                set_bit(tm.mem_waiting_tps, i);
                tp.mem_at = ready;
                tp.mem_request = {
                    s.mem_address, i,    d.rd,   s.mem_store, region_of(s.mem_address),
                    s.mem_bytes,   s.pc, tp.item};
                result_at = kNever;  // set by the L1 reply
            }
            if (d.rd != isa::kNoReg && !s.mem_store) {
                tp.reg_ready[d.rd] = tm.epoch.offset(result_at);
                tp.reg_producer[d.rd] = pool;
            }
            if (s.exited) {
                clear_bit(tm.awake_tps, i);
                if (--tm.running == 0) tm.idle_from.store(now + 1, std::memory_order_relaxed);
                tm.charges.push_back({tp.item, now + 1 - tp.item_since, tp.item_instructions});
                if (s.value != 0)  // the exit lets threads at the barrier go on
                    tm.atomics_out.push_back({now, tm.id, tm.atomic_sequence++, i, 0,
                                              GlobalRequest::Exit, s.value, first_thread + i});
            } else if (fu == isa::FuClass::Branch) {
                // The bubble after a branch: no fetch before now + 1 + bubble.
                const uint32_t bubble =
                    s.taken ? config_.tp.branch_taken_penalty : config_.tp.branch_not_taken_penalty;
                if (bubble != 0) {
                    counters.active_tp_cycles += bubble;
                    counters.stalls[size_t(Stall::Branch)] += bubble;
                    if constexpr (kProfile)
                        profile_at(s.pc).stalls[size_t(Stall::Branch)] += bubble;
                    tm.sleep_until(i, now + 1 + bubble, now);
                }
            }
        });
    }
    tm.rotation = tm.rotation + 1 == n ? 0 : tm.rotation + 1;
}

template <class Source, bool kProfile>
uint64_t Chip::fetch_lines(Tm& tm, const RotatedPart& part, uint64_t granted, uint64_t now,
                           Source& source) {
    const uint32_t first_thread = tm.id * config_.chip.tps_per_tm;
    uint64_t hits = 0;
    for (uint64_t bits = granted; bits != 0; bits &= bits - 1) {
        const auto bit = static_cast<uint32_t>(std::countr_zero(bits));
        const uint32_t i = part.index(bit);
        Tm::Tp& tp = tm.tps[i];
        const uint32_t pc = source.next_pc(first_thread + i);
        switch (tm.lines->fetch(now, i, pc, tp.item)) {
        case CacheOutcome::Hit:
            hits |= uint64_t{1} << bit;
            break;
        case CacheOutcome::MshrFull:  // stays awake and tries again next cycle
            ++tm.counters.stalls[size_t(Stall::FetchMiss)];
            if constexpr (kProfile) {
                PcCounters* counters = tm.profile->at(pc);
                ++(counters ? *counters : *tm.outside_text).stalls[size_t(Stall::FetchMiss)];
            }
            break;
        default:  // Miss or MergedMiss: asleep from this cycle until the line arrives
            clear_bit(tm.awake_tps, i);
            tp.wake_at = kFetchWait;
            tp.asleep_from = now;
            break;
        }
    }
    tm.lines->send(tm.l1.outbound());
    return hits;
}

namespace {

constexpr std::string_view kStallNames[] = {"fetch_conflict", "branch", "fu_busy",   "memory_port",
                                            "operand",        "sync",   "fetch_miss"};
static_assert(std::size(kStallNames) == kStalls);

}  // namespace

void Chip::register_stats(stats::Registry& r) const {
    const double threads = double(config_.chip.num_tms) * config_.chip.tps_per_tm;
    // A finite I-cache's keys exist only with one: with an I-cache that never misses, the
    // statistics are what they were before there was a choice.
    const bool finite_icache = config_.icache.finite();
    const size_t stall_causes = finite_icache ? kStalls : size_t(Stall::FetchMiss);
    const std::span<const std::string_view> stall_names(kStallNames, stall_causes);
    for (const auto& tm_ptr : tms_) {
        const Tm& tm = *tm_ptr;
        const std::string p = fmt::format("tm{}", tm.id);
        r.add_counter(p + "/instructions", tm.counters.instructions, "instructions issued");
        r.add_counter(p + "/active_tp_cycles", tm.counters.active_tp_cycles,
                      "TP-cycles of threads that had not exited (= issued + stalled)", "TP-cycles");
        for (size_t s = 0; s < stall_causes; ++s)
            r.add_counter(fmt::format("{}/stalls/{}", p, kStallNames[s]), tm.counters.stalls[s],
                          "TP-cycles without issue, by cause (docs/statistics.md)", "TP-cycles");
        for (size_t q = 0; q < kPools; ++q)
            r.add_counter(fmt::format("{}/stalls/operand_from/{}", p, to_string(Pool(q))),
                          tm.counters.operand_stalls[q],
                          "operand stalls waiting on a result of this pool", "TP-cycles");
        for (size_t c = 0; c < size_t(isa::FuClass::Count); ++c)
            r.add_counter(fmt::format("{}/class/{}", p, isa::to_string(isa::FuClass(c))),
                          tm.counters.per_class[c], "instructions issued of this FU class");
        for (size_t q = 0; q < kPools; ++q)
            tm.pools[q].register_stats(r, fmt::format("{}/fu/{}", p, to_string(Pool(q))));
        tm.icache.register_stats(r, p + "/icache");
        if (tm.lines) tm.lines->register_stats(r, p + "/icache");
        tm.l1.register_stats(r, p + "/l1");
        r.add_counter(p + "/local_store/loads", tm.counters.local_loads, "local-store loads");
        r.add_counter(p + "/local_store/stores", tm.counters.local_stores, "local-store stores");
    }
    for (size_t g = 0; g < l2s_.size(); ++g)
        l2s_[g].register_stats(r, fmt::format("l2/{}", g));
    dram_.register_stats(r, "dram");
    global_registers_.register_stats(r, "global_registers");

    r.add_counter("chip/cycles", cycles_, "cycles until every thread exited and memory drained",
                  "cycles");
    const double clock_hz = config_.chip.clock_mhz * 1e6;
    using Values = std::span<const double>;
    r.add_formula(
        "chip/frame_seconds", {"chip/cycles"}, [clock_hz](Values v) { return v[0] / clock_hz; },
        "simulated time at chip.clock_mhz", "s");
    r.add_formula(
        "chip/fps", {"chip/cycles"}, [clock_hz](Values v) { return v[0] ? clock_hz / v[0] : 0; },
        "frames per second if one run is one frame", "1/s");
    r.add_sum("chip/instructions", "*/instructions", "instructions issued, all TMs",
              "instructions");
    r.add_formula(
        "chip/issue_rate", {"chip/instructions", "chip/cycles"},
        [threads](Values v) { return v[1] ? v[0] / (v[1] * threads) : 0.0; },
        "instructions per thread per cycle (1 = every TP issues every cycle)", "ratio");
    r.add_sum("chip/active_tp_cycles", "*/active_tp_cycles", "TP-cycles before exit, all TMs",
              "TP-cycles");
    for (std::string_view stall : stall_names)
        r.add_sum(fmt::format("chip/stalls/{}", stall), fmt::format("*/stalls/{}", stall),
                  "TP-cycles without issue by cause, all TMs", "TP-cycles");
    for (size_t q = 0; q < kPools; ++q) {
        const std::string_view pool = to_string(Pool(q));
        r.add_sum(fmt::format("chip/stalls/operand_from/{}", pool),
                  fmt::format("*/stalls/operand_from/{}", pool),
                  "operand stalls by producing pool, all TMs", "TP-cycles");
    }
    for (size_t c = 0; c < size_t(isa::FuClass::Count); ++c) {
        const std::string_view cls = isa::to_string(isa::FuClass(c));
        r.add_sum(fmt::format("chip/class/{}", cls), fmt::format("*/class/{}", cls),
                  "instructions of this FU class, all TMs");
    }
    for (size_t q = 0; q < kPools; ++q) {
        const std::string_view pool = to_string(Pool(q));
        const std::string busy = fmt::format("chip/fu/{}/unit_busy_cycles", pool);
        r.add_sum(busy, fmt::format("*/fu/{}/unit_busy_cycles", pool),
                  "unit-cycles occupied, all TMs", "unit-cycles");
        const double units = double(pool_config(config_.fu, Pool(q)).count) * config_.chip.num_tms;
        r.add_formula(
            fmt::format("chip/fu/{}/utilisation", pool), {busy, "chip/cycles"},
            [units](Values v) { return v[1] ? v[0] / (units * v[1]) : 0.0; },
            "busy unit-cycles / (units x cycles)");
    }
    for (std::string_view level : {"l1", "l2"}) {
        const std::string from = level == "l1" ? "*/l1/" : "l2/*/";
        for (std::string_view leaf :
             {"reads", "writes", "hits", "misses", "merged_misses", "bank_conflicts", "mshr_full"})
            r.add_sum(fmt::format("chip/{}/{}", level, leaf), from + std::string(leaf),
                      fmt::format("{} {}, all caches", level, leaf), "accesses");
        r.add_ratio(fmt::format("chip/{}/hit_rate", level), fmt::format("chip/{}/hits", level),
                    fmt::format("chip/{}/reads", level), "hits / reads", "ratio");
    }
    r.add_formula(
        "chip/dram/bandwidth_bytes_per_cycle",
        {"dram/bytes_read", "dram/bytes_written", "chip/cycles"},
        [](Values v) { return v[2] ? (v[0] + v[1]) / v[2] : 0.0; }, "achieved DRAM bandwidth",
        "B/cycle");
    r.add_formula(
        "chip/dram/bandwidth_gbps", {"chip/dram/bandwidth_bytes_per_cycle"},
        [clock_hz](Values v) { return v[0] * clock_hz / 1e9; },
        "achieved DRAM bandwidth at chip.clock_mhz", "GB/s");
    r.add_level("chip/local_store_high_water", local_store_high_water_,
                "largest local-store (stack) footprint of any thread", "B");

    // Traffic by region (docs/statistics.md says how each figure is counted): one level's
    // counters, worded for what the region carries (data, or instruction lines, never written).
    struct Carried {
        std::string_view requests, each, payload;
        bool written;
    };
    const Carried data{"loads", "loads", "bytes the kernel's loads and stores asked of this level",
                       true};
    const Carried instructions{"I-cache line requests", "line requests",
                               "bytes of instruction lines asked of this level", false};
    const auto add_traffic = [&](std::string_view region, std::string_view level,
                                 const LevelTraffic& t, bool cache, const Carried& c) {
        const std::string p = fmt::format("region/{}/{}/", region, level);
        r.add_counter(p + "reads", t.reads,
                      cache ? fmt::format("{} accepted", c.requests) : "line reads served",
                      "accesses");
        if (c.written)
            r.add_counter(p + "writes", t.writes, cache ? "stores accepted" : "line writes served",
                          "accesses");
        if (cache) {
            r.add_counter(p + "hits", t.hits, fmt::format("{} that hit", c.each), "accesses");
            r.add_counter(p + "misses", t.misses,
                          fmt::format("{} that requested a line below", c.each), "accesses");
            r.add_counter(p + "merged_misses", t.merged_misses,
                          fmt::format("{} merged into an outstanding miss", c.each), "accesses");
        }
        r.add_counter(p + "payload_bytes", t.payload_bytes, std::string(c.payload), "B");
        r.add_counter(p + "moved_bytes", t.moved_bytes,
                      "bytes this level moved to or from the level below", "B");
    };
    for (size_t region = 0; region <= layout_.regions.size(); ++region) {
        const std::string& name =
            region < layout_.regions.size() ? layout_.regions[region].name : "other";
        add_traffic(name, "l1", l1_traffic_[region], true, data);
        add_traffic(name, "l2", l2_traffic_[region], true, data);
        add_traffic(name, "dram", dram_traffic_[region], false, data);
    }
    r.add_sum("region/local_store/local_store/loads", "*/local_store/loads",
              "loads served by the local stores", "accesses");
    r.add_sum("region/local_store/local_store/stores", "*/local_store/stores",
              "stores served by the local stores", "accesses");
    r.add_counter("region/local_store/local_store/payload_bytes", local_payload_bytes_,
                  "bytes of those loads and stores", "B");
    r.add_sum("region/instruction_fetch/icache/fetches", "*/icache/fetches",
              "instructions fetched, all TMs", "instructions");
    if (!finite_icache) return;
    // After the region's sum of */icache/fetches, which chip/icache/fetches would join.
    add_traffic("instruction_fetch", "l2", l2_traffic_[fetch_region_], true, instructions);
    add_traffic("instruction_fetch", "dram", dram_traffic_[fetch_region_], false, instructions);
    r.add_sum("chip/icache/fetches", "*/icache/fetches",
              "fetches granted by the banks (lookups), all TMs", "fetches");
    for (std::string_view leaf : {"misses", "merged_misses", "mshr_full", "evictions"})
        r.add_sum(fmt::format("chip/icache/{}", leaf), fmt::format("*/icache/{}", leaf),
                  fmt::format("I-cache {}, all TMs", leaf),
                  leaf == "evictions" ? "lines" : "fetches");
    r.add_formula(
        "chip/icache/miss_rate",
        {"chip/icache/misses", "chip/icache/merged_misses", "chip/icache/fetches"},
        [](Values v) { return v[2] ? (v[0] + v[1]) / v[2] : 0.0; },
        "(misses + merged_misses) / fetches: the I-caches' lookups that missed");
}

}  // namespace tpsim::timing
