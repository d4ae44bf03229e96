// The functional machine (sim/core) as the timing model's instruction source: thread ids are
// tm * tps_per_tm + tp on both sides, so MachineConfig::threads_per_tm must equal
// chip.tps_per_tm (machine_config_for() builds a matching one).
#pragma once
#include "sim/core/machine.hpp"
#include "sim/core/thread_env.hpp"
#include "sim/timing/chip.hpp"

#include <array>
#include <cstring>
#include <exception>
#include <memory>
#include <span>
#include <utility>
#include <vector>

namespace tpsim::timing {

/// The machine shape a chip needs: one thread per TP, the chip's TM size and local store.
inline core::MachineConfig machine_config_for(const ChipConfig& chip) {
    core::MachineConfig config;
    config.threads = chip.chip.num_tms * chip.chip.tps_per_tm;
    config.threads_per_tm = chip.chip.tps_per_tm;
    config.local_store_bytes = chip.tp.local_store_bytes;
    return config;
}

/// The functional machine of a kernel run, with `global` (the memory image, of which the first
/// `read_only_bytes` are read-only) in its global memory: the one place a run's machine is set
/// up, for the functional engine, the cycle-level engine and their tests.
inline std::unique_ptr<core::Machine> make_machine(const core::Program& program,
                                                   std::span<const uint32_t> global,
                                                   uint64_t read_only_bytes, const ChipConfig& chip,
                                                   uint64_t max_instructions,
                                                   uint64_t max_item_instructions = 0) {
    core::MachineConfig config = machine_config_for(chip);
    config.global_bytes = uint32_t(global.size_bytes());
    config.read_only_global_bytes = uint32_t(read_only_bytes);
    config.max_instructions = max_instructions;
    config.max_item_instructions = max_item_instructions;
    auto machine = std::make_unique<core::Machine>(program, config);
    std::memcpy(machine->memory().global().data(), global.data(), global.size_bytes());
    return machine;
}

/// Runs each thread ahead of the chip: when the chip fetches an instruction of a thread with
/// nothing buffered, that instruction executes (exactly when it is fetched, as the model
/// requires), and so do the following ones while they are private to the thread
/// (Machine::is_private); the chip then takes their records from the buffer. Instructions
/// that see shared state still execute in fetch order and cycle, so results are the same as
/// executing each at its fetch, while the functional core runs a thread's code in stretches,
/// which the host's branch predictors handle far better than one instruction per thread in turn.
/// Stores to shared memory run ahead too, held back by the machine (core::Machine::clock_by):
/// each happens when the chip fetches it.
class MachineSource final : public InstructionSource {
public:
    explicit MachineSource(core::Machine& machine)
        : machine_(machine), records_(record_slot(machine.thread_count())),
          faults_(machine.thread_count()), cursor_lines_(cursor_line(machine.thread_count()) + 1) {
        for (uint32_t t = 0; t < machine.thread_count(); ++t)
            cursor(t).pc = machine.next_pc(t);
    }

    core::Machine& machine() const { return machine_; }

    uint32_t next_pc(uint32_t thread) const override { return cursor(thread).pc; }

    /// Records run ahead are private (executed already); so is the next instruction if the
    /// machine says so. A fault waiting for its fetch is not: it must be raised in turn.
    bool next_is_private(uint32_t thread) const override {
        const Cursor& c = cursor(thread);
        return c.next < c.size || next_unbuffered_is_private(thread);
    }

    /// Its next record (on a large chip, the records taken a stretch ago have left the host's
    /// caches by the time the chip comes back to the thread).
    void prefetch_next(uint32_t thread) const override {
        const Cursor& c = cursor(thread);
        __builtin_prefetch(&records_[record_slot(thread)][c.next]);
    }

    void step(uint32_t thread, StepInfo& out) override {
        Cursor& c = cursor(thread);
        Records& records = records_[record_slot(thread)];
        if (c.next == c.size) run_ahead(thread, c, records);
        if (c.next == c.held) [[unlikely]]
            hold(thread, c, records);
        out = records[c.next++];
        // The chip takes a thread's records one at a time, among those of a thousand other
        // threads on large chips: the buffer's next line is fetched before it is needed.
        __builtin_prefetch(&records[std::min<uint32_t>(c.next + kPrefetchAhead, kAhead - 1)]);
        c.pc = c.next < c.size ? records[c.next].pc : machine_.next_pc(thread);
    }

    /// Writes the stores held from the steps before `cycle` (Machine::write_held_before).
    void passed(uint64_t cycle) override { machine_.write_held_before(cycle); }

    /// Functional warming (Chip::warm): thread `thread` executes up to `budget` instructions,
    /// first those it has run ahead, and `observer` hears of their loads, stores and atomic
    /// increments (core::ThreadEnv); stops after an exit or a synchronisation instruction,
    /// leaving its record in `last` (and returns true). `executed` counts the instructions.
    template <class Observer>
    bool warm(uint32_t thread, uint64_t budget, uint64_t& executed, StepInfo& last,
              Observer& observer) {
        Cursor& c = cursor(thread);
        const Records& records = records_[record_slot(thread)];
        executed = 0;
        bool stopped = false;
        while (c.next < c.size && executed < budget && !stopped) {
            const StepInfo& s = records[c.next++];
            ++executed;
            // Warming writes its stores at once, as it executes them (after a drain, nothing
            // is held): so does a store run ahead.
            if (held(s)) machine_.memory().write(s.mem_address, s.mem_bytes, s.value);
            stopped = replay(s, last, observer);
        }
        c.held = next_held(records, c.next, c.size);
        if (executed < budget && !stopped) {
            raise_fault_due(thread);
            uint64_t more = 0;
            stopped = machine_.run_observed(thread, budget - executed, more, last, observer);
            executed += more;
        }
        c.pc = c.next < c.size ? records[c.next].pc : machine_.next_pc(thread);
        return stopped;
    }

