// CSR numbers tpsim knows by name: the standard ones a bare-metal RV32IMF program uses and the
// read-only tpsim custom CSRs (docs/isa.md). One list, so simulator, disassembler and docs agree.
#pragma once
#include <cstdint>
#include <string_view>

namespace tpsim::isa::csr {

// X(constant, number, assembler name)
#define TPSIM_CSRS(X)                                                                              \
    X(kFflags, 0x001, "fflags")                                                                    \
    X(kFrm, 0x002, "frm")                                                                          \
    X(kFcsr, 0x003, "fcsr")                                                                        \
    X(kCycle, 0xC00, "cycle")                                                                      \
    X(kTime, 0xC01, "time")                                                                        \
    X(kInstret, 0xC02, "instret")                                                                  \
    X(kCycleH, 0xC80, "cycleh")                                                                    \
    X(kTimeH, 0xC81, "timeh")                                                                      \
    X(kInstretH, 0xC82, "instreth")                                                                \
    X(kMstatus, 0x300, "mstatus")                                                                  \
    X(kMisa, 0x301, "misa")                                                                        \
    X(kMie, 0x304, "mie")                                                                          \
    X(kMtvec, 0x305, "mtvec")                                                                      \
    X(kMscratch, 0x340, "mscratch")                                                                \
    X(kMepc, 0x341, "mepc")                                                                        \
    X(kMcause, 0x342, "mcause")                                                                    \
    X(kMtval, 0x343, "mtval")                                                                      \
    X(kMip, 0x344, "mip")                                                                          \
    X(kMcycle, 0xB00, "mcycle")                                                                    \
    X(kMinstret, 0xB02, "minstret")                                                                \
    X(kMcycleH, 0xB80, "mcycleh")                                                                  \
    X(kMinstretH, 0xB82, "minstreth")                                                              \
    X(kMvendorid, 0xF11, "mvendorid")                                                              \
    X(kMarchid, 0xF12, "marchid")                                                                  \
    X(kMimpid, 0xF13, "mimpid")                                                                    \
    X(kMhartid, 0xF14, "mhartid")                                                                  \
    X(kNthreads, 0xCC0, "tp.nthreads")                                                             \
    X(kTmid, 0xCC1, "tp.tmid")                                                                     \
    X(kNtms, 0xCC2, "tp.ntms")                                                                     \
    X(kTpid, 0xCC3, "tp.tpid")                                                                     \
    X(kTmsize, 0xCC4, "tp.tmsize")

#define TPSIM_CSR_CONSTANT(constant, number, name) constexpr uint32_t constant = number;
TPSIM_CSRS(TPSIM_CSR_CONSTANT)
#undef TPSIM_CSR_CONSTANT

/// The assembler name of a CSR, or an empty view if tpsim has no name for it.
constexpr std::string_view name(uint32_t number) {
#define TPSIM_CSR_CASE(constant, number, name)                                                     \
    case constant:                                                                                 \
        return name;
    switch (number) {
        TPSIM_CSRS(TPSIM_CSR_CASE)
    default:
        return {};
    }
#undef TPSIM_CSR_CASE
}

/// CSRs whose top two address bits are 11 are read-only by the privileged spec's convention.
constexpr bool is_read_only(uint32_t number) {
    return (number >> 10) == 3;
}

}  // namespace tpsim::isa::csr
