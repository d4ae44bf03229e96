// The instruction table is consistent, and decode/disassemble agree with LLVM's assembler and
// disassembler on every instruction.
#include <catch2/catch.hpp>

#include <fstream>
#include <random>
#include <regex>
#include <sstream>

#include "tests/isa/test_support.hpp"

using namespace tpsim::isa;
using namespace tpsim::isa::test;

TEST_CASE("no two table encodings overlap", "[isa][table]") {
    // A word matches both entries iff the matches agree on every bit that both masks fix.
    for (size_t i = 0; i < kNumInsns; ++i) {
        for (size_t j = i + 1; j < kNumInsns; ++j) {
            const InsnInfo &a = info(Op(i)), &b = info(Op(j));
            INFO(a.mnemonic << " vs " << b.mnemonic);
            CHECK(((a.match ^ b.match) & a.mask & b.mask) != 0);
        }
    }
}

TEST_CASE("every table entry is self-consistent", "[isa][table]") {
    for (size_t i = 0; i < kNumInsns; ++i) {
        const InsnInfo& insn = info(Op(i));
        INFO(insn.mnemonic);
        CHECK((insn.match & ~insn.mask) == 0);
        CHECK((insn.mask & 0x7f) == 0x7f);  // the major opcode is always fixed
        CHECK(insn.fu != FuClass::Count);
    }
}

TEST_CASE("every instruction decodes back to itself from random operand fields", "[isa][decode]") {
    std::mt19937 rng(6958);
    for (size_t i = 0; i < kNumInsns; ++i) {
        const Op op = Op(i);
        const InsnInfo& insn = info(op);
        INFO(insn.mnemonic);
        for (int trial = 0; trial < 200; ++trial) {
            const uint32_t word = (uint32_t(rng()) & ~insn.mask) | insn.match;
            const Decoded d = decode(word);
            const uint32_t rm = word >> 12 & 7;
            if (insn.operands.rounding_mode && (rm == 5 || rm == 6)) {
                CHECK(d.op == Op::Illegal);  // reserved rounding modes
                continue;
            }
            REQUIRE(d.op == op);
            CHECK(d.fu == insn.fu);
            const uint32_t rd = word >> 7 & 31, rs1 = word >> 15 & 31, rs2 = word >> 20 & 31;
            auto expect = [](RegKind kind, uint32_t field, bool destination) -> uint8_t {
                if (kind == RegKind::None) return kNoReg;
                if (kind == RegKind::Fp) return uint8_t(32 + field);
                return destination && field == 0 ? kSink : uint8_t(field);
            };
            CHECK(d.rd == expect(insn.operands.rd, rd, true));
            CHECK(d.rs1 == expect(insn.operands.rs1, rs1, false));
            CHECK(d.rs2 == expect(insn.operands.rs2, rs2, false));
            CHECK(d.rs3 == (insn.format == Format::R4 ? uint8_t(32 + (word >> 27)) : kNoReg));
        }
    }
}

