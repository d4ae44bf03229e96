// Cycles as 32-bit offsets from an epoch that follows the clock: the TPs' register scoreboards
// hold them so that the state the cycle loop reads of every awake TP in every cycle spans few
// host cache lines (on chips of a thousand TPs that state outgrows the host's caches).
#pragma once
#include <cstdint>
#include <span>

namespace tpsim::timing {

class EpochCycles {
public:
    /// The offset of kNever (never, or until a reply).
    static constexpr uint32_t kNever = UINT32_MAX;
    /// How far the clock may run ahead of the epoch: far above the clock plus any latency
    /// (config latencies are at most 10^5 cycles).
    static constexpr uint64_t kSpan = uint64_t{1} << 31;

    /// `cycle` (at or after the epoch, or UINT64_MAX for never) as an offset, and back.
    uint32_t offset(uint64_t cycle) const {
        return cycle == UINT64_MAX ? kNever : uint32_t(cycle - epoch_);
    }
    uint64_t cycle(uint32_t offset) const {
        return offset == kNever ? UINT64_MAX : epoch_ + offset;
    }

    /// Whether the epoch must move before the clock reaches `now`.
    bool due(uint64_t now) const { return now - epoch_ >= kSpan; }
    /// Moves the epoch to `now`, re-expressing `offsets` (every array of offsets taken from
    /// this epoch, through `each`): a cycle before `now` becomes `now` (what it is before
    /// `now` no longer matters), a later one and kNever keep their meaning.
    template <class Each> void move_to(uint64_t now, Each&& each) {
        const auto moved = uint32_t(now - epoch_);
        each([moved](std::span<uint32_t> offsets) {
            for (uint32_t& o : offsets)
                if (o != kNever) o = o > moved ? o - moved : 0;
        });
        epoch_ = now;
    }

private:
    uint64_t epoch_ = 0;
};

}  // namespace tpsim::timing
