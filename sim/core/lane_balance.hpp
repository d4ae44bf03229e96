// How many TMs each host thread (lane) should simulate, from what the lanes' work cost them:
// hosts whose cores run at different speeds (a hybrid CPU's performance and efficiency cores, a
// virtual machine's core whose physical sibling is busy with another guest) and the serial work
// one lane carries besides its TMs (the chip's shared parts) make equal blocks wait for the
// slowest lane.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

namespace tpsim::core {

/// One lane's host time over a measuring interval.
struct LaneLoad {
    double tm_seconds = 0;     ///< ticking its TMs
    uint32_t running_tms = 0;  ///< of which still had work (an idle TM costs nothing)
    double other_seconds = 0;  ///< other work that stays with the lane (the shared parts)
};

/// Blocks of consecutive TM ids, lane l ticking [bounds[l], bounds[l + 1]), that make the lanes'
/// busy time about equal, each lane's time per running TM taken as measured (a lane without a
/// running TM as the lanes' mean). `running[t]`: TM t still has work. Returns `bounds` itself
/// unless the new blocks are predicted to shorten the busiest lane's time by more than
/// `least_gain` (a fraction): moving a TM moves its state between the host's cores.
std::vector<uint32_t> balance_lanes(std::span<const uint32_t> bounds,
                                    std::span<const LaneLoad> loads,
                                    const std::vector<bool>& running, double least_gain);

}  // namespace tpsim::core
