#include <functional>

#include <catch2/catch.hpp>

#include "kernel/memory_map.hpp"
#include "sim/core/error.hpp"
#include "sim/core/fault.hpp"
#include "sim/core/memory.hpp"

using namespace tpsim;
using namespace tpsim::core;
using namespace trax::map;

namespace {

/// A hand-made program: 16 bytes of code, 8 bytes of rodata, and 8 bytes of data + 8 of bss.
Program tiny_program() {
    Program p;
    p.name = "tiny";
    p.entry = kCodeBase;
    p.segments.push_back({kCodeBase, 16, std::vector<uint8_t>(16, 0x13), true, false, true});
    p.segments.push_back({kCodeBase + 0x100, 8, {1, 2, 3, 4, 5, 6, 7, 8}, true, false, false});
    p.segments.push_back({kCodeBase + 0x1000, 16, {9, 9, 9, 9, 9, 9, 9, 9}, true, true, false});
    return p;
}

FaultKind fault_of(const std::function<void()>& access) {
    try {
        access();
    } catch (const GuestFault& f) {
        return f.kind;
    }
    FAIL("the access did not fault");
    return FaultKind::Unmapped;
}

}  // namespace

TEST_CASE("memory maps program segments with their permissions", "[sim][memory]") {
    Memory m(tiny_program(), {.global_bytes = 64, .local_store_bytes = 256, .threads = 2});
    uint8_t* local = m.local_store(0).data();
    CHECK(m.load<uint32_t>(kCodeBase + 0x100, local) == 0x04030201u);  // little-endian
    CHECK(m.load<int8_t>(kCodeBase + 0x107, local) == 8);
    CHECK(m.load<uint32_t>(kCodeBase + 0x1000, local) == 0x09090909u);
    CHECK(m.load<uint32_t>(kCodeBase + 0x100c, local) == 0u);  // bss part is zero
    m.store<uint32_t>(kCodeBase + 0x100c, 0xdeadbeef, local);
    CHECK(m.load<uint16_t>(kCodeBase + 0x100e, local) == 0xdeadu);
    CHECK(fault_of([&] { m.store<uint32_t>(kCodeBase + 0x100, 1, local); }) ==
          FaultKind::WriteToReadOnly);
    CHECK(fault_of([&] { m.store<uint8_t>(kCodeBase, 1, local); }) == FaultKind::WriteToReadOnly);
    CHECK(m.code_word(kCodeBase + 4) == 0x13131313u);
}

TEST_CASE("global memory is shared and visible to the host", "[sim][memory]") {
    Memory m(tiny_program(), {.global_bytes = 64, .local_store_bytes = 256, .threads = 2});
    m.store<uint32_t>(kGlobalBase + 60, 77, m.local_store(0).data());
    CHECK(m.load<uint32_t>(kGlobalBase + 60, m.local_store(1).data()) == 77);
    CHECK(m.global()[60] == 77);
    CHECK(fault_of([&] { m.load<uint32_t>(kGlobalBase + 64, m.local_store(0).data()); }) ==
          FaultKind::Unmapped);
}

TEST_CASE("the read-only start of global memory takes loads and refuses stores", "[sim][memory]") {
    Memory m(
        tiny_program(),
        {.global_bytes = 64, .read_only_global_bytes = 16, .local_store_bytes = 256, .threads = 1});
    uint8_t* local = m.local_store(0).data();
    m.global()[12] = 5;  // the host writes the scene before the run
    CHECK(m.load<uint8_t>(kGlobalBase + 12, local) == 5);
    CHECK(m.in_read_only_global(kGlobalBase + 15));
    CHECK_FALSE(m.in_read_only_global(kGlobalBase + 16));
    CHECK(fault_of([&] { m.store<uint32_t>(kGlobalBase + 12, 1, local); }) ==
          FaultKind::WriteToReadOnly);
    CHECK(fault_of([&] { m.store<uint8_t>(kGlobalBase, 1, local); }) == FaultKind::WriteToReadOnly);
    m.store<uint32_t>(kGlobalBase + 16, 7, local);
    CHECK(m.load<uint32_t>(kGlobalBase + 16, local) == 7);
    CHECK_THROWS_AS(Memory(tiny_program(), {.global_bytes = 64, .read_only_global_bytes = 68}),
                    tpsim::Error);
}

