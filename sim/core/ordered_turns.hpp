// Turns in a fixed order for work spread over host threads (lanes): each lane walks through
// increasing positions of one global order (e.g. cycle * TMs + TM) and publishes where it is;
// an action that other lanes can observe (an atomic increment, a shared load, a print) waits
// until every other lane has moved past its position. Such actions then happen in the order of
// their positions, whatever the host does, and each sees exactly the effects of the earlier
// ones (the release/acquire on the positions orders the memory). Lanes never wait in a cycle:
// the lane with the lowest position waits for no one.
#pragma once
#include <atomic>
#include <cstdint>
#include <memory>

#include "sim/core/host_spacing.hpp"
#include "sim/core/spin_wait.hpp"

namespace tpsim::core {

/// The cycle-level chip's order, which its turns and the functional machine's held stores
/// share: TM `tm` of `tms` in cycle `cycle`.
constexpr uint64_t chip_position(uint64_t cycle, uint32_t tm, uint64_t tms) {
    return cycle * tms + tm;
}

class OrderedTurns {
public:
    /// Past every position: a lane that has finished (or stopped) waits for nothing more.
    static constexpr uint64_t kDone = UINT64_MAX;

    /// Thrown by a lane whose next action comes after another lane's failure: it stops there.
    struct Abandoned {};

    explicit OrderedTurns(uint32_t lanes)
        : lanes_(lanes), spins_(spins_for(lanes)), at_(new Position[lanes]) {}

    uint32_t lanes() const { return lanes_; }
    /// Lane `lane` has done everything before `position` (non-decreasing per lane).
    void reach(uint32_t lane, uint64_t position) {
        at_[lane].value.store(position, std::memory_order_release);
    }
    /// The position lane `lane` reached last (read by that lane).
    uint64_t position(uint32_t lane) const {
        return at_[lane].value.load(std::memory_order_relaxed);
    }
    /// Whether every other lane has reached a position after `position` (wait_turn would not
    /// wait).
    bool passed(uint32_t lane, uint64_t position) const {
        for (uint32_t other = 0; other < lanes_; ++other)
            if (other != lane && at_[other].value.load(std::memory_order_acquire) <= position)
                return false;
        return true;
    }
    /// Returns once every other lane has reached a position after `position`. (The other lanes
    /// are usually a few steps behind: spin_until.)
    void wait_turn(uint32_t lane, uint64_t position) const {
        spin_until([&] { return passed(lane, position); }, spins_);
    }

private:
    struct alignas(kHostSpacing) Position {  // lanes write theirs at every step
        std::atomic<uint64_t> value{0};
    };
    uint32_t lanes_, spins_;
    std::unique_ptr<Position[]> at_;
};

}  // namespace tpsim::core
