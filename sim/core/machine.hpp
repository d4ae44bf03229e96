// The functional machine: T threads running one program over shared memory, deterministically.
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "isa/hart.hpp"
#include "kernel/kernel_output.hpp"
#include "kernel/memory_map.hpp"
#include "sim/core/elf_loader.hpp"
#include "sim/core/fault.hpp"
#include "sim/core/host_spacing.hpp"
#include "sim/core/memory.hpp"
#include "sim/core/ordered_turns.hpp"

namespace tpsim::core {

class HeldStores;

struct MachineConfig {
    /// Hardware threads (one per thread processor); each starts at the ELF entry.
    uint32_t threads = 1;
    /// Threads per thread multiprocessor; only the tp.tmid/tp.tpid/tp.ntms/tp.tmsize CSRs see it.
    uint32_t threads_per_tm = 32;
    /// Bytes of private local store per thread (--local-store).
    uint32_t local_store_bytes = 4096;
    /// Bytes of global memory at kGlobalBase (scene image + framebuffer).
    uint32_t global_bytes = 0;
    /// Leading bytes of global memory that are read-only (MemoryConfig).
    uint32_t read_only_global_bytes = 0;
    /// Instructions one thread may execute before it faults as a runaway (--max-instructions).
    uint64_t max_instructions = uint64_t(1) << 32;
    /// Instructions a thread may retire on one work item, i.e. since its last tp.atominc on
    /// global register 0 (or its start), before it faults as a runaway; 0: no such limit.
    /// Renders set it (--max-item-instructions; render::default_item_instructions).
    uint64_t max_item_instructions = 0;
    /// Instructions a thread runs before the functional scheduler moves to the next thread.
    uint32_t quantum = 1024;

    /// Throws tpsim::Error naming the bad field.
    void validate() const;
};

/// Waiting: at the barrier or for a semaphore (tp.barrier, tp.semacq), until another thread's
/// instruction lets it go on.
enum class ThreadState : uint8_t { Running, Waiting, Exited, Faulted };

/// Thrown by a synchronisation instruction that completed and left its thread Waiting: the run
/// loops stop running the thread there.
struct ThreadSuspended {};

/// Where an exited thread's pc is parked: below kCodeBase, so never fetchable.
constexpr uint32_t kParkedPc = 0;

/// On its own pairs of cache lines (kHostSpacing): threads simulated on different host threads
/// never share one.
struct alignas(kHostSpacing) Thread {
    isa::Hart hart;
    ThreadState state = ThreadState::Running;
    int32_t exit_code = 0;  ///< a0 of the exit ecall
    uint32_t exit_pc = 0;   ///< address of the exit ecall (hart.pc is parked at kParkedPc)
    /// Instructions executed, including the exit ecall and trapping ones (which instret does
    /// not count); checked against max_instructions.
    uint64_t executed = 0;
    /// hart.instret at its last tp.atominc on global register 0 (max_item_instructions).
    uint64_t item_start = 0;
};

/// Whether a guest address is private to each thread: its local store, the overflow guard below
/// it and the unmapped space above (an access there touches the thread's own store or faults).
constexpr bool in_local_store(uint32_t addr) {
    return addr >= trax::map::kLocalTop - trax::map::kStackGuard;
}

/// What one instruction did, for the timing model (step()).
struct StepRecord {
    uint32_t pc = 0;  ///< address of the instruction
    /// The value an atomic increment returned; for the synchronisation instructions what the
    /// chip needs to time them (see Machine::barrier and the semaphore functions); for a
    /// store the machine holds (Machine::clock_by), the bytes it stores.
    uint32_t value = 0;
    const isa::Decoded* insn = nullptr;  ///< its pre-decoded form (registers, FU class)
    /// Effective address when mem_bytes != 0 (in the thread's own local store when
    /// in_local_store(mem_address): no cache, no traffic).
    uint32_t mem_address = 0;
    uint8_t mem_bytes = 0;  ///< access size; 0 = no memory access
    bool mem_store = false;
    bool taken = false;   ///< control left the fall-through path (branch, jump, trap)
    bool exited = false;  ///< the instruction ended the thread
};
static_assert(sizeof(StepRecord) == 24, "the timing model buffers 128 per thread");

struct Counters {
    uint64_t instructions = 0;
    std::array<uint64_t, size_t(isa::Op::Count)> per_op{};  ///< indexed by isa::Op
};

/// Number of global registers for tp.atominc (all start at 0).
constexpr uint32_t kGlobalRegisters = 256;
/// The most bytes one tp.print hands over.
constexpr uint32_t kMaxPrintBytes = 4096;

class Machine {
public:
    Machine(Program program, const MachineConfig& config);
    // Out of line: HeldStores is complete only in machine.cpp.
    Machine(Machine&&) noexcept;
    ~Machine();

