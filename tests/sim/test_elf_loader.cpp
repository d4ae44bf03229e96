#include <cstring>
#include <random>

#include <catch2/catch.hpp>
#include <elf.h>

#include "sim/core/elf_loader.hpp"
#include "sim/core/error.hpp"
#include "sim/core/machine.hpp"
#include "tests/sim/test_support.hpp"

using namespace tpsim;
using namespace tpsim::core;
using tpsim::test::guest_program;
using tpsim::test::read_bytes;

namespace {

/// A good ELF with its headers at hand, for patching into bad ones.
struct Patchable {
    std::vector<uint8_t> bytes = read_bytes(guest_program("loadstore"));

    Elf32_Ehdr header() const {
        Elf32_Ehdr h;
        std::memcpy(&h, bytes.data(), sizeof h);
        return h;
    }
    void set_header(const Elf32_Ehdr& h) { std::memcpy(bytes.data(), &h, sizeof h); }
    Elf32_Phdr phdr(size_t i) const {
        Elf32_Phdr p;
        std::memcpy(&p, bytes.data() + header().e_phoff + i * sizeof p, sizeof p);
        return p;
    }
    void set_phdr(size_t i, const Elf32_Phdr& p) {
        std::memcpy(bytes.data() + header().e_phoff + i * sizeof p, &p, sizeof p);
    }
    /// Index of the n-th PT_LOAD program header.
    size_t load(size_t n) const {
        for (size_t i = 0; i < header().e_phnum; ++i)
            if (phdr(i).p_type == PT_LOAD && n-- == 0) return i;
        FAIL("the test program has too few PT_LOAD segments");
        return 0;
    }
    Program parse() const { return load_elf(bytes, "patched.elf"); }
};

}  // namespace

TEST_CASE("the loader reads segments, entry and symbols of a linked program", "[sim][elf]") {
    const Program p = load_elf(guest_program("loadstore"));
    // test.ld puts .text at 0x10000 and .data/.bss on the next page after rodata.
    REQUIRE(p.segments.size() >= 2);
    const Segment& text = p.segments.front();
    CHECK(text.vaddr == 0x10000);
    CHECK(text.executable);
    CHECK_FALSE(text.writable);
    const Segment& data = p.segments.back();
    CHECK(data.writable);
    CHECK_FALSE(data.executable);
    CHECK(data.memsz == 4 + 8);     // .word + .space 8 (bss)
    CHECK(data.bytes.size() == 4);  // only .data is in the file
    CHECK(p.entry == text.vaddr);   // _start is the first thing in .text
    REQUIRE(p.function_at(p.entry));
    CHECK(p.function_at(p.entry)->name == "_start");
    CHECK(p.describe_pc(p.entry + 8) == "_start+0x8");
    CHECK(p.function_at(0x4000) == nullptr);
}

TEST_CASE("the loader maps pc to file:line from DWARF", "[sim][elf]") {
    const Program p = load_elf(guest_program("calls"));
    const Symbol* fib = nullptr;
    for (const Symbol& s : p.functions)
        if (s.name == "fib") fib = &s;
    REQUIRE(fib);
    CHECK(fib->size > 0);
    CHECK(p.function_at(fib->address + fib->size - 4) == fib);
    const auto where = p.source_at(fib->address);
    REQUIRE(where);
    CHECK(where->file == "calls.c");
    CHECK(where->line == tpsim::test::line_of("calls.c", "int fib(int n)"));
}

TEST_CASE("the loader rejects files that are not RV32 executables", "[sim][elf]") {
    SECTION("garbage") {
        const std::vector<uint8_t> junk = {'h', 'e', 'l', 'l', 'o', ' ', 'w', 'o', 'r', 'l', 'd'};
        REQUIRE_THROWS_WITH(load_elf(junk, "junk"), Catch::Contains("not an ELF file"));
    }
    SECTION("empty") {
        REQUIRE_THROWS_WITH(load_elf(std::vector<uint8_t>{}, "empty"),
                            Catch::Contains("not an ELF file"));
    }
    SECTION("a missing file") {
        REQUIRE_THROWS_WITH(load_elf("/nonexistent/x.elf"), Catch::Contains("cannot open"));
    }
    SECTION("an x86-64 executable built by the host compiler (this test)") {
        REQUIRE_THROWS_WITH(load_elf("/proc/self/exe"),
                            Catch::Contains("is not RISC-V") && Catch::Contains("x86-64"));
    }
    SECTION("a 64-bit RISC-V executable") {
        REQUIRE_THROWS_WITH(load_elf(guest_program("rv64")), Catch::Contains("64-bit"));
    }
}

TEST_CASE("the loader rejects truncated files at every stage", "[sim][elf]") {
    const std::vector<uint8_t> good = read_bytes(guest_program("loadstore"));
    Elf32_Ehdr h;
    std::memcpy(&h, good.data(), sizeof h);
    Elf32_Phdr first;
    std::memcpy(&first, good.data() + h.e_phoff, sizeof first);
    const size_t cuts[] = {
        2, EI_NIDENT - 1, 30, sizeof(Elf32_Ehdr) + 10, size_t(first.p_offset) + 8, good.size() - 1};
    for (size_t cut : cuts) {
        INFO("truncated to " << cut << " bytes");
        const std::vector<uint8_t> part(good.begin(), good.begin() + cut);
        REQUIRE_THROWS_AS(load_elf(part, "cut.elf"), Error);
    }
    const std::vector<uint8_t> header_only(good.begin(), good.begin() + 30);
    REQUIRE_THROWS_WITH(load_elf(header_only, "cut.elf"), Catch::Contains("truncated ELF header"));
    const std::vector<uint8_t> no_phdrs(good.begin(), good.begin() + sizeof(Elf32_Ehdr) + 10);
    REQUIRE_THROWS_WITH(load_elf(no_phdrs, "cut.elf"), Catch::Contains("program headers end"));
}

