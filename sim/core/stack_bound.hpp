// The most stack a kernel can ever use, read from its ELF before it runs, so that a kernel whose
// stack does not fit in a thread's local store is refused the same way by every engine (the
// native twin's host frames say nothing about the RV32 frames). docs/debugging.md.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "sim/core/elf_loader.hpp"

namespace tpsim::core {

struct StackBound {
    /// False when no bound exists or cannot be read: recursion, an indirect call, or an ELF
    /// without frame sizes; `reason` then says which and where.
    bool bounded = false;
    uint32_t bytes = 0;  ///< the deepest chain's frames, summed (when bounded)
    /// The deepest chain from the entry point, outermost first: "trax_main (16 B)" ...
    std::vector<std::string> chain;
    std::string reason;
};

/// Walks the direct calls (jal, auipc + jalr) from the entry point and sums each function's
/// frame (Program::frame_sizes; functions without one, written in assembly, count 0) along the
/// deepest chain. A tail call reuses its caller's stack. Exact for kernels without recursion or
/// calls through pointers: every frame of clang's is fixed in size (the kernel build forbids
/// variable-length arrays), so the deepest chain is the worst case whether or not a run takes it.
StackBound stack_bound(const Program& program);

}  // namespace tpsim::core
