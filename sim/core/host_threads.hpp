// How many host threads tpsim may use (tpsim render --threads): the cycle-level chip's TMs,
// the functional machine's threads, and library code built on oneTBB. Only host scheduling
// follows it; no result depends on it.
#pragma once
#include <cstdint>

namespace tpsim::core {

/// The host threads set for this process; the host's cores until set.
uint32_t host_threads();
/// Sets them (at least 1); also limits oneTBB's parallelism for the whole process.
void set_host_threads(uint32_t threads);

}  // namespace tpsim::core