TEST_CASE("the loader rejects patched headers with a message naming the problem", "[sim][elf]") {
    Patchable elf;
    REQUIRE_NOTHROW(elf.parse());
    Elf32_Ehdr h = elf.header();
    SECTION("64-bit class") {
        elf.bytes[EI_CLASS] = ELFCLASS64;
        REQUIRE_THROWS_WITH(elf.parse(), Catch::Contains("64-bit"));
    }
    SECTION("big-endian") {
        elf.bytes[EI_DATA] = ELFDATA2MSB;
        REQUIRE_THROWS_WITH(elf.parse(), Catch::Contains("big-endian"));
    }
    SECTION("wrong machine") {
        h.e_machine = EM_ARM;
        elf.set_header(h);
        REQUIRE_THROWS_WITH(elf.parse(), Catch::Contains("is not RISC-V"));
    }
    SECTION("relocatable object instead of executable") {
        h.e_type = ET_REL;
        elf.set_header(h);
        REQUIRE_THROWS_WITH(elf.parse(), Catch::Contains("not an executable"));
    }
    SECTION("compressed instructions") {
        h.e_flags |= EF_RISCV_RVC;
        elf.set_header(h);
        REQUIRE_THROWS_WITH(elf.parse(), Catch::Contains("compressed"));
    }
    SECTION("entry point outside the code") {
        h.e_entry = 0;
        elf.set_header(h);
        REQUIRE_THROWS_WITH(elf.parse(), Catch::Contains("entry point"));
    }
    SECTION("segment outside the file") {
        Elf32_Phdr p = elf.phdr(elf.load(0));
        p.p_offset = uint32_t(elf.bytes.size()) - 2;
        elf.set_phdr(elf.load(0), p);
        REQUIRE_THROWS_WITH(elf.parse(), Catch::Contains("outside the file"));
    }
    SECTION("overlapping segments") {
        Elf32_Phdr second = elf.phdr(elf.load(1));
        second.p_vaddr = elf.phdr(elf.load(0)).p_vaddr + 4;
        elf.set_phdr(elf.load(1), second);
        REQUIRE_THROWS_WITH(elf.parse(), Catch::Contains("overlap"));
    }
    SECTION("segment below the code base") {
        Elf32_Phdr p = elf.phdr(elf.load(0));
        p.p_vaddr = 0x1000;
        elf.set_phdr(elf.load(0), p);
        REQUIRE_THROWS_WITH(elf.parse(), Catch::Contains("below the code base"));
    }
    SECTION("segment reaching into global memory") {
        const size_t last = elf.load(1);
        Elf32_Phdr p = elf.phdr(last);
        p.p_vaddr = 0x10000000 - 4;
        elf.set_phdr(last, p);
        REQUIRE_THROWS_WITH(elf.parse(), Catch::Contains("global memory"));
    }
    SECTION("misaligned executable segment") {
        Elf32_Phdr p = elf.phdr(elf.load(0));
        REQUIRE((p.p_flags & PF_X));
        p.p_vaddr += 2;
        elf.set_phdr(elf.load(0), p);
        h.e_entry += 2;
        elf.set_header(h);
        REQUIRE_THROWS_WITH(elf.parse(), Catch::Contains("not 4-byte aligned"));
    }
    SECTION("writable and executable segment") {
        Elf32_Phdr p = elf.phdr(elf.load(0));
        p.p_flags |= PF_W;
        elf.set_phdr(elf.load(0), p);
        REQUIRE_THROWS_WITH(elf.parse(), Catch::Contains("writable and executable"));
    }
    SECTION("file size larger than memory size") {
        Elf32_Phdr p = elf.phdr(elf.load(0));
        p.p_memsz = p.p_filesz - 1;
        elf.set_phdr(elf.load(0), p);
        REQUIRE_THROWS_WITH(elf.parse(), Catch::Contains("file size"));
    }
}

TEST_CASE("randomly corrupted programs load and run or fail with an Error, never crash",
          "[sim][elf]") {
    const std::vector<uint8_t> good = read_bytes(guest_program("calls"));
    std::mt19937 random(6958);  // fixed seed: the same corruptions every run
    std::uniform_int_distribution<size_t> header_byte(0, 255), any_byte(0, good.size() - 1);
    std::uniform_int_distribution<int> value(0, 255), count(1, 4);
    size_t loaded = 0, rejected = 0;
    for (int trial = 0; trial < 400; ++trial) {
        std::vector<uint8_t> bad = good;
        // Half the trials hit the ELF and program headers, half anywhere (sections, DWARF).
        for (int n = count(random); n > 0; --n)
            bad[trial % 2 ? header_byte(random) : any_byte(random)] = uint8_t(value(random));
        try {
            Machine machine(load_elf(bad, "corrupt.elf"), {.max_instructions = 20000});
            ++loaded;
            machine.run();
        } catch (const Error&) {
            ++rejected;
        }
    }
    CHECK(loaded > 0);
    CHECK(rejected > 0);
}
