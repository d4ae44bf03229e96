// How far apart the simulator keeps what different host threads write.
#pragma once
#include <cstddef>

namespace tpsim::core {

/// What one host thread writes while another reads or writes what lies beside it (a TM's
/// state, a lane's position) starts on its own pair of cache lines: the host's adjacent-line
/// prefetcher fetches a line together with its neighbour, so data one line apart still moves
/// between the cores (bunny 256x256, 4 TMs on 2 host threads: 4.30-4.35 s at 128 bytes against
/// 4.5 s at 64, docs/performance.md).
inline constexpr std::size_t kHostSpacing = 128;

/// What one TM's host thread writes every cycle in an array indexed by TM or by thread (its
/// clock, its counters, its threads' run-ahead records and cursors) lies at least this far from
/// what the next TM's writes: the host's stream prefetchers, which follow a host thread up
/// through its TMs' entries, fetch a few lines past the last one, and would take the next
/// TM's lines from the core that writes them at every cycle (bunny 256x256, 4 TMs on 2 host
/// threads: 13 % less wall time at the best of four runs, docs/performance.md).
inline constexpr std::size_t kTmSpacing = 512;

}  // namespace tpsim::core
