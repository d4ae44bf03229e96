// The static instruction table (expanded from instructions.def) and small accessors.
#include "isa/isa.hpp"

#include <bit>
#include <iterator>

#include "isa/hart.hpp"

namespace tpsim::isa {

const InsnInfo& info(Op op) {
    static constexpr InsnInfo kTable[] = {
#define TPSIM_INSN(name, mnemonic, match, mask, format, fu, operands, ...)                         \
    {mnemonic, match, mask, format, fu, operand_info(operands)},
#include "isa/instructions.def"
#undef TPSIM_INSN
        {"<illegal>", 0, 0, Format::System, FuClass::System, {}},
    };
    static_assert(std::size(kTable) == size_t(Op::Illegal) + 1);
    return kTable[op < Op::Illegal ? size_t(op) : size_t(Op::Illegal)];
}

std::string_view to_string(FuClass fu) {
    switch (fu) {
    case FuClass::IntAlu:
        return "int_alu";
    case FuClass::IntMul:
        return "int_mul";
    case FuClass::IntDiv:
        return "int_div";
    case FuClass::FpAdd:
        return "fp_add";
    case FuClass::FpMul:
        return "fp_mul";
    case FuClass::FpDiv:
        return "fp_div";
    case FuClass::FpSqrt:
        return "fp_sqrt";
    case FuClass::FpMisc:
        return "fp_misc";
    case FuClass::Branch:
        return "branch";
    case FuClass::Load:
        return "load";
    case FuClass::Store:
        return "store";
    case FuClass::Atomic:
        return "atomic";
    case FuClass::System:
        return "system";
    case FuClass::Sync:
        return "sync";
    case FuClass::Print:
        return "print";
    case FuClass::Count:
        break;
    }
    return "?";
}

float Hart::f(unsigned i) const {
    return std::bit_cast<float>(reg[kFpBase + i]);
}

}  // namespace tpsim::isa
