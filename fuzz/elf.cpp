// Fuzzes the kernel ELF loader (sim/core/elf_loader.cpp, libelf and libdw behind it) and what a
// loaded program goes through next: the pc lookups of fault messages and a short run on the
// functional machine, so every segment layout the loader accepts is also one the machine can
// set up and fetch from.
#include <cstdint>
#include <span>

#include "sim/core/elf_loader.hpp"
#include "sim/core/error.hpp"
#include "sim/core/machine.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    try {
        tpsim::core::Program program = tpsim::core::load_elf({data, size}, "fuzz.elf");
        program.describe_pc(program.entry);
        program.source_at(program.entry);
        program.inlined_call_sites(program.entry);
        program.source_function_at(program.entry);
        tpsim::core::MachineConfig config;
        config.threads = 2;
        config.global_bytes = 4096;
        config.max_instructions = 10'000;  // every input terminates
        config.quantum = 64;
        tpsim::core::Machine machine(std::move(program), config);
        machine.run();
    } catch (const tpsim::Error&) {
        // A clean rejection or a guest fault (core::Fault): the expected outcomes.
    }
    return 0;
}
