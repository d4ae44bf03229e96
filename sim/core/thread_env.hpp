// The per-instruction execution environment (ThreadEnv) and Machine::run_ahead, in a header
// so the timing model's cycle loop can inline the whole step (fetch check, execute, record)
// instead of calling through machine.cpp for every simulated instruction.
#pragma once
#include <bit>
#include <cstring>
#include <type_traits>

#include <fmt/format.h>

#include "isa/execute.hpp"
#include "kernel/memory_map.hpp"
#include "sim/core/machine.hpp"

namespace tpsim::core {

namespace detail {

constexpr uint32_t kExitSyscall = 93;  // a7 value of exit(a0), as in Linux/newlib
constexpr unsigned kA0 = 10, kA7 = 17, kSp = 2;

struct NoRecorder {};

/// A ThreadEnv without an observer (Machine::run_observed's has one).
struct NoObserver {};

}  // namespace detail

/// The isa::execute environment of one thread. kRecord adds the bookkeeping step() reports,
/// written straight into its record; the fast path instantiates it away. An Observer (not
/// detail::NoObserver) hears of every load and store (observer.access(addr, bytes, store))
/// and atomic increment (observer.atomic(global_register, old)) as it happens.
template <bool kRecord, class Observer = detail::NoObserver> class ThreadEnv {
public:
    using Record = std::conditional_t<kRecord, StepRecord*, detail::NoRecorder>;
    static constexpr bool kObserved = !std::is_same_v<Observer, detail::NoObserver>;
    using ObserverRef = std::conditional_t<kObserved, Observer*, detail::NoObserver>;

    ThreadEnv(Machine& machine, uint32_t id, Record record = {}, ObserverRef observer = {})
        : machine_(machine), thread_(machine.threads_[id]), id_(id),
          local_(machine.memory_.local_store(id).data()), record_(record), observer_(observer) {}

    template <class T> T load(uint32_t addr) {
        if constexpr (kRecord) record_access(addr, sizeof(T), false);
        if constexpr (kObserved) observer_->access(addr, sizeof(T), false);
        return machine_.memory_.load<T>(addr, local_);
    }

    template <class T> void store(uint32_t addr, T value) {
        if constexpr (kObserved) observer_->access(addr, sizeof(T), true);
        if constexpr (kRecord) {
            record_access(addr, sizeof(T), true);
            // Timing mode: a store to shared memory is held until the chip fetches it
            // (Machine::clock_by); a bad address faults now.
            if (machine_.held_ && !in_local_store(addr)) [[unlikely]] {
                machine_.memory_.check_store(addr, sizeof(T), local_);
                uint32_t bytes = 0;
                std::memcpy(&bytes, &value, sizeof(T));
                record_->value = bytes;
                if (!first_held_) first_held_ = record_;
                return;
            }
        }
        machine_.memory_.store<T>(addr, value, local_);
    }

    uint32_t atomic_inc(uint32_t global_register) {
        if (global_register >= kGlobalRegisters) [[unlikely]]
            bad_global_register(global_register);
        const uint32_t old = machine_.global_registers_[global_register]++;
        // Register 0 hands out the work items (pixels): a new item starts.
        if (global_register == 0) thread_.item_start = thread_.hart.instret;
        if constexpr (kRecord) record_->value = old;
        if constexpr (kObserved) observer_->atomic(global_register, old);
        return old;
    }

    bool read_csr(uint32_t csr, uint32_t& value) { return machine_.read_csr(id_, csr, value); }

    void print(uint32_t address, uint32_t length) { machine_.print(id_, address, length, local_); }
    void barrier(isa::Hart& h) { report(machine_.barrier(id_, h)); }
    void sem_acquire(isa::Hart& h, uint32_t reg) { report(machine_.sem_acquire(id_, h, reg)); }
    void sem_release(isa::Hart& h, uint32_t reg) { report(machine_.sem_release(id_, h, reg)); }

    void ecall(isa::Hart& h) {
        const uint32_t number = h.reg[detail::kA7];
        if (number == detail::kExitSyscall) {
            thread_.state = ThreadState::Exited;
            thread_.exit_code = int32_t(h.reg[detail::kA0]);
            thread_.exit_pc = h.pc;
            h.pc = kParkedPc;
            if constexpr (kRecord) record_->exited = true;
            report(machine_.exited(id_));
            return;
        }
        if (h.mtvec != 0) return isa::trap(h, isa::cause::kEcallM, 0);
        unsupported_ecall(number);
    }

    // The rare and fault paths are out of line and take no pointer to the environment, so it
    // stays in registers in the flattened step (see there). With a trap handler installed
    // (mtvec != 0) they trap as the privileged spec has it; without one they stop the thread.
    [[gnu::cold, gnu::noinline]] static void ebreak(isa::Hart& h) {
        if (h.mtvec != 0) return isa::trap(h, isa::cause::kBreakpoint, h.pc);
        throw GuestFault{FaultKind::Breakpoint, "stops the thread",
                         "remove the breakpoint (__builtin_trap / ebreak) or fix the failed "
                         "check that reached it"};
    }

    [[gnu::cold, gnu::noinline]] static void misaligned_jump(isa::Hart& h, uint32_t target) {
        if (h.mtvec != 0) return isa::trap(h, isa::cause::kMisalignedFetch, target);
        throw GuestFault{FaultKind::MisalignedJump,
                         fmt::format("jumps to {:#010x}, which is not 4-byte aligned", target),
                         "a return address or function pointer is corrupt (stack smashed?)"};
    }

    void illegal(isa::Hart& h, const isa::Decoded& d) { machine_.illegal(id_, h, d); }

    /// Where the next instruction's bookkeeping goes (recording environments only).
    void record_into(StepRecord* record) { record_ = record; }
    /// The record of the first store held back (timing mode), or nullptr.
    const StepRecord* first_held() const { return first_held_; }

private:
    [[noreturn, gnu::cold, gnu::noinline]] static void bad_global_register(uint32_t index) {
        throw GuestFault{FaultKind::BadGlobalRegister,
                         fmt::format("uses global register {}, but there are only {} (0..{})",
                                     index, kGlobalRegisters, kGlobalRegisters - 1),
                         "use a register index below 256"};
    }

    [[noreturn, gnu::cold, gnu::noinline]] static void unsupported_ecall(uint32_t number) {
        throw GuestFault{FaultKind::UnsupportedEcall,
                         fmt::format("with a7={}; tpsim only implements exit (a7={})", number,
                                     detail::kExitSyscall),
                         "call exit through the kernel runtime, or install a trap handler in "
                         "mtvec"};
    }

    /// What a synchronisation instruction or exit tells the chip (StepRecord::value).
    void report(uint32_t value) {
        if constexpr (kRecord) record_->value = value;
    }

    void record_access(uint32_t addr, uint8_t bytes, bool store) {
        record_->mem_address = addr;
        record_->mem_bytes = bytes;
        record_->mem_store = store;
    }

    Machine& machine_;
    Thread& thread_;
    uint32_t id_;
    uint8_t* local_;
    [[no_unique_address]] Record record_;
    [[no_unique_address]] ObserverRef observer_;
    const StepRecord* first_held_ = nullptr;
};

// The timing model's hot path: the functional core's stretch of one thread (see
// MachineSource). Every check in one unlikely branch, the fault paths out of line. Flattened:
// GCC would otherwise keep isa::execute out of line (too big for its inliner), which costs a
// call and keeps the environment and record in memory instead of registers.
[[gnu::flatten]] inline void Machine::run_ahead(uint32_t id, StepRecord* out, uint32_t capacity,
                                                uint32_t& done, uint32_t& first_held) {
    done = 0;
    first_held = UINT32_MAX;
    // config_.threads, not threads_.size(): no division by sizeof(Thread).
    if (id >= config_.threads) [[unlikely]]
        refuse_step(id);
    Thread& t = threads_[id];
    const uint64_t left = instructions_left(t);
    if (t.state != ThreadState::Running || left == 0) [[unlikely]]
        refuse_step(id);
    // Stop at the instruction limits: the next call then reports the runaway at its fetch.
    capacity = uint32_t(std::min<uint64_t>(capacity, left));
    isa::Hart& h = t.hart;
    ThreadEnv<true> env(*this, id, out);
    // Locals, not members (as in run_quantum): stores through the hart's registers could alias
    // members, and the compiler would reload them every instruction.
    Counters& counters = counters_of(id);
    uint64_t* per_op = counters.per_op.data();
    const isa::Decoded* decoded = decoded_.data() + entry_code_.first;
    uint32_t first = entry_code_.first;
    uint32_t text_base = entry_code_.base;
    uint32_t text_words = entry_code_.words;
    uint32_t n = 0;  // records written
    const auto count = [&] {
        done = n;
        if (env.first_held()) first_held = uint32_t(env.first_held() - out);
        t.executed += n;
        counters.instructions += n;
    };
    uint32_t pc = h.pc;
    // Timing mode: a load or print in its turn reads shared memory after the stores held
    // before it are written. (A pc outside the entry's code range is left to the out-of-line
    // check, which finds its range.)
    if (held_) {
        const uint32_t index = std::rotr(pc - text_base, 2);
        const isa::FuClass fu = index < text_words ? decoded[index].fu : isa::FuClass::Load;
        if (fu == isa::FuClass::Load || fu == isa::FuClass::Print) [[unlikely]]
            write_held_before_step(id);
    }
    try {
        for (;;) {
            pc = h.pc;
            // One compare checks range and alignment, as in run_quantum.
            uint32_t index = std::rotr(pc - text_base, 2);
            if (index >= text_words) [[unlikely]] {
                const CodeRange* range = code_range_at(pc);
                if (!range) fetch_fault(id, pc);
                decoded = decoded_.data() + range->first;
                first = range->first;
                text_base = range->base;
                text_words = range->words;
                index = (pc - text_base) / 4;
            }
            const isa::Decoded& d = decoded[index];
            ++per_op[size_t(d.op)];
            StepRecord& record = out[n];
            record = StepRecord{.pc = pc, .insn = &d};
            env.record_into(&record);
            isa::execute<ThreadEnv<true>, false>(d, h, env);
            record.taken = !record.exited && h.pc != pc + 4;
            // An exited thread's pc is parked outside the code, so it is not private either.
            if (++n == capacity ||
                !is_private(h, std::rotr(h.pc - text_base, 2), text_words, first))
                break;
        }
    } catch (const ThreadSuspended&) {
        ++n;  // the instruction completed; the thread waits, so the batch ends with it
    } catch (const GuestFault& f) {
        if (!take_trap(h, f)) {
            count();
            fault(id, pc, f);
        }
        // The access did not happen; the instruction ends the batch as a trap.
        StepRecord& record = out[n++];
        record.mem_bytes = 0;
        record.mem_store = false;
        record.taken = true;
    } catch (...) {
        count();
        throw;
    }
    count();
}

template <class Observer>
[[gnu::flatten]] inline bool Machine::run_observed(uint32_t id, uint64_t budget, uint64_t& executed,
                                                   StepRecord& last, Observer& observer) {
    executed = 0;
    if (id >= config_.threads) [[unlikely]]
        refuse_step(id);
    Thread& t = threads_[id];
    if (t.state != ThreadState::Running) [[unlikely]]
        refuse_step(id);
    const uint64_t left = instructions_left(t);
    if (left == 0) [[unlikely]]
        limit_fault(id);
    isa::Hart& h = t.hart;
    ThreadEnv<false, Observer> env(*this, id, {}, &observer);
    Counters& counters = counters_of(id);
    uint64_t* per_op = counters.per_op.data();
    const isa::Decoded* decoded = decoded_.data() + entry_code_.first;
    uint32_t text_base = entry_code_.base;
    uint32_t text_words = entry_code_.words;
    uint64_t n = 0;
    bool stopped = false;
    uint32_t pc = h.pc;
    try {
        // Up to the limits as they stand now (a new work item raises the item limit; the next
        // call sees it).
        for (const uint64_t end = std::min(budget, left); n < end; ++n) {
            pc = h.pc;
            uint32_t index = std::rotr(pc - text_base, 2);
            if (index >= text_words) [[unlikely]] {
                const CodeRange* range = code_range_at(pc);
                if (!range) fetch_fault(id, pc);
                decoded = decoded_.data() + range->first;
                text_base = range->base;
                text_words = range->words;
                index = (pc - text_base) / 4;
            }
            const isa::Decoded& d = decoded[index];
            ++per_op[size_t(d.op)];
            if (d.fu == isa::FuClass::Sync || d.fu == isa::FuClass::System) [[unlikely]] {
                // What the chip needs of an exit or a synchronisation is in its record.
                ThreadEnv<true, Observer> recording(*this, id, &last, &observer);
                last = StepRecord{.pc = pc, .insn = &d};
                isa::execute<ThreadEnv<true, Observer>, false>(d, h, recording);
                last.taken = !last.exited && h.pc != pc + 4;
                if (last.exited || d.fu == isa::FuClass::Sync) {
                    ++n;
                    stopped = true;
                    break;
                }
                continue;
            }
            isa::execute<ThreadEnv<false, Observer>, false>(d, h, env);
        }
    } catch (const ThreadSuspended&) {
        ++n;  // a synchronisation instruction completed; the thread waits
        last.taken = false;
        stopped = true;
    } catch (const GuestFault& f) {
        if (!take_trap(h, f)) {
            executed = n;
            t.executed += n;
            counters.instructions += n;
            fault(id, pc, f);
        }
        ++n;  // the access did not happen; the trap handler runs next
    } catch (...) {
        executed = n;
        t.executed += n;
        counters.instructions += n;
        throw;
    }
    executed = n;
    t.executed += n;
    counters.instructions += n;
    return stopped;
}

inline bool Machine::is_private(const isa::Hart& h, uint32_t index, uint32_t words,
                                uint32_t first) const {
    if (index >= words) return false;
    index += first;
    const Privacy privacy = privacy_[index];
    if (privacy == Privacy::Always || privacy == Privacy::Never) return privacy == Privacy::Always;
    // The local store, its overflow guard and the unmapped space above are private: an access
    // there either touches the thread's own store or faults. Loads from read-only memory (the
    // scene, the kernel's constants) see the same value whenever they run.
    const isa::Decoded& d = decoded_[index];
    const uint32_t addr = h.reg[d.rs1] + uint32_t(d.imm);
    // A store the machine holds (timing mode) changes nothing another thread can see yet.
    return in_local_store(addr) ||
           (privacy == Privacy::Load ? memory_.in_read_only(addr) : held_ != nullptr);
}

inline bool Machine::next_is_private(uint32_t id) const {
    const Thread& t = threads_[id];
    if (t.state != ThreadState::Running) return false;
    const uint32_t pc = t.hart.pc;
    const uint32_t index = std::rotr(pc - entry_code_.base, 2);
    if (index < entry_code_.words)
        return is_private(t.hart, index, entry_code_.words, entry_code_.first);
    const CodeRange* range = code_range_at(pc);
    return range && is_private(t.hart, (pc - range->base) / 4, range->words, range->first);
}

}  // namespace tpsim::core
