// Decoder: a linear scan of the instruction table (it runs once per word of the text segment,
// never in the execute loop), then field extraction by format.
#include "isa/isa.hpp"

namespace tpsim::isa {
namespace {

constexpr uint32_t bits(uint32_t word, unsigned hi, unsigned lo) {
    return (word >> lo) & ((1u << (hi - lo + 1)) - 1);
}

/// Sign-extends the low `width` bits of `value`.
constexpr int32_t sign_extend(uint32_t value, unsigned width) {
    const uint32_t sign = 1u << (width - 1);
    return int32_t((value ^ sign) - sign);
}

/// Maps a 5-bit register field into the unified file (see isa.hpp).
constexpr uint8_t unified(uint32_t field, RegKind kind, bool is_destination) {
    switch (kind) {
    case RegKind::Int:
        return field == 0 && is_destination ? kSink : uint8_t(field);
    case RegKind::Fp:
        return uint8_t(kFpBase + field);
    case RegKind::None:
        break;
    }
    return kNoReg;
}

int32_t immediate(uint32_t word, Format format, uint32_t mask) {
    switch (format) {
    case Format::I:
        // Shifts pin funct7 in the mask; their immediate is the 5-bit shamt.
        if ((mask >> 25) == 0x7f) return int32_t(bits(word, 24, 20));
        return sign_extend(bits(word, 31, 20), 12);
    case Format::S:
        return sign_extend(bits(word, 31, 25) << 5 | bits(word, 11, 7), 12);
    case Format::B:
        return sign_extend(bits(word, 31, 31) << 12 | bits(word, 7, 7) << 11 |
                               bits(word, 30, 25) << 5 | bits(word, 11, 8) << 1,
                           13);
    case Format::U:
        return int32_t(word & 0xffff'f000);
    case Format::J:
        return sign_extend(bits(word, 31, 31) << 20 | bits(word, 19, 12) << 12 |
                               bits(word, 20, 20) << 11 | bits(word, 30, 21) << 1,
                           21);
    case Format::Csr:
    case Format::CsrImm:
    case Format::Fence:
        return int32_t(bits(word, 31, 20));
    case Format::R:
    case Format::R4:
    case Format::System:
        break;
    }
    return 0;
}

}  // namespace

Decoded decode(uint32_t word) {
    Decoded d;
    for (size_t i = 0; i < kNumInsns; ++i) {
        const InsnInfo& insn = info(Op(i));
        if ((word & insn.mask) != insn.match) continue;
        const OperandInfo& ops = insn.operands;
        const uint32_t rm = bits(word, 14, 12);
        // Rounding modes 5 and 6 are reserved: the encoding is illegal.
        if (ops.rounding_mode && (rm == 5 || rm == 6)) return d;
        d.op = Op(i);
        d.fu = insn.fu;
        d.rd = unified(bits(word, 11, 7), ops.rd, true);
        d.rs1 = unified(bits(word, 19, 15), ops.rs1, false);
        d.rs2 = unified(bits(word, 24, 20), ops.rs2, false);
        if (insn.format == Format::R4) d.rs3 = unified(bits(word, 31, 27), RegKind::Fp, false);
        if (ops.rounding_mode) d.rm = uint8_t(rm);
        if (insn.format == Format::CsrImm) d.zimm = uint8_t(bits(word, 19, 15));
        d.imm = immediate(word, insn.format, insn.mask);
        return d;
    }
    return d;
}

}  // namespace tpsim::isa
