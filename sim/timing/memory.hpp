// Requests and replies exchanged between memory components. Everything that crosses a
// component boundary is stamped with the cycle it becomes visible, so components can be
// simulated independently and merged in a fixed order (cycle, then source, then sequence).
#pragma once
#include <cstdint>

namespace tpsim::timing {

/// A load or store presented to a cache (or DRAM) by one requester. A line request sent on
/// after a miss keeps the region, pc and work item of the access that missed, so every level
/// can charge its costs to them (attribution.hpp).
struct MemRequest {
    uint32_t addr = 0;    ///< byte address
    uint32_t source = 0;  ///< requester id at this level (TP within a TM, TM within an L2 group)
    uint32_t tag = 0;     ///< opaque to the component, returned in the reply (e.g. a register)
    bool write = false;
    uint8_t region = 0;  ///< index in the chip's region table, tagged when the access issued
    uint16_t bytes = 0;  ///< bytes asked for: the access size; a combined line write's payload
    uint32_t pc = 0;     ///< the instruction that made the access
    uint32_t item = 0;   ///< the work item its thread held (Chip's work-item accounting)
};
static_assert(sizeof(MemRequest) == 24, "queued by the thousand: keep it small");

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