    /// Runs every thread to its exit, round-robin by thread id in fixed quanta (a waiting thread
    /// is passed over until it may go on), so results never depend on anything but the program
    /// and the config. Throws Fault on the first guest fault, a deadlock included. On several
    /// host threads (host thread h takes threads h, h + host_threads, ...), instructions that
    /// are not private run in the turn (round, thread) they have in that order, so nothing
    /// depends on the number.
    void run(uint32_t host_threads = 1);

    /// Executes one instruction of a running thread and reports what it did. Throws Fault.
    StepRecord step(uint32_t thread);
    /// The timing model's batched step(): executes thread `id`'s next instruction, then the
    /// following ones while they are private (is_private), at most `capacity` in all (and
    /// never past the instruction limit), writing their records to out[0..done);
    /// `first_held` is the index of the first store held back (timing mode, clock_by), or
    /// UINT32_MAX. If an instruction faults, the Fault is thrown with `done` and `first_held`
    /// counting the records written before it. Defined in thread_env.hpp so the cycle loop
    /// can inline it.
    inline void run_ahead(uint32_t id, StepRecord* out, uint32_t capacity, uint32_t& done,
                          uint32_t& first_held);
    /// Functional warming's step (timing::Chip::warm): executes up to `budget` instructions of
    /// thread `id` (never past the instruction limits) without records; `observer` hears of
    /// every load, store and atomic increment as ThreadEnv describes. Stops after an exit or
    /// a synchronisation instruction, whose record it leaves in `last`, and returns true then.
    /// `executed` counts the instructions run. Throws Fault as run_ahead() does. Defined in
    /// thread_env.hpp.
    template <class Observer>
    inline bool run_observed(uint32_t id, uint64_t budget, uint64_t& executed, StepRecord& last,
                             Observer& observer);

    /// Timing mode, for the timing model's MachineSource: the cycle/time CSRs of a thread in
    /// TM t read `cycles[t * stride]` (the cycle that TM is simulating: TMs may be simulated
    /// on different host threads, each at its own cycle) instead of instret; and a store to
    /// shared memory (outside the thread's local store) is private: run_ahead checks it but
    /// holds it back, its bytes in its record, for hold_store() when the chip fetches it.
    /// nullptr (the default) = functional mode, where cycle = instret and stores write at
    /// once; leaving timing mode writes what is still held. The counters must outlive the
    /// instructions that read them.
    void clock_by(const uint64_t* cycles, uint32_t stride);
    /// Timing mode: thread `id`'s store (its record from run_ahead) is fetched; it joins the
    /// held stores at its TM's position (cycle * TMs + TM) in the order.
    void hold_store(uint32_t id, const StepRecord& store);
    /// Timing mode: every step before cycle `cycle` has happened; the stores held from those
    /// steps are written.
    void write_held_before(uint64_t cycle);
    /// Whether thread `id`'s next instruction is private (is_private): running it at any
    /// moment, whatever other threads run meanwhile, gives the same result. False for an
    /// instruction that touches shared state, and for a thread that is not running.
    /// Defined in thread_env.hpp.
    inline bool next_is_private(uint32_t id) const;

