// execute(): the functional semantics of every instruction, expanded from instructions.def into
// one switch. This is the simulator's hot loop: no heap, no virtual calls, no table lookups.
#pragma once
#include <cstdint>

#include "isa/csr.hpp"
#include "isa/fpu.hpp"
#include "isa/hart.hpp"

namespace tpsim::isa {
namespace detail {

/// RISC-V division never traps: x/0 = -1, INT_MIN/-1 = INT_MIN (and the matching remainders).
constexpr int32_t div(int32_t a, int32_t b) {
    if (b == 0) return -1;
    if (a == INT32_MIN && b == -1) return a;
    return a / b;
}
constexpr int32_t rem(int32_t a, int32_t b) {
    if (b == 0) return a;
    if (a == INT32_MIN && b == -1) return 0;
    return a % b;
}

/// misa: RV32 (MXL=1) with I, M, F and X (non-standard extensions present).
constexpr uint32_t kMisa =
    1u << 30 | 1u << ('I' - 'A') | 1u << ('M' - 'A') | 1u << ('F' - 'A') | 1u << ('X' - 'A');
/// mstatus bits that mret touches (machine mode only: MPP reads back as M).
constexpr uint32_t kMie = 1u << 3, kMpie = 1u << 7, kMpp = 3u << 11;

inline void mret(Hart& h) {
    const uint32_t mie = (h.mstatus & kMpie) ? kMie : 0;
    h.mstatus = (h.mstatus & ~kMie) | mie | kMpie | kMpp;
}

/// Hart-held CSR storage, or nullptr if the CSR is not kept in the hart.
inline uint32_t* hart_csr(Hart& h, uint32_t number) {
    switch (number) {
    case csr::kMstatus:
        return &h.mstatus;
    case csr::kMtvec:
        return &h.mtvec;
    case csr::kMepc:
        return &h.mepc;
    case csr::kMcause:
        return &h.mcause;
    case csr::kMtval:
        return &h.mtval;
    case csr::kMscratch:
        return &h.mscratch;
    case csr::kMie:
        return &h.mie;
    case csr::kMip:
        return &h.mip;
    default:
        return nullptr;
    }
}

enum class CsrWrite { Replace, Set, Clear };

/// One Zicsr access: reads the old value, then writes if `writes`. Returns false if the access
/// is illegal (unknown CSR, or a write to a read-only one). instret is the hart's own count of
/// retired instructions (the CSR instruction itself not yet included); cycle, mhartid and the
/// tpsim CSRs come from the environment.
template <class Env>
bool csr_access(uint32_t number, uint32_t source, CsrWrite kind, bool writes, uint32_t& old,
                Hart& h, Env& env) {
    if (writes && csr::is_read_only(number)) return false;
    auto combine = [&](uint32_t value) {
        switch (kind) {
        case CsrWrite::Replace:
            return source;
        case CsrWrite::Set:
            return value | source;
        case CsrWrite::Clear:
            return value & ~source;
        }
        return value;
    };
    switch (number) {
    case csr::kFflags:
        old = h.fflags;
        if (writes) h.fflags = combine(old) & 0x1f;
        return true;
    case csr::kFrm:
        old = h.frm;
        if (writes) h.frm = combine(old) & 0x7;
        return true;
    case csr::kFcsr:
        old = h.frm << 5 | h.fflags;
        if (writes) {
            const uint32_t value = combine(old);
            h.fflags = value & 0x1f;
            h.frm = (value >> 5) & 0x7;
        }
        return true;
    // Zicsr: an explicit write of instret replaces the writing instruction's own increment,
    // so the next instruction reads the value written; execute() adds that increment after
    // this, hence the one less.
    case csr::kInstret:
    case csr::kMinstret:
        old = uint32_t(h.instret);
        if (writes) h.instret = ((h.instret & ~uint64_t{0xffff'ffff}) | combine(old)) - 1;
        return true;
    case csr::kInstretH:
    case csr::kMinstretH:
        old = uint32_t(h.instret >> 32);
        if (writes) h.instret = (uint64_t{combine(old)} << 32 | uint32_t(h.instret)) - 1;
        return true;
    case csr::kMepc:  // without the C extension mepc[1:0] are always zero
        old = h.mepc;
        if (writes) h.mepc = combine(old) & ~3u;
        return true;
    case csr::kMisa:  // WARL: writes are ignored
        old = kMisa;
        return true;
    case csr::kMvendorid:
    case csr::kMarchid:
    case csr::kMimpid:
        old = 0;
        return true;
    default:
        break;
    }
    if (uint32_t* field = hart_csr(h, number)) {
        old = *field;
        if (writes) *field = combine(old);
        return true;
    }
    // Everything else (cycle, mhartid, tp.*) is the environment's and read-only here.
    return !writes && env.read_csr(number, old);
}

}  // namespace detail

/// Executes one pre-decoded instruction (contract in hart.hpp). A pc-relative jump or branch
/// (jal, b*) has a misaligned target exactly when its offset is misaligned
/// (has_misaligned_offset), which decode time knows: kCheckOffsets = false skips their test, for
/// a caller that pre-decodes such words to run them with kCheckOffsets = true (the machine's
/// fast loop); jalr's target is always checked.
template <class Env, bool kCheckOffsets = true>
inline void execute(const Decoded& d, Hart& h, Env& env) {
    uint32_t npc = h.pc + 4;

// Helper vocabulary of the instruction bodies (see instructions.def).
#define RS1 h.reg[d.rs1]
#define RS2 h.reg[d.rs2]
#define RS3 h.reg[d.rs3]
#define SRS1 int32_t(h.reg[d.rs1])
#define SRS2 int32_t(h.reg[d.rs2])
#define IMM d.imm
#define PC h.pc
#define NPC npc
#define RM rm
#define FFLAGS h.fflags
#define WRITE_RD(value) (h.reg[d.rd] = uint32_t(value))
// Without the C extension a target must be 4-byte aligned; a misaligned one is the jump's own
// exception (instruction-address-misaligned): the instruction does not complete.
#define JUMP(target)                                                                               \
    do {                                                                                           \
        const uint32_t jump_to = (target);                                                         \
        if (jump_to & 3) [[unlikely]] {                                                            \
            env.misaligned_jump(h, jump_to);                                                       \
            return;                                                                                \
        }                                                                                          \
        npc = jump_to;                                                                             \
    } while (false)
#define JUMP_RELATIVE(target)                                                                      \
    do {                                                                                           \
        if constexpr (kCheckOffsets)                                                               \
            JUMP(target);                                                                          \
        else                                                                                       \
            npc = (target);                                                                        \
    } while (false)
#define LOAD(type) env.template load<type>(RS1 + IMM)
#define STORE(type, value) env.template store<type>(RS1 + IMM, type(value))
#define CSR(source, kind, writes)                                                                  \
    do {                                                                                           \
        uint32_t old = 0;                                                                          \
        if (!detail::csr_access(uint32_t(IMM), uint32_t(source), kind, writes, old, h, env)) {     \
            env.illegal(h, d);                                                                     \
            return;                                                                                \
        }                                                                                          \
        WRITE_RD(old);                                                                             \
    } while (false)

    switch (d.op) {
#define TPSIM_INSN(name, mnemonic, match, mask, format, fu, operands, ...)                         \
    case Op::name: {                                                                               \
        [[maybe_unused]] unsigned rm = 0;                                                          \
        if constexpr (operand_info(operands).rounding_mode) {                                      \
            rm = d.rm == fpu::DYN ? h.frm : d.rm;                                                  \
            if (rm > fpu::RMM) {                                                                   \
                env.illegal(h, d);                                                                 \
                return;                                                                            \
            }                                                                                      \
        }                                                                                          \
        __VA_ARGS__;                                                                               \
        break;                                                                                     \
    }
#include "isa/instructions.def"
#undef TPSIM_INSN
    case Op::Illegal:
    case Op::Count:
        env.illegal(h, d);
        return;
    }

#undef RS1
#undef RS2
#undef RS3
#undef SRS1
#undef SRS2
#undef IMM
#undef PC
#undef NPC
#undef RM
#undef FFLAGS
#undef WRITE_RD
#undef JUMP
#undef JUMP_RELATIVE
#undef LOAD
#undef STORE
#undef CSR

    h.pc = npc;
    ++h.instret;
}

}  // namespace tpsim::isa
