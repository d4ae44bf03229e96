// The tpsim instruction set: RV32I + M + F + Zicsr + the small tpsim custom extension.
// Every instruction is defined once, in instructions.def; everything here is derived from it.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace tpsim::isa {

/// One enumerator per instruction in instructions.def, plus Illegal for undecodable words.
enum class Op : uint16_t {
#define TPSIM_INSN(name, ...) name,
#include "isa/instructions.def"
#undef TPSIM_INSN
    Illegal,
    Count
};

/// Encoding formats; they decide which fields carry registers and immediates.
enum class Format : uint8_t { R, R4, I, S, B, U, J, Csr, CsrImm, Fence, System };

/// The functional-unit class that executes an instruction: the timing model keys on this only.
enum class FuClass : uint8_t {
    IntAlu,  ///< add, logic, shifts, compares, lui/auipc
    IntMul,  ///< mul, mulh*
    IntDiv,  ///< div*, rem*
    FpAdd,   ///< fadd, fsub
    FpMul,   ///< fmul, fused multiply-add family
    FpDiv,   ///< fdiv
    FpSqrt,  ///< fsqrt
    FpMisc,  ///< compare, min/max, sign injection, classify, move, convert
    Branch,  ///< conditional branches and jumps
    Load,    ///< lw/lh/lb/flw ...
    Store,   ///< sw/sh/sb/fsw ...
    Atomic,  ///< global-register atomics (tpsim custom extension)
    System,  ///< csr*, fence*, ecall, ebreak, mret
    Sync,    ///< barrier and semaphores (tpsim custom extension)
    Print,   ///< kernel output (tpsim custom extension)
    Count
};

std::string_view to_string(FuClass fu);

/// Register operands live in one unified 65-entry file so the timing model's scoreboard is a
/// flat array: 0..31 are x0..x31, 32..63 are f0..f31, and kSink absorbs writes to x0.
constexpr uint8_t kFpBase = 32;
constexpr uint8_t kSink = 64;
constexpr uint8_t kNumRegs = 65;
/// An unused operand slot: the index just past the file, so a scoreboard with one extra
/// always-ready entry reads every slot without a branch.
constexpr uint8_t kNoReg = kNumRegs;

/// A pre-decoded instruction: decode once, execute many times.
struct Decoded {
    Op op = Op::Illegal;
    uint8_t rd = kNoReg;   ///< unified index; kSink for x0; kNoReg if none
    uint8_t rs1 = kNoReg;  ///< unified index; kNoReg if not read
    uint8_t rs2 = kNoReg;
    uint8_t rs3 = kNoReg;
    uint8_t rm = 0;                ///< FP rounding-mode field (7 = dynamic)
    uint8_t zimm = 0;              ///< 5-bit unsigned immediate of csrrwi/csrrsi/csrrci
    FuClass fu = FuClass::System;  ///< info(op).fu, here so the timing model reads it per issue
    int32_t imm = 0;  ///< sign-extended immediate; CSR number for Zicsr; shamt for shifts;
                      ///< fm|pred|succ for fence
};

/// Which register file an operand field names.
enum class RegKind : uint8_t { None, Int, Fp };

/// The operand fields an instruction uses (rs3 is used, as Fp, by Format::R4 only).
struct OperandInfo {
    RegKind rd = RegKind::None, rs1 = RegKind::None, rs2 = RegKind::None;
    bool rounding_mode = false;  ///< funct3 is a rounding mode
};

/// Parses the table's 4-character operand spec ("fffr", "xf--", ...; see instructions.def).
constexpr OperandInfo operand_info(std::string_view spec) {
    auto kind = [](char c) {
        return c == 'x' ? RegKind::Int : c == 'f' ? RegKind::Fp : RegKind::None;
    };
    return {kind(spec[0]), kind(spec[1]), kind(spec[2]), spec[3] == 'r'};
}

/// Static facts about one instruction, straight from the table.
struct InsnInfo {
    std::string_view mnemonic;
    uint32_t match;
    uint32_t mask;
    Format format;
    FuClass fu;
    OperandInfo operands;
};

constexpr size_t kNumInsns = size_t(Op::Illegal);  ///< table entries (Op::Illegal excluded)

const InsnInfo& info(Op op);

/// Decodes one 32-bit word; returns op == Op::Illegal when no table entry matches.
Decoded decode(uint32_t word);

/// True for a jal or conditional branch whose offset is not a multiple of 4: taken, it jumps
/// to a misaligned target (IALIGN = 32 without the C extension), whatever its pc.
constexpr bool has_misaligned_offset(const Decoded& d) {
    return (d.op == Op::jal || d.op == Op::beq || d.op == Op::bne || d.op == Op::blt ||
            d.op == Op::bge || d.op == Op::bltu || d.op == Op::bgeu) &&
           (d.imm & 3) != 0;
}

/// Disassembles one word as at address pc, in the syntax of llvm-objdump (e.g. "addi a0, a0, 1").
std::string disassemble(uint32_t word, uint32_t pc);

}  // namespace tpsim::isa
