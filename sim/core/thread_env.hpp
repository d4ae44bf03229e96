// The per-instruction execution environment (ThreadEnv) and Machine::step_inline, in a header
// so the timing model's cycle loop can inline the whole step (fetch check, execute, record)
// instead of calling through machine.cpp for every simulated instruction.
#pragma once
#include <bit>
#include <type_traits>

#include <fmt/format.h>

#include "isa/csr.hpp"
#include "isa/execute.hpp"
#include "machine.hpp"

namespace tpsim::core {

namespace detail {

constexpr uint32_t kExitSyscall = 93; // a7 value of exit(a0), as in Linux/newlib
constexpr uint32_t kCauseIllegal = 2; // mcause values of the privileged spec
constexpr uint32_t kCauseEcallM = 11;
constexpr unsigned kA0 = 10, kA7 = 17, kSp = 2;

struct NoRecorder {};

} // namespace detail

/// The isa::execute environment of one thread. kRecord adds the bookkeeping step() reports,
/// written straight into its record; the fast path instantiates it away.
template <bool kRecord> class ThreadEnv {
  public:
    using Record = std::conditional_t<kRecord, StepRecord*, detail::NoRecorder>;

    ThreadEnv(Machine& machine, uint32_t id, Record record = {})
        : machine_(machine), thread_(machine.threads_[id]), id_(id),
          local_(machine.memory_.local_store(id).data()), record_(record) {}

    template <class T> T load(uint32_t addr) {
        if constexpr (kRecord) record_access(addr, sizeof(T), false);
        return machine_.memory_.load<T>(addr, local_);
    }

    template <class T> void store(uint32_t addr, T value) {
        if constexpr (kRecord) record_access(addr, sizeof(T), true);
        machine_.memory_.store<T>(addr, value, local_);
    }

    uint32_t atomic_inc(uint32_t global_register) {
        if (global_register >= kGlobalRegisters) [[unlikely]]
            bad_global_register(global_register);
        return machine_.global_registers_[global_register]++;
    }

    // Out of line: CSR reads are rare, and inlined into the flattened step they only add
    // register pressure.
    [[gnu::noinline]] bool read_csr(uint32_t csr, uint32_t& value) {
        namespace c = isa::csr;
        const Machine& m = machine_;
        const uint32_t per_tm = m.config_.threads_per_tm;
        // Functionally every instruction takes one cycle, so cycle = instret; the timing model
        // supplies real cycles (set_cycle_counter). (instret itself is the hart's.)
        const uint64_t cycles = m.cycle_counter_ ? *m.cycle_counter_ : thread_.hart.instret;
        switch (csr) {
        case c::kMhartid:
            value = id_;
            return true;
        case c::kNthreads:
            value = m.thread_count();
            return true;
        case c::kTmid:
            value = id_ / per_tm;
            return true;
        case c::kNtms:
            value = (m.thread_count() + per_tm - 1) / per_tm;
            return true;
        case c::kTpid:
            value = id_ % per_tm;
            return true;
        case c::kTmsize:
            value = per_tm;
            return true;
        case c::kCycle:
        case c::kMcycle:
        case c::kTime:
            value = uint32_t(cycles);
            return true;
        case c::kCycleH:
        case c::kMcycleH:
        case c::kTimeH:
            value = uint32_t(cycles >> 32);
            return true;
        default:
            return false;
        }
    }

    void ecall(isa::Hart& h) {
        const uint32_t number = h.reg[detail::kA7];
        if (number == detail::kExitSyscall) {
            thread_.state = ThreadState::Exited;
            thread_.exit_code = int32_t(h.reg[detail::kA0]);
            thread_.exit_pc = h.pc;
            h.pc = kParkedPc;
            if constexpr (kRecord) record_->exited = true;
            return;
        }
        if (h.mtvec != 0) return isa::trap(h, detail::kCauseEcallM, 0);
        unsupported_ecall(number);
    }

    // The fault paths are cold and out of line: step_inline is flattened (see there), and they
    // would only bloat the hot body.
    [[gnu::cold, gnu::noinline]] void ebreak(isa::Hart&) {
        throw GuestFault{FaultKind::Breakpoint, "stops the thread",
                         "remove the breakpoint (__builtin_trap / ebreak) or fix the failed "
                         "check that reached it"};
    }

    [[gnu::cold, gnu::noinline]] void illegal(isa::Hart& h, const isa::Decoded& d) {
        const uint32_t word = machine_.memory_.code_word(h.pc);
        const Segment* segment = machine_.program_.segment_at(h.pc);
        if (!segment || !segment->executable) machine_.fetch_fault(id_, h.pc);
        if (h.mtvec != 0) return isa::trap(h, detail::kCauseIllegal, word);
        if (d.op == isa::Op::Illegal)
            throw GuestFault{FaultKind::IllegalInstruction,
                             fmt::format("word {:#010x} is not an RV32IMF instruction", word),
                             "the pc ran into data, or the program uses an extension tpsim lacks "
                             "(compile with -march=rv32imf)"};
        const isa::Format format = isa::info(d.op).format;
        if (format == isa::Format::Csr || format == isa::Format::CsrImm)
            throw GuestFault{FaultKind::IllegalInstruction,
                             fmt::format("accesses CSR {:#05x}, which tpsim does not implement "
                                         "or which is read-only",
                                         uint32_t(d.imm)),
                             "use only the CSRs listed in docs/isa.md"};
        throw GuestFault{FaultKind::IllegalInstruction,
                         fmt::format("has no valid rounding mode (frm = {})", h.frm),
                         "set frm to 0..4 (fsrm) or give the instruction a static rounding mode"};
    }

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
};

// The timing model's hot path (once per simulated instruction): every check in one unlikely
// branch, the environment built inline, the fault paths out of line. Flattened: GCC would
// otherwise keep isa::execute out of line (too big for its inliner), which costs a call and
// keeps the environment and record in memory instead of registers.
[[gnu::flatten]] inline StepRecord Machine::step_inline(uint32_t id) {
    // config_.threads, not threads_.size(): no division by sizeof(Thread).
    if (id >= config_.threads) [[unlikely]]
        refuse_step(id);
    Thread& t = threads_[id];
    if (t.state != ThreadState::Running || t.executed == config_.max_instructions) [[unlikely]]
        refuse_step(id);
    isa::Hart& h = t.hart;
    const uint32_t pc = h.pc;
    const uint32_t index = std::rotr(pc - text_base_, 2); // range and alignment, as in run_quantum
    if (index >= text_bytes_ / 4) [[unlikely]]
        fetch_fault(id, pc);
    const isa::Decoded& d = decoded_[index];
    ++counters_.per_op[size_t(d.op)];
    StepRecord record;
    record.pc = pc;
    record.insn = &d;
    ThreadEnv<true> env(*this, id, &record);
    try {
        isa::execute(d, h, env);
    } catch (const GuestFault& f) {
        fault(id, pc, f);
    }
    ++t.executed;
    ++counters_.instructions;
    record.taken = !record.exited && h.pc != pc + 4;
    return record;
}

} // namespace tpsim::core
