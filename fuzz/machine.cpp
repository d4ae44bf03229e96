// Fuzzes the functional machine (sim/core/machine.cpp, thread_env.hpp, memory.cpp): the input is
// the code segment of a program run by two threads, with a data segment and global memory to
// load from and store to, for at most 10,000 instructions per thread so every input ends.
#include <cstdint>
#include <utility>

#include "kernel/memory_map.hpp"
#include "sim/core/error.hpp"
#include "sim/core/machine.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace tpsim::core;
    Program program;
    program.name = "fuzz";
    program.entry = trax::map::kCodeBase;
    Segment code;
    code.vaddr = trax::map::kCodeBase;
    code.memsz = uint32_t(size);
    code.bytes.assign(data, data + size);
    code.readable = code.executable = true;
    Segment bss;
    bss.vaddr = trax::map::kCodeBase + 0x10'0000;  // past any input libFuzzer makes
    bss.memsz = 4096;
    bss.readable = bss.writable = true;
    program.segments = {std::move(code), std::move(bss)};
    MachineConfig config;
    config.threads = 2;
    config.global_bytes = 4096;
    config.read_only_global_bytes = 1024;
    config.local_store_bytes = 256;
    config.max_instructions = 10'000;
    config.quantum = 64;
    try {
        Machine machine(std::move(program), config);
        machine.run();
    } catch (const tpsim::Error&) {
        // A guest fault (core::Fault) or a refused program: the expected outcomes.
    }
    return 0;
}
