// Stores to shared memory held back from the moment they execute until they are written in
// their place in a fixed order (docs/hardware-model.md, "Parallel simulation", turns). The
// timing model runs a thread's stores ahead with its private steps, and hands each one over
// here when the chip fetches it, with that fetch's position (cycle, TM); the held stores are
// written in position order before anything reads shared memory (a load in its turn, the
// host after a run). Every read then sees exactly the stores before it in the order, on any
// number of host threads, while a store itself needs no turn.
#pragma once
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <vector>

#include "sim/core/host_spacing.hpp"

namespace tpsim::core {

class Memory;

/// One store to shared memory and its place in the order.
struct HeldStore {
    uint64_t position = 0;  ///< positions of different producers never coincide
    uint32_t address = 0;
    uint32_t value = 0;  ///< its low `bytes` bytes are stored
    uint8_t bytes = 0;   ///< 1, 2 or 4
};

/// The stores of several producers (the chip's TMs), each holding its own in order.
class HeldStores {
public:
    explicit HeldStores(uint32_t producers);

    /// Producer `producer` holds `store`. A producer's positions never decrease (equal
    /// positions keep the order they were held in); throws std::logic_error otherwise. Only
    /// one host thread at a time holds for a given producer; others may write meanwhile.
    void hold(uint32_t producer, const HeldStore& store);
    /// Writes into `memory`, in position order, every held store at or before `position`, and
    /// forgets them. The caller guarantees that every store at or before `position` has been
    /// held. Safe from any host thread; concurrent calls take turns.
    void write_through(uint64_t position, Memory& memory);
    /// Stores held and not written yet.
    size_t size() const;

private:
    // Each on cache lines of its own: a producer's host thread appends to its queue while a
    // writer on another host thread takes the front.
    struct alignas(kHostSpacing) Queue {
        mutable std::mutex lock;
        std::deque<HeldStore> stores;  // by position
    };
    std::unique_ptr<Queue[]> queues_;
    uint32_t producers_;
    std::mutex writing_;
    std::vector<HeldStore> batch_;  // under writing_: the stores one call writes
};

}  // namespace tpsim::core
