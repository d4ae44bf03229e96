// Architectural state of one hardware thread, and the contract of execute().
#pragma once
#include "isa/isa.hpp"

namespace tpsim::isa {

/// Registers and the machine-mode CSRs a bare-metal program uses. No timing, no memory.
struct Hart {
    uint32_t reg[kNumRegs] = {};  ///< unified file (see isa.hpp); reg[0] is always 0
    uint32_t pc = 0;
    uint32_t fflags = 0;  ///< accrued exception flags NV|DZ|OF|UF|NX (bits 4..0)
    uint32_t frm = 0;     ///< dynamic rounding mode
    uint32_t mstatus = 0, mtvec = 0, mepc = 0, mcause = 0, mtval = 0, mscratch = 0;
    uint32_t mie = 0, mip = 0;
    uint64_t instret = 0;

    float f(unsigned i) const;  ///< f-register i as a float
};

/// mcause exception codes of the privileged spec (machine mode, synchronous exceptions).
namespace cause {
constexpr uint32_t kMisalignedFetch = 0;  ///< jump or branch to a target not 4-byte aligned
constexpr uint32_t kIllegal = 2;
constexpr uint32_t kBreakpoint = 3;
constexpr uint32_t kMisalignedLoad = 4;
constexpr uint32_t kLoadAccess = 5;
constexpr uint32_t kMisalignedStore = 6;
constexpr uint32_t kStoreAccess = 7;
constexpr uint32_t kEcallM = 11;
}  // namespace cause

/// Sets the trap CSRs and jumps to mtvec (direct mode), as a machine-mode trap does.
inline void trap(Hart& h, uint32_t cause, uint32_t tval) {
    h.mepc = h.pc;
    h.mcause = cause;
    h.mtval = tval;
    h.pc = h.mtvec & ~3u;
}

/// What execute() does after an instruction that completes: the environment's synchronisation
/// hooks (barrier, sem_acquire, sem_release) call it themselves, before the thread may wait.
inline void complete(Hart& h) {
    h.pc += 4;
    ++h.instret;
}

// execute() lives in execute.hpp:
//
//   template <class Env> void execute(const Decoded& d, Hart& h, Env& env);
//
// runs one instruction, updating registers, pc (always; next pc or branch target) and CSRs.
// Env supplies everything outside the hart:
//   template <class T> T    env.load(uint32_t addr);          // T: u8/i8/u16/i16/u32; may throw
//   template <class T> void env.store(uint32_t addr, T value); // may throw
//   uint32_t env.atomic_inc(uint32_t global_register);         // returns the old value
//   void env.print(uint32_t address, uint32_t length);          // tp.print; may throw
//   void env.barrier(Hart& h);                                  // pc still at the instruction;
//   void env.sem_acquire(Hart& h, uint32_t global_register);    // the environment completes
//   void env.sem_release(Hart& h, uint32_t global_register);    // them (complete()) or faults
//   bool env.read_csr(uint32_t csr, uint32_t& value);          // machine CSRs (mhartid, cycle,
//                                                              // custom); false = not mine
//   void env.ecall(Hart& h);  void env.ebreak(Hart& h);        // pc still at the instruction
//   void env.illegal(Hart& h, const Decoded& d);               // pc still at the instruction
//   void env.misaligned_jump(Hart& h, uint32_t target);        // pc still at the jump
//
// ecall, ebreak, illegal instructions (including unknown CSRs, writes to read-only CSRs and
// FP instructions whose dynamic rounding mode frm is 5..7) and jumps or taken branches to a
// target that is not 4-byte aligned do not complete: execute() calls the
// hook and returns without touching pc or instret, so the environment decides what follows
// (halt the thread, emulate and advance pc itself, or call trap()). Every other instruction
// completes: pc advances (or jumps) and instret is incremented. A load or store that throws
// leaves the hart exactly as before the instruction.

}  // namespace tpsim::isa