    /// What `observer` hears of an instruction already executed (warm()): its access or
    /// atomic increment; true (its record copied to `last`) if it is an exit or a
    /// synchronisation, where warming stops.
    template <class Observer>
    static bool replay(const StepInfo& s, StepInfo& last, Observer& observer) {
        if (s.exited || s.insn->fu == isa::FuClass::Sync) {
            last = s;
            return true;
        }
        if (s.mem_bytes != 0) observer.access(s.mem_address, s.mem_bytes, s.mem_store);
        if (s.insn->fu == isa::FuClass::Atomic) observer.atomic(uint32_t(s.insn->imm), s.value);
        return false;
    }

private:
    static constexpr uint32_t kAhead = 128;  // records buffered per thread
    static constexpr uint32_t kPrefetchAhead = 4;
    // Each thread's on its own cache lines (as are the machine's threads): the threads of TMs
    // simulated on different host threads must not share a line that both write. Nor come
    // near one (core::kTmSpacing): after every block of 32 threads (a TM by default; TMs of a
    // multiple of 32 TPs each start one) one Records is left unused.
    using Records = std::array<StepInfo, kAhead>;
    static_assert(sizeof(Records) % core::kHostSpacing == 0 && sizeof(Records) >= core::kTmSpacing);
    struct alignas(core::kHostSpacing) AlignedRecords : Records {};
    static constexpr uint32_t kBlockThreads = 32;
    static uint32_t record_slot(uint32_t thread) { return thread + thread / kBlockThreads; }
    // What the chip reads of a thread at every fetch, dense: the pc it fetches next, its place
    // in its records (records[next, size) are run ahead, not yet taken) and the next of them
    // that is a store held back (kNoneHeld: none).
    struct Cursor {
        uint32_t pc = 0;
        uint8_t next = 0, size = 0, held = kNoneHeld;
    };
    static constexpr uint8_t kNoneHeld = UINT8_MAX;
    static_assert(kAhead < kNoneHeld);
    // In whole pairs of cache lines (core::kHostSpacing): TMs of a multiple of 16 threads (32
    // by default) never share one. Blocks of 32 threads are core::kTmSpacing apart, as above.
    static constexpr uint32_t kCursorsPerLine = core::kHostSpacing / sizeof(Cursor);
    struct alignas(core::kHostSpacing) CursorLine {
        std::array<Cursor, kCursorsPerLine> cursors{};
    };
    static_assert(kBlockThreads % kCursorsPerLine == 0, "a block is whole lines of cursors");
    static constexpr uint32_t kBlockLines =
        kBlockThreads / kCursorsPerLine + core::kTmSpacing / core::kHostSpacing;
    static uint32_t cursor_line(uint32_t thread) {
        return thread / kBlockThreads * kBlockLines + thread % kBlockThreads / kCursorsPerLine;
    }

    Cursor& cursor(uint32_t thread) {
        return cursor_lines_[cursor_line(thread)].cursors[thread % kCursorsPerLine];
    }
    const Cursor& cursor(uint32_t thread) const {
        return cursor_lines_[cursor_line(thread)].cursors[thread % kCursorsPerLine];
    }

    /// next_is_private() of a thread with nothing buffered: out of line, as it is rare (the
    /// chip asks at every fetch).
    [[gnu::noinline]] bool next_unbuffered_is_private(uint32_t thread) const {
        return !faults_[thread] && machine_.next_is_private(thread);
    }

    /// Whether a record is a store the machine held back: one to shared memory (timing mode,
    /// core::Machine::clock_by).
    static bool held(const StepInfo& s) {
        return s.mem_store && !core::in_local_store(s.mem_address);
    }
    static uint8_t next_held(const Records& records, uint32_t from, uint32_t size) {
        for (uint32_t k = from; k < size; ++k)
            if (held(records[k])) return uint8_t(k);
        return kNoneHeld;
    }
    /// The chip fetches a store held back: it happens now (Machine::hold_store). Out of line:
    /// a few stores per work item go to shared memory.
    [[gnu::cold, gnu::noinline]] void hold(uint32_t thread, Cursor& c, const Records& records) {
        machine_.hold_store(thread, records[c.next]);
        c.held = next_held(records, c.next + 1u, c.size);
    }

    /// A fault of an instruction run ahead is raised when the chip comes to that instruction.
    void raise_fault_due(uint32_t thread) {
        if (faults_[thread]) std::rethrow_exception(std::exchange(faults_[thread], nullptr));
    }

    void run_ahead(uint32_t thread, Cursor& c, Records& records) {
        raise_fault_due(thread);
        uint32_t size = 0, first_held = kNoneHeld;
        try {
            machine_.run_ahead(thread, records.data(), kAhead, size, first_held);
        } catch (...) {
            c.next = c.size = 0;
            c.held = kNoneHeld;
            if (size == 0) throw;  // the fetched instruction itself: its fault is due now
            // A later one's: raised when the chip fetches it (its pc stays the thread's pc).
            faults_[thread] = std::current_exception();
        }
        c.next = 0;
        c.size = uint8_t(size);
        c.held = first_held < size ? uint8_t(first_held) : kNoneHeld;
    }

    core::Machine& machine_;
    std::vector<AlignedRecords> records_;
    std::vector<std::exception_ptr> faults_;
    std::vector<CursorLine> cursor_lines_;
};

}  // namespace tpsim::timing