    const Program& program() const { return program_; }
    const MachineConfig& config() const { return config_; }
    Memory& memory() { return memory_; }
    const Memory& memory() const { return memory_; }
    /// The pc thread `id` executes next; unchecked (the timing model asks once per instruction).
    uint32_t next_pc(uint32_t id) const { return threads_[id].hart.pc; }
    Thread& thread(uint32_t id) { return threads_.at(id); }
    const Thread& thread(uint32_t id) const { return threads_.at(id); }
    uint32_t thread_count() const { return uint32_t(threads_.size()); }
    /// The code: the file-backed words of each executable segment, by address. Only these
    /// are decoded and fetched; a pc anywhere else is a fetch fault.
    struct CodeRange {
        uint32_t base = 0;   ///< address of the first word
        uint32_t words = 0;  ///< instruction words
        uint32_t first = 0;  ///< index of the first word in the decoded array
    };
    const std::vector<CodeRange>& code() const { return code_; }
    /// Instructions executed, summed over the TMs' counters.
    Counters counters() const;
    uint32_t global_register(uint32_t index) const { return global_registers_.at(index); }
    /// What the threads printed (tp.print).
    const trax::KernelOutput& output() const { return output_; }

private:
    template <bool kRecord, class Observer> friend class ThreadEnv;

    /// Runs up to `budget` instructions of thread `id`, counting them in `counters`. `turn` is
    /// called before the first one that is not private (nothing is checked for a NoTurn).
    template <class Turn>
    void run_quantum(uint32_t id, uint64_t budget, Counters& counters, Turn&& turn);
    void run_lanes(uint32_t lanes);
    /// The code range holding the aligned pc, or nullptr (a fetch fault). Cold: the run loops
    /// keep the current range in locals and ask only when the pc leaves it.
    [[gnu::cold]] const CodeRange* code_range_at(uint32_t pc) const;
    [[noreturn]] void fault(uint32_t id, uint32_t pc, const GuestFault& what);
    /// Traps the hart to its handler if it has one and the fault is an exception a handler
    /// may take (a load or store fault); false if the fault must stop the thread.
    static bool take_trap(isa::Hart& h, const GuestFault& what) {
        if (h.mtvec == 0 || what.mcause == kNoTrap) return false;
        isa::trap(h, what.mcause, what.mtval);
        return true;
    }
    [[noreturn]] void fetch_fault(uint32_t id, uint32_t pc);
    [[noreturn]] void limit_fault(uint32_t id);
    /// Instructions thread `t` may still run before a limit stops it (0: stop now).
    uint64_t instructions_left(const Thread& t) const {
        uint64_t left = config_.max_instructions - t.executed;
        if (config_.max_item_instructions != 0) {
            // instret only moves back if the guest writes minstret; count that as a fresh item.
            const uint64_t used =
                t.hart.instret >= t.item_start ? t.hart.instret - t.item_start : 0;
            left = std::min(left, used >= config_.max_item_instructions
                                      ? 0
                                      : config_.max_item_instructions - used);
        }
        return left;
    }
    [[noreturn]] void refuse_step(uint32_t id);
    /// Timing mode, before run_ahead's first step (the chip's fetch): if the step is not
    /// private (a load of shared memory, a print), it is in its turn, and every store held
    /// before it in the order is written. Cold: run_ahead calls it only for a load or print.
    [[gnu::cold]] void write_held_before_step(uint32_t id);

