// execute() semantics of the integer, memory, control-flow, CSR and custom instructions.
// Expected values come from the RISC-V unprivileged spec (chapters 2, 7, 9) by hand.
#include <catch2/catch.hpp>

#include "tests/isa/test_support.hpp"

using namespace tpsim::isa;
using namespace tpsim::isa::test;

namespace {

/// Runs `op rd=x3, rs1=x1 (a), rs2=x2 (b)` and returns x3.
uint32_t alu(Op op, uint32_t a, uint32_t b) {
    Hart h;
    FakeEnv env;
    h.reg[1] = a;
    h.reg[2] = b;
    run(h, env, encode(op, x(3), x(1), x(2)));
    return h.reg[3];
}

uint32_t alu_imm(Op op, uint32_t a, int32_t imm) {
    Hart h;
    FakeEnv env;
    h.reg[1] = a;
    run(h, env, encode(op, x(3), x(1), 0, imm));
    return h.reg[3];
}

constexpr uint32_t kIntMin = 0x8000'0000;

}  // namespace

TEST_CASE("integer ALU and shifts", "[isa][execute]") {
    CHECK(alu(Op::add, 0xffff'ffff, 1) == 0);  // wraps
    CHECK(alu(Op::sub, 0, 1) == 0xffff'ffff);
    CHECK(alu(Op::slt, kIntMin, 0) == 1);   // INT_MIN < 0 signed
    CHECK(alu(Op::sltu, kIntMin, 0) == 0);  // but not unsigned
    CHECK(alu(Op::sll, 1, 33) == 2);        // shift amount is rs2[4:0]
    CHECK(alu(Op::srl, kIntMin, 31) == 1);
    CHECK(alu(Op::sra, kIntMin, 31) == 0xffff'ffff);
    CHECK(alu(Op::xor_, 0xf0f0, 0xff00) == 0x0ff0);
    CHECK(alu(Op::or_, 0xf0f0, 0xff00) == 0xfff0);
    CHECK(alu(Op::and_, 0xf0f0, 0xff00) == 0xf000);
    CHECK(alu_imm(Op::addi, 5, -2048) == uint32_t(5 - 2048));
    CHECK(alu_imm(Op::sltiu, 5, -1) ==
          1);  // imm sign-extends to 0xffffffff, then compares unsigned
    CHECK(alu_imm(Op::slti, 5, -1) == 0);
    CHECK(alu_imm(Op::xori, 0x1234, -1) == ~0x1234u);
    CHECK(alu_imm(Op::srai, 0x8000'0000, 4) == 0xf800'0000);
    CHECK(alu_imm(Op::srli, 0x8000'0000, 4) == 0x0800'0000);
    CHECK(alu_imm(Op::slli, 3, 31) == 0x8000'0000);
}

TEST_CASE("M extension edge cases", "[isa][execute]") {
    // Spec table 7.1: division by zero and signed overflow.
    CHECK(alu(Op::div, 7, 0) == 0xffff'ffff);
    CHECK(alu(Op::divu, 7, 0) == 0xffff'ffff);
    CHECK(alu(Op::rem, 7, 0) == 7);
    CHECK(alu(Op::remu, 7, 0) == 7);
    CHECK(alu(Op::div, kIntMin, 0xffff'ffff) == kIntMin);
    CHECK(alu(Op::rem, kIntMin, 0xffff'ffff) == 0);
    // Truncating division: -7/2 = -3 rem -1.
    CHECK(alu(Op::div, uint32_t(-7), 2) == uint32_t(-3));
    CHECK(alu(Op::rem, uint32_t(-7), 2) == uint32_t(-1));
    CHECK(alu(Op::divu, uint32_t(-7), 2) == 0x7fff'fffc);
    // High products: (-1)*(-1) = 1 -> high 0; as unsigned (2^32-1)^2 -> high 2^32-2;
    // signed -1 times unsigned 2^32-1 = -(2^32-1) -> high word -1.
    CHECK(alu(Op::mul, 0xffff'ffff, 0xffff'ffff) == 1);
    CHECK(alu(Op::mulh, 0xffff'ffff, 0xffff'ffff) == 0);
    CHECK(alu(Op::mulhu, 0xffff'ffff, 0xffff'ffff) == 0xffff'fffe);
    CHECK(alu(Op::mulhsu, 0xffff'ffff, 0xffff'ffff) == 0xffff'ffff);
    CHECK(alu(Op::mulh, kIntMin, kIntMin) == 0x4000'0000);  // 2^62 >> 32
}

TEST_CASE("x0 stays zero and pc/instret advance", "[isa][execute]") {
    Hart h;
    FakeEnv env;
    h.pc = 0x100;
    h.reg[1] = 42;
    run(h, env, encode(Op::addi, x(0), x(1), 0, 1));
    CHECK(h.reg[0] == 0);
    CHECK(h.reg[kSink] == 43);
    CHECK(h.pc == 0x104);
    CHECK(h.instret == 1);
}

TEST_CASE("loads sign- or zero-extend, stores truncate", "[isa][execute]") {
    Hart h;
    FakeEnv env;
    h.reg[1] = 0x100;
    h.reg[2] = 0x8180'ff80;
    run(h, env, encode(Op::sw, 0, x(1), x(2), 4));
    CHECK(env.memory[0x104] == 0x80);  // little-endian
    run(h, env, encode(Op::lb, x(3), x(1), 0, 4));
    CHECK(h.reg[3] == 0xffff'ff80);
    run(h, env, encode(Op::lbu, x(3), x(1), 0, 4));
    CHECK(h.reg[3] == 0x80);
    run(h, env, encode(Op::lh, x(3), x(1), 0, 4));
    CHECK(h.reg[3] == 0xffff'ff80);
    run(h, env, encode(Op::lhu, x(3), x(1), 0, 6));
    CHECK(h.reg[3] == 0x8180);
    run(h, env, encode(Op::lw, x(3), x(1), 0, 4));
    CHECK(h.reg[3] == 0x8180'ff80);
    run(h, env, encode(Op::sb, 0, x(1), x(2), -1));
    CHECK(env.memory[0xff] == 0x80);
    run(h, env, encode(Op::sh, 0, x(1), x(2), 0x10));
    CHECK(env.memory[0x110] == 0x80);
    CHECK(env.memory[0x111] == 0xff);
    CHECK(env.memory[0x112] == 0);
    // A faulting access throws and leaves the hart as it was.
    const uint32_t pc = h.pc;
    const uint64_t instret = h.instret;
    h.reg[1] = 0xffff'0000;
    CHECK_THROWS(run(h, env, encode(Op::lw, x(3), x(1), 0, 0)));
    CHECK(h.pc == pc);
    CHECK(h.instret == instret);
}

TEST_CASE("branches and jumps", "[isa][execute]") {
    auto branch = [](Op op, uint32_t a, uint32_t b) {
        Hart h;
        FakeEnv env;
        h.pc = 0x1000;
        h.reg[1] = a;
        h.reg[2] = b;
        run(h, env, encode(op, 0, x(1), x(2), -16));
        return h.pc == 0x1000 - 16;
    };
    CHECK(branch(Op::beq, 3, 3));
    CHECK_FALSE(branch(Op::beq, 3, 4));
    CHECK(branch(Op::bne, 3, 4));
    CHECK(branch(Op::blt, kIntMin, 1));
    CHECK_FALSE(branch(Op::bltu, kIntMin, 1));
    CHECK(branch(Op::bge, 1, kIntMin));
    CHECK(branch(Op::bgeu, kIntMin, 1));
    CHECK(branch(Op::bge, 5, 5));

    Hart h;
    FakeEnv env;
    h.pc = 0x1000;
    run(h, env, encode(Op::jal, x(1), 0, 0, 0x800));
    CHECK(h.pc == 0x1800);
    CHECK(h.reg[1] == 0x1004);
    // jalr clears bit 0 of the target and reads rs1 before writing rd (rd == rs1 here).
    h.reg[5] = 0x2002;
    run(h, env, encode(Op::jalr, x(5), x(5), 0, 3));
    CHECK(h.pc == 0x2004);
    CHECK(h.reg[5] == 0x1804);
    // A target that is not 4-byte aligned: the jump does not complete (pc, rd, instret kept).
    const uint64_t instret = h.instret;
    h.reg[7] = 0x3002;
    run(h, env, encode(Op::jalr, x(1), x(7), 0, 0));
    CHECK(env.misaligned_jumps == 1);
    CHECK(h.pc == 0x2004);
    CHECK(h.reg[1] == 0x1004);
    CHECK(h.instret == instret);
    run(h, env, encode(Op::lui, x(6), 0, 0, int32_t(0xabcde000)));
    CHECK(h.reg[6] == 0xabcd'e000);
    run(h, env, encode(Op::auipc, x(6), 0, 0, 0x1000));
    CHECK(h.reg[6] == 0x2004 + 0x1000 + 4);  // pc of the auipc: 0x2008
}

TEST_CASE("CSR instructions", "[isa][execute][csr]") {
    Hart h;
    FakeEnv env;
    h.reg[1] = 0xff;
    // csrrw fcsr: reads 0, writes frm=7, fflags=0x1f (8-bit field).
    run(h, env, encode(Op::csrrw, x(2), x(1), 0, csr::kFcsr));
    CHECK(h.reg[2] == 0);
    CHECK(h.fflags == 0x1f);
    CHECK(h.frm == 7);
    // csrrci fflags, 0b00101 clears NX and OF; reads the old value.
    run(h, env, encode(Op::csrrci, x(3), 5, 0, csr::kFflags));
    CHECK(h.reg[3] == 0x1f);
    CHECK(h.fflags == 0x1a);
    // csrrs with rs1=x0 only reads: allowed on read-only CSRs, served by the env.
    run(h, env, encode(Op::csrrs, x(4), x(0), 0, csr::kMhartid));
    CHECK(h.reg[4] == 7);
    run(h, env, encode(Op::csrrs, x(4), x(0), 0, csr::kNthreads));
    CHECK(h.reg[4] == 128);
    // instret counts retired instructions before this one (4 so far).
    run(h, env, encode(Op::csrrs, x(4), x(0), 0, csr::kInstret));
    CHECK(h.reg[4] == 4);
    run(h, env, encode(Op::csrrw, x(4), x(1), 0, csr::kMscratch));
    run(h, env, encode(Op::csrrs, x(4), x(0), 0, csr::kMscratch));
    CHECK(h.reg[4] == 0xff);
    CHECK(env.illegals == 0);
    // Writing a read-only CSR, or touching an unknown one, is illegal and does not retire.
    const uint32_t pc = h.pc;
    run(h, env, encode(Op::csrrw, x(4), x(1), 0, csr::kMhartid));
    run(h, env, encode(Op::csrrs, x(4), x(0), 0, 0x7c0));
    CHECK(env.illegals == 2);
    CHECK(h.pc == pc);
}

TEST_CASE("system instructions", "[isa][execute]") {
    Hart h;
    FakeEnv env;
    h.pc = 0x40;
    run(h, env, 0x0000'0073);  // ecall
    run(h, env, 0x0010'0073);  // ebreak
    run(h, env, 0);            // illegal
    CHECK(env.ecalls == 1);
    CHECK(env.ebreaks == 1);
    CHECK(env.illegals == 1);
    CHECK(h.pc == 0x40);
    CHECK(h.instret == 0);
    run(h, env, 0x1050'0073);  // wfi: no-op
    run(h, env, 0x0ff0'000f);  // fence iorw, iorw
    CHECK(h.pc == 0x48);
    // mret returns to mepc and sets MIE from MPIE.
    h.mepc = 0x200;
    h.mstatus = 1u << 7;
    run(h, env, 0x3020'0073);
    CHECK(h.pc == 0x200);
    CHECK((h.mstatus & (1u << 3)) != 0);
}

TEST_CASE("tp.print and the synchronisation instructions reach the environment",
          "[isa][execute][custom]") {
    Hart h;
    FakeEnv env;
    std::memcpy(&env.memory[100], "hello", 5);
    h.reg[10] = 100;
    h.reg[11] = 5;
    run(h, env, 11u << 20 | 10u << 15 | 1u << 12 | 0x0b);  // tp.print a0, a1
    CHECK(env.printed == "hello");
    CHECK(h.pc == 4);
    CHECK(h.instret == 1);
    run(h, env, 0x0000200b);                  // tp.barrier
    run(h, env, 9u << 20 | 3u << 12 | 0x0b);  // tp.semacq 9
    run(h, env, 9u << 20 | 4u << 12 | 0x0b);  // tp.semrel 9
    CHECK(env.barriers == 1);
    CHECK(env.acquired == std::vector<uint32_t>{9});
    CHECK(env.released == std::vector<uint32_t>{9});
    // The environment completed each once: not twice.
    CHECK(h.pc == 16);
    CHECK(h.instret == 4);
}

TEST_CASE("tp.atominc returns the old value and increments", "[isa][execute][custom]") {
    Hart h;
    FakeEnv env;
    env.globals[3] = 41;
    const uint32_t word = 3u << 20 | 10u << 7 | 0x0b;  // tp.atominc a0, 3
    run(h, env, word);
    CHECK(h.reg[10] == 41);
    run(h, env, word);
    CHECK(h.reg[10] == 42);
    CHECK(env.globals[3] == 43);
}
