// Requests and replies exchanged between memory components. Everything that crosses a
// component boundary is stamped with the cycle it becomes visible, so components can be
// simulated independently and merged in a fixed order (cycle, then source, then sequence).
#pragma once
#include <cstdint>

namespace tpsim::timing {

/// A load or store presented to a cache (or DRAM) by one requester.
struct MemRequest {
    uint32_t addr = 0;     ///< byte address
    uint32_t source = 0;   ///< requester id at this level (TP within a TM, TM within an L2 group)
    uint32_t tag = 0;      ///< opaque to the component, returned in the reply (e.g. a register)
    bool write = false;
};

/// The reply to a read: data usable by the requester from cycle `ready`.
struct MemReply {
    uint64_t ready = 0;
    MemRequest request;
};

/// A request sent to the next level, visible there from cycle `cycle`.
struct OutboundRequest {
    uint64_t cycle = 0;
    MemRequest request;  ///< addr is the line's first byte for reads
};

}  // namespace tpsim::timing
