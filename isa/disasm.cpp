// Disassembler in llvm-objdump's canonical syntax (as with `-M no-aliases`): ABI register names,
// explicit rounding modes, absolute hexadecimal branch targets, decimal immediates.
#include <array>
#include <string>

#include "isa/csr.hpp"
#include "isa/isa.hpp"

namespace tpsim::isa {
namespace {

constexpr std::array<std::string_view, 32> kIntNames = {
    "zero", "ra", "sp", "gp", "tp",  "t0",  "t1", "t2", "s0", "s1", "a0",
    "a1",   "a2", "a3", "a4", "a5",  "a6",  "a7", "s2", "s3", "s4", "s5",
    "s6",   "s7", "s8", "s9", "s10", "s11", "t3", "t4", "t5", "t6"};
constexpr std::array<std::string_view, 32> kFpNames = {
    "ft0", "ft1", "ft2", "ft3", "ft4",  "ft5",  "ft6", "ft7", "fs0",  "fs1", "fa0",
    "fa1", "fa2", "fa3", "fa4", "fa5",  "fa6",  "fa7", "fs2", "fs3",  "fs4", "fs5",
    "fs6", "fs7", "fs8", "fs9", "fs10", "fs11", "ft8", "ft9", "ft10", "ft11"};
constexpr std::array<std::string_view, 8> kRoundingNames = {"rne", "rtz", "rdn", "rup",
                                                            "rmm", "",    "",    "dyn"};

std::string_view reg_name(uint8_t unified) {
    if (unified == kSink) return kIntNames[0];
    return unified >= kFpBase ? kFpNames[unified - kFpBase] : kIntNames[unified];
}

std::string hex(uint32_t value) {
    static constexpr char kDigits[] = "0123456789abcdef";
    std::string digits;
    do {
        digits.insert(digits.begin(), kDigits[value & 15]);
        value >>= 4;
    } while (value);
    return "0x" + digits;
}

std::string csr_name(uint32_t number) {
    const std::string_view name = csr::name(number);
    return name.empty() ? std::to_string(number) : std::string(name);
}

/// fence's predecessor/successor sets: "iorw" letters, or "0" for the empty set.
std::string fence_set(uint32_t set) {
    std::string s;
    for (auto [bit, letter] : {std::pair{8u, 'i'}, {4u, 'o'}, {2u, 'r'}, {1u, 'w'}})
        if (set & bit) s += letter;
    return s.empty() ? "0" : s;
}

}  // namespace

std::string disassemble(uint32_t word, uint32_t pc) {
    const Decoded d = decode(word);
    if (d.op == Op::Illegal) return "<illegal " + hex(word) + ">";
    const InsnInfo& insn = info(d.op);
    std::string text(insn.mnemonic);
    auto operand = [&, first = true](std::string_view s) mutable {
        text += first ? " " : ", ";
        text += s;
        first = false;
    };
    auto offset_base = [&](uint8_t base) {
        return std::to_string(d.imm) + "(" + std::string(reg_name(base)) + ")";
    };

    switch (insn.format) {
    case Format::R:
    case Format::R4:
        if (d.rd != kNoReg) operand(reg_name(d.rd));  // tp.print has none
        operand(reg_name(d.rs1));
        if (d.rs2 != kNoReg) operand(reg_name(d.rs2));
        if (d.rs3 != kNoReg) operand(reg_name(d.rs3));
        if (insn.operands.rounding_mode) operand(kRoundingNames[d.rm]);
        break;
    case Format::I:
        if (d.rd != kNoReg) operand(reg_name(d.rd));  // tp.semacq/semrel have none
        if (d.rs1 == kNoReg) {                        // tp.atominc rd, imm; tp.semacq imm
            operand(std::to_string(d.imm));
        } else if (insn.fu == FuClass::Load || d.op == Op::jalr) {
            operand(offset_base(d.rs1));
        } else {
            operand(reg_name(d.rs1));
            operand(std::to_string(d.imm));
        }
        break;
    case Format::S:
        operand(reg_name(d.rs2));
        operand(offset_base(d.rs1));
        break;
    case Format::B:
        operand(reg_name(d.rs1));
        operand(reg_name(d.rs2));
        operand(hex(pc + uint32_t(d.imm)));
        break;
    case Format::U:
        operand(reg_name(d.rd));
        operand(std::to_string(uint32_t(d.imm) >> 12));
        break;
    case Format::J:
        operand(reg_name(d.rd));
        operand(hex(pc + uint32_t(d.imm)));
        break;
    case Format::Csr:
    case Format::CsrImm:
        operand(reg_name(d.rd));
        operand(csr_name(uint32_t(d.imm)));
        operand(insn.format == Format::Csr ? std::string(reg_name(d.rs1)) : std::to_string(d.zimm));
        break;
    case Format::Fence:
        if (d.op != Op::fence) break;
        if (uint32_t(d.imm) == 0x833) return "fence.tso";  // fm=1000, pred=succ=rw
        operand(fence_set(uint32_t(d.imm) >> 4 & 15));
        operand(fence_set(uint32_t(d.imm) & 15));
        break;
    case Format::System:
        break;
    }
    return text;
}

}  // namespace tpsim::isa