TEST_CASE("decoder rejects what is not RV32IMF + tpsim", "[isa][decode]") {
    CHECK(decode(0x0000'0000).op == Op::Illegal);  // all-zero word: defined illegal
    CHECK(decode(0x0000'0000).fu == info(Op::Illegal).fu);
    CHECK(decode(0xffff'ffff).op == Op::Illegal);  // all-ones word: defined illegal
    CHECK(decode(0x0200'1013).op == Op::Illegal);  // slli with shamt[5]=1 is RV64 only
    CHECK(decode(0x0000'3003).op == Op::Illegal);  // ld (RV64)
    CHECK(decode(0x0000'3007).op == Op::Illegal);  // fld (D extension)
    CHECK(decode(0x0200'0053).op == Op::Illegal);  // fadd.d
    CHECK(decode(0x1000'202f).op == Op::Illegal);  // lr.w (A extension)
    CHECK(decode(0x0000'0001).op == Op::Illegal);  // compressed quadrant
    CHECK(decode(0x0000'800b).op == Op::Illegal);  // custom-0 with rs1 = x1
    CHECK(decode(0x1000'000b).op == Op::Illegal);  // custom-0 with imm = 256
    // fadd.s with rm = 5 and 6 is reserved; 7 (dynamic) is legal.
    CHECK(decode(encode(Op::fadd_s, 1, 2, 3, 0, 5)).op == Op::Illegal);
    CHECK(decode(encode(Op::fadd_s, 1, 2, 3, 0, 6)).op == Op::Illegal);
    CHECK(decode(encode(Op::fadd_s, 1, 2, 3, 0, 7)).op == Op::fadd_s);
}

TEST_CASE("tp.atominc encoding and disassembly", "[isa][decode][custom]") {
    // `.insn i 0x0b, 0, a0, x0, 5` = imm 5 << 20 | rd 10 << 7 | 0x0b.
    const uint32_t word = 5u << 20 | 10u << 7 | 0x0b;
    const Decoded d = decode(word);
    CHECK(d.op == Op::tp_atominc);
    CHECK(d.rd == 10);
    CHECK(d.rs1 == kNoReg);
    CHECK(d.imm == 5);
    CHECK(info(d.op).fu == FuClass::Atomic);
    CHECK(disassemble(word, 0) == "tp.atominc a0, 5");
    CHECK(disassemble(255u << 20 | 10u << 7 | 0x0b, 0) == "tp.atominc a0, 255");
}

TEST_CASE("tp.print, tp.barrier, tp.semacq, tp.semrel encodings and disassembly",
          "[isa][decode][custom]") {
    // `.insn r 0x0b, 1, 0, x0, a0, a1`: funct3 1, rs1 a0, rs2 a1.
    const uint32_t print = 11u << 20 | 10u << 15 | 1u << 12 | 0x0b;
    Decoded d = decode(print);
    CHECK(d.op == Op::tp_print);
    CHECK(d.rs1 == 10);
    CHECK(d.rs2 == 11);
    CHECK(d.rd == kNoReg);
    CHECK(info(d.op).fu == FuClass::Print);
    CHECK(disassemble(print, 0) == "tp.print a0, a1");
    CHECK(decode(print | 1u << 7).op == Op::Illegal);   // rd must be 0
    CHECK(decode(print | 1u << 25).op == Op::Illegal);  // funct7 must be 0

    CHECK(decode(0x0000200b).op == Op::tp_barrier);
    CHECK(info(Op::tp_barrier).fu == FuClass::Sync);
    CHECK(disassemble(0x0000200b, 0) == "tp.barrier");
    CHECK(decode(0x0000208b).op == Op::Illegal);  // any other field set

    // `.insn i 0x0b, 3, x0, x0, 7` and funct3 4.
    const uint32_t acquire = 7u << 20 | 3u << 12 | 0x0b, release = 7u << 20 | 4u << 12 | 0x0b;
    d = decode(acquire);
    CHECK(d.op == Op::tp_semacq);
    CHECK(d.imm == 7);
    CHECK(d.rd == kNoReg);
    CHECK(info(d.op).fu == FuClass::Sync);
    CHECK(disassemble(acquire, 0) == "tp.semacq 7");
    CHECK(decode(release).op == Op::tp_semrel);
    CHECK(disassemble(release | 255u << 20, 0) == "tp.semrel 255");
    CHECK(decode(acquire | 1u << 7).op == Op::Illegal);   // rd must be 0
    CHECK(decode(acquire | 1u << 28).op == Op::Illegal);  // imm above 255
    CHECK(decode(5u << 12 | 0x0b).op == Op::Illegal);     // funct3 5.. are free
}

TEST_CASE("custom CSRs disassemble by name", "[isa][disasm][custom]") {
    // csrrs a0, 0xcc3, zero
    CHECK(disassemble(0xcc30'2573, 0) == "csrrs a0, tp.tpid, zero");
    CHECK(disassemble(0, 0) == "<illegal 0x0>");
}

namespace {

std::vector<std::string> read_lines(const char* path) {
    std::ifstream in(path);
    REQUIRE(in);
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);)
        lines.push_back(line);
    return lines;
}

std::string collapse_whitespace(const std::string& s) {
    std::istringstream in(s);
    std::string word, out;
    while (in >> word)
        out += (out.empty() ? "" : " ") + word;
    return out;
}

}  // namespace

TEST_CASE("decode and disassembly match LLVM on every instruction", "[isa][decode][disasm][llvm]") {
    // Source mnemonics, in order, one instruction per non-comment line.
    std::vector<std::string> mnemonics;
    for (const std::string& line : read_lines(TPSIM_ALL_INSNS_SRC)) {
        if (line.empty() || line[0] == '#') continue;
        mnemonics.push_back(line.substr(0, line.find(' ')));
    }
    // llvm-objdump lines: "  addr: b0 b1 b2 b3 \tmnemonic\toperands [<symbol+off>]".
    const std::regex row(
        R"(^\s*([0-9a-f]+):\s+([0-9a-f]{2}) ([0-9a-f]{2}) ([0-9a-f]{2}) ([0-9a-f]{2})\s+([^<]*))");
    size_t index = 0;
    std::vector<bool> seen(kNumInsns);
    for (const std::string& line : read_lines(TPSIM_ALL_INSNS_DIS)) {
        std::smatch m;
        if (!std::regex_search(line, m, row)) continue;
        REQUIRE(index < mnemonics.size());
        const uint32_t pc = uint32_t(std::stoul(m[1], nullptr, 16));
        uint32_t word = 0;
        for (int b = 0; b < 4; ++b)
            word |= uint32_t(std::stoul(m[2 + b], nullptr, 16)) << (8 * b);
        const Decoded d = decode(word);
        INFO(line);
        CHECK(info(d.op).mnemonic == mnemonics[index]);
        if (d.op != Op::Illegal) seen[size_t(d.op)] = true;
        CHECK(collapse_whitespace(disassemble(word, pc)) == collapse_whitespace(m[6]));
        ++index;
    }
    CHECK(index == mnemonics.size());
    // Everything but the custom extension (unknown to LLVM) is covered by the file.
    for (size_t i = 0; i < kNumInsns; ++i)
        if (!info(Op(i)).mnemonic.starts_with("tp.")) {
            INFO(info(Op(i)).mnemonic);
            CHECK(seen[i]);
        }
}
