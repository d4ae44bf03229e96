// How many host threads tpsim may use (tpsim render --threads): the cycle-level chip's TMs,
// the functional machine's threads, and library code built on oneTBB. Only host scheduling
// follows it; no result depends on it.
#pragma once
#include <cstdint>

namespace tpsim::core {

/// The host threads set for this process; 1 until set. The simulation is not faster on more
/// threads yet (docs/performance.md, "Host threads": 0.81x on 2 cores for the default 4-TM
/// chip), so it stays on one unless asked; oneTBB code (the BVH build) uses every core.
uint32_t host_threads();
/// Sets them (at least 1); also limits oneTBB's parallelism for the whole process.
void set_host_threads(uint32_t threads);

}  // namespace tpsim::core
