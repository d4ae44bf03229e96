// Shared helpers for the isa tests: an instruction encoder built from the table's match bits and
// the spec's field layouts, and a fake environment with a flat memory.
#pragma once
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "isa/csr.hpp"
#include "isa/execute.hpp"

namespace tpsim::isa::test {

/// Register operand for the encoder: x(n) integer, f(n) float (plain 5-bit field numbers).
constexpr uint32_t x(uint32_t n) {
    return n;
}
constexpr uint32_t f(uint32_t n) {
    return n;
}

/// Encodes `op` with the given fields; imm is placed per the op's format (RISC-V spec, ch. 2).
inline uint32_t encode(Op op, uint32_t rd, uint32_t rs1, uint32_t rs2, int32_t imm = 0,
                       uint32_t rm = 0, uint32_t rs3 = 0) {
    const InsnInfo& insn = info(op);
    const uint32_t u = uint32_t(imm);
    uint32_t w = insn.match | rd << 7 | rs1 << 15 | rs2 << 20;
    switch (insn.format) {
    case Format::R:
        break;
    case Format::R4:
        w |= rs3 << 27;
        break;
    case Format::I:
    case Format::Csr:
    case Format::CsrImm:
        w = insn.match | rd << 7 | rs1 << 15 | (u & 0xfff) << 20;
        break;
    case Format::S:
        w = insn.match | rs1 << 15 | rs2 << 20 | (u & 0x1f) << 7 | (u >> 5 & 0x7f) << 25;
        break;
    case Format::B:
        w = insn.match | rs1 << 15 | rs2 << 20 | (u >> 11 & 1) << 7 | (u >> 1 & 0xf) << 8 |
            (u >> 5 & 0x3f) << 25 | (u >> 12 & 1) << 31;
        break;
    case Format::U:
        w = insn.match | rd << 7 | (u & 0xfffff000);
        break;
    case Format::J:
        w = insn.match | rd << 7 | (u >> 12 & 0xff) << 12 | (u >> 11 & 1) << 20 |
            (u >> 1 & 0x3ff) << 21 | (u >> 20 & 1) << 31;
        break;
    case Format::Fence:
    case Format::System:
        w = insn.match;
        break;
    }
    if (insn.operands.rounding_mode) w = (w & ~0x7000u) | rm << 12;
    // Fields the mask fixes (funct7 of shifts, rs2 of fcvt/fsqrt ...) always come from match.
    return insn.match | (w & ~insn.mask);
}

struct FakeEnv {
    std::vector<uint8_t> memory = std::vector<uint8_t>(4096);
    uint32_t globals[256] = {};
    int ecalls = 0, ebreaks = 0, illegals = 0, misaligned_jumps = 0;

    template <class T> T load(uint32_t addr) {
        check(addr, sizeof(T));
        T value;
        std::memcpy(&value, &memory[addr], sizeof value);
        return value;
    }
    template <class T> void store(uint32_t addr, T value) {
        check(addr, sizeof(T));
        std::memcpy(&memory[addr], &value, sizeof value);
    }
    uint32_t atomic_inc(uint32_t reg) { return globals[reg]++; }
    // The synchronisation hooks record their calls and complete the instruction, as the
    // machine does when the thread need not wait.
    std::string printed;
    int barriers = 0;
    std::vector<uint32_t> acquired, released;
    void print(uint32_t address, uint32_t length) {
        check(address, length);
        printed.append(reinterpret_cast<const char*>(&memory[address]), length);
    }
    void barrier(Hart& h) {
        ++barriers;
        complete(h);
    }
    void sem_acquire(Hart& h, uint32_t reg) {
        acquired.push_back(reg);
        complete(h);
    }
    void sem_release(Hart& h, uint32_t reg) {
        released.push_back(reg);
        complete(h);
    }
    bool read_csr(uint32_t csr, uint32_t& value) {
        switch (csr) {
        case csr::kMhartid:
            value = 7;
            return true;
        case csr::kCycle:
            value = 1234;
            return true;
        case csr::kNthreads:
            value = 128;
            return true;
        default:
            return false;
        }
    }
    void ecall(Hart&) { ++ecalls; }
    void ebreak(Hart&) { ++ebreaks; }
    void illegal(Hart&, const Decoded&) { ++illegals; }
    void misaligned_jump(Hart&, uint32_t) { ++misaligned_jumps; }

private:
    void check(uint32_t addr, size_t size) const {
        if (addr + size > memory.size())
            throw std::out_of_range("fake memory: address out of range");
    }
};

/// Decodes and executes one word.
inline void run(Hart& h, FakeEnv& env, uint32_t word) {
    execute(decode(word), h, env);
}

inline uint32_t bits(float value) {
    return std::bit_cast<uint32_t>(value);
}

}  // namespace tpsim::isa::test