TEST_CASE("local stores are private per thread and overflow is detected", "[sim][memory]") {
    Memory m(tiny_program(), {.global_bytes = 0, .local_store_bytes = 256, .threads = 3});
    CHECK(m.local_base() == kLocalTop - 256);
    for (uint32_t t = 0; t < 3; ++t)
        m.store<uint32_t>(kLocalTop - 4, 100 + t, m.local_store(t).data());
    for (uint32_t t = 0; t < 3; ++t)
        CHECK(m.load<uint32_t>(kLocalTop - 4, m.local_store(t).data()) == 100 + t);
    CHECK(m.local_store(2)[252] == 102);
    uint8_t* local = m.local_store(0).data();
    CHECK(m.load<uint32_t>(kLocalTop - 256, local) == 0);
    CHECK(fault_of([&] { m.store<uint32_t>(kLocalTop - 260, 1, local); }) ==
          FaultKind::StackOverflow);
    CHECK(fault_of([&] { m.load<uint8_t>(kLocalTop - kStackGuard, local); }) ==
          FaultKind::StackOverflow);
    CHECK(fault_of([&] { m.load<uint8_t>(kLocalTop - kStackGuard - 1, local); }) ==
          FaultKind::Unmapped);
    CHECK(fault_of([&] { m.load<uint32_t>(kLocalTop, local); }) == FaultKind::Unmapped);
}

TEST_CASE("memory faults: null, unmapped, misaligned", "[sim][memory]") {
    Memory m(tiny_program(), {.global_bytes = 64, .local_store_bytes = 256, .threads = 1});
    uint8_t* local = m.local_store(0).data();
    CHECK(fault_of([&] { m.load<uint32_t>(0, local); }) == FaultKind::NullAccess);
    CHECK(fault_of([&] { m.load<uint32_t>(kCodeBase - 4, local); }) == FaultKind::NullAccess);
    CHECK(fault_of([&] { m.load<uint32_t>(kCodeBase + 0x200, local); }) == FaultKind::Unmapped);
    CHECK(fault_of([&] { m.load<uint32_t>(0x4000'0000, local); }) == FaultKind::Unmapped);
    CHECK(fault_of([&] { m.load<uint32_t>(kCodeBase + 0x1002, local); }) == FaultKind::Misaligned);
    CHECK(fault_of([&] { m.load<uint16_t>(kGlobalBase + 1, local); }) == FaultKind::Misaligned);
    CHECK(fault_of([&] { m.store<uint32_t>(kLocalTop - 6, 0, local); }) == FaultKind::Misaligned);
    CHECK(m.load<uint8_t>(kGlobalBase + 1, local) == 0);  // bytes have no alignment
    try {
        m.store<uint32_t>(kLocalTop - 260, 1, local);
        FAIL("no fault");
    } catch (const GuestFault& f) {
        CHECK_THAT(f.detail, Catch::Contains("writes 4 bytes at 0x7ffffefc") &&
                                 Catch::Contains("256-byte local store [0x7fffff00, 0x80000000)"));
        CHECK_THAT(f.hint, Catch::Contains("--local-store"));
    }
}

TEST_CASE("memory configuration is validated", "[sim][memory]") {
    const Program p = tiny_program();
    CHECK_THROWS_WITH(Memory(p, {.global_bytes = 0, .local_store_bytes = 100, .threads = 1}),
                      Catch::Contains("multiple of 16"));
    CHECK_THROWS_AS(Memory(p, {.global_bytes = 0, .local_store_bytes = 4100, .threads = 1}), Error);
    CHECK_THROWS_AS(Memory(p, {.global_bytes = 0, .local_store_bytes = 2u << 20, .threads = 1}),
                    Error);
    CHECK_THROWS_AS(
        Memory(p, {.global_bytes = 0x7000'0000, .local_store_bytes = 256, .threads = 1}), Error);
    CHECK_NOTHROW(Memory(p, {.global_bytes = 0, .local_store_bytes = 1u << 20, .threads = 4}));
}