    // The synchronisation instructions and exit (ThreadEnv's hooks). Each returns what the
    // chip needs to time it (StepRecord::value): barrier() the number of threads the
    // arrival lets go on (itself included; 0 if it waits), sem_acquire() 1 if it got the
    // semaphore at once (0: it waits until a release hands it over), sem_release() 1 + the
    // thread it hands the semaphore to (0: none waited), exited() the number of threads
    // waiting at the barrier the exit lets go on. A thread that must wait is completed, set
    // Waiting and ThreadSuspended is thrown; a deadlock throws GuestFault.
    [[gnu::cold]] uint32_t barrier(uint32_t id, isa::Hart& h);
    [[gnu::cold]] uint32_t sem_acquire(uint32_t id, isa::Hart& h, uint32_t reg);
    [[gnu::cold]] uint32_t sem_release(uint32_t id, isa::Hart& h, uint32_t reg);
    [[gnu::cold]] uint32_t exited(uint32_t id);
    [[gnu::cold]] void print(uint32_t id, uint32_t address, uint32_t length, uint8_t* local);
    /// Throws the deadlock GuestFault if the calling thread is the last one running, so
    /// that nothing could end the wait it is about to begin (`waits`: "at the barrier" ...).
    void check_not_last_running(const std::string& waits) const;
    /// Completes the instruction and sets thread `id` Waiting; throws ThreadSuspended.
    [[noreturn]] void suspend(uint32_t id, isa::Hart& h);
    /// Lets the barrier's waiters go on if every thread that has not exited is one of them;
    /// returns how many went.
    uint32_t release_barrier();
    void check_semaphore(uint32_t reg) const;
    /// "held by thread 2" and the like, for deadlock messages.
    std::string semaphore_holder(uint32_t reg) const;
    /// "threads 0-3 at the barrier, thread 5 for semaphore 2 (held by thread 1)".
    std::string describe_waiting() const;
    /// ThreadEnv's out-of-line paths (thread_env.hpp): the CSRs the machine answers (false for
    /// others), and an illegal or unimplemented instruction (traps to mtvec or throws), or a
    /// pc-relative jump with a misaligned offset (pre-decoded as illegal; run here).
    bool read_csr(uint32_t id, uint32_t csr, uint32_t& value) const;
    [[gnu::cold, gnu::noinline]] void illegal(uint32_t id, isa::Hart& h, const isa::Decoded& d);
    /// True if the instruction at word `index` of the code range whose decoded words start at
    /// word `first` (any index: outside the range's `words` is not private), run by hart `h`,
    /// touches only the thread's own state (registers, pc, local store), reads the read-only
    /// scene or, in timing mode, stores to shared memory (held: clock_by): executing it
    /// earlier or later than other threads' instructions cannot change any result. False for
    /// other shared-memory accesses, atomics and CSR/system instructions (whose results may
    /// depend on when they run). Defined in thread_env.hpp.
    inline bool is_private(const isa::Hart& h, uint32_t index, uint32_t words,
                           uint32_t first) const;

    Program program_;
    MachineConfig config_;
    Memory memory_;
    std::vector<CodeRange> code_;        ///< by address
    CodeRange entry_code_;               ///< the range holding the entry, where fetch starts
    std::vector<isa::Decoded> decoded_;  ///< every code range's words, back to back
    /// Per word of decoded_: whether the instruction is private (is_private): always,
    /// never, or depending on the address it loads from or stores to.
    enum class Privacy : uint8_t { Always, Never, Load, Store };
    std::vector<Privacy> privacy_;
    std::vector<Thread> threads_;
    std::array<uint32_t, kGlobalRegisters> global_registers_{};
    uint32_t running_threads_ = 0;      ///< threads Running
    uint32_t live_threads_ = 0;         ///< threads Running or Waiting
    std::vector<uint32_t> at_barrier_;  ///< waiting at the barrier, in arrival order
    struct SemaphoreWait {
        uint32_t reg, thread;
    };
    std::vector<SemaphoreWait> semaphore_waits_;  ///< in arrival order (FIFO hand-over)
    /// The thread that acquired each semaphore last (for messages); kNoThread: never.
    static constexpr uint32_t kNoThread = UINT32_MAX;
    std::array<uint32_t, kGlobalRegisters> semaphore_holder_;
    trax::KernelOutput output_;
    /// The counters of the threads of TM t in counter_lanes_[t] (t = thread / threads_per_tm),
    /// kTmSpacing apart: TMs simulated on different host threads never write the same
    /// counters, nor lines next to them.
    struct alignas(kTmSpacing) CounterLane {
        Counters counters;
    };
    std::vector<CounterLane> counter_lanes_;
    Counters& counters_of(uint32_t id) {
        return counter_lanes_[id / config_.threads_per_tm].counters;
    }
    const uint64_t* cycle_counters_ = nullptr;
    uint32_t cycle_stride_ = 0;
    /// Timing mode's stores, one producer per TM; none in functional mode.
    std::unique_ptr<HeldStores> held_;
    /// The timing mode's order, the chip's turns: TM `tm` in cycle `cycle`.
    uint64_t position(uint64_t cycle, uint32_t tm) const {
        return chip_position(cycle, tm, counter_lanes_.size());
    }
    /// Thread `id`'s place in that order: its TM at the cycle the TM is simulating.
    uint64_t position_of(uint32_t id) const {
        const uint32_t tm = id / config_.threads_per_tm;
        return position(cycle_counters_[size_t(tm) * cycle_stride_], tm);
    }
};

}  // namespace tpsim::core
