// Fuzzes the decoder and disassembler (isa/decode.cpp, isa/disasm.cpp): the input as
// little-endian 32-bit words at consecutive addresses. Neither may throw or crash, and decode
// must agree with the table: the first entry whose mask and match fit the word, unless its
// rounding-mode field holds a reserved mode (5 or 6), which is illegal; operands stay in the
// register file.
#include <cstdint>
#include <cstring>

#include "isa/isa.hpp"

namespace {

tpsim::isa::Op expected_op(uint32_t word) {
    using namespace tpsim::isa;
    for (size_t i = 0; i < kNumInsns; ++i) {
        const InsnInfo& insn = info(Op(i));
        if ((word & insn.mask) != insn.match) continue;
        const uint32_t rm = (word >> 12) & 7;
        return insn.operands.rounding_mode && (rm == 5 || rm == 6) ? Op::Illegal : Op(i);
    }
    return Op::Illegal;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace tpsim::isa;
    for (size_t offset = 0; offset + 4 <= size; offset += 4) {
        uint32_t word;
        std::memcpy(&word, data + offset, 4);
        const Decoded d = decode(word);
        if (d.op != expected_op(word) || d.fu != info(d.op).fu) __builtin_trap();
        if (d.rd > kNoReg || d.rs1 > kNoReg || d.rs2 > kNoReg || d.rs3 > kNoReg) __builtin_trap();
        if (disassemble(word, 0x10000 + uint32_t(offset)).empty()) __builtin_trap();
    }
    return 0;
}
