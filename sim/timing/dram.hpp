// DRAM: channels x banks, each bank with one row buffer (open-page policy), commands ACT, PRE,
// RD, WR checked against a table of timing constraints in the spirit of ramulator2 (a rule
// says: after command A, command B on the same bank or channel must wait N cycles), and
// FR-FCFS scheduling per channel (row hits first, then oldest first): deterministic.
//
// Address mapping, from the most significant bits: row : bank : channel : column, with
// column = byte offset within one row_bytes chunk. Consecutive lines stay in one row of one
// bank (row hits); the next row_bytes chunk moves to the next channel.
// One request moves one cache line; its data occupies the channel's bus for tBURST cycles.
// Not modelled: refresh, ranks, bank groups, tFAW, power-down, command-bus slots beyond one
// command per channel per cycle.
#pragma once
#include "sim/stats/registry.hpp"
#include "sim/timing/config.hpp"
#include "sim/timing/memory.hpp"

#include <array>
#include <cstdint>
#include <functional>
#include <queue>
#include <string_view>
#include <vector>

namespace tpsim::timing {

enum class DramCommand : uint8_t { Activate, Precharge, Read, Write, Count };

/// One timing rule: `next` may issue no earlier than `delay` cycles after `prev`, on the same
/// bank (per_bank) or anywhere in the same channel.
struct DramConstraint {
    DramCommand prev;
    DramCommand next;
    bool per_bank;
    uint32_t delay;
};

/// The rule table derived from a DramConfig (exposed for documentation and tests).
std::vector<DramConstraint> dram_constraints(const DramConfig& config);

struct DramLocation {
    uint32_t channel, bank, row, column;
};

class Dram {
public:
    struct Counters {
        uint64_t reads = 0;
        uint64_t writes = 0;
        uint64_t bytes_read = 0;
        uint64_t bytes_written = 0;
        uint64_t store_payload_bytes = 0;  ///< bytes the stores behind the line writes wrote
        uint64_t row_hits = 0;             ///< served from an already open row
        uint64_t row_misses = 0;           ///< needed an activate of a closed bank
        uint64_t row_conflicts = 0;  ///< needed a precharge of another open row, then activate
        uint64_t activates = 0;
        uint64_t precharges = 0;
        uint64_t bus_busy_cycles = 0;  ///< data-bus cycles, summed over channels
        uint64_t queue_full = 0;       ///< requests refused (channel queue full)
    };

    Dram(const DramConfig& config, uint32_t line_bytes);

    DramLocation locate(uint32_t addr) const;
    /// Whether the channel of `addr` has room for one more request.
    bool can_accept(uint32_t addr) const;
    /// Queues a request arriving in cycle `now`; returns false (and counts it) if the channel
    /// queue is full, in which case the caller retries later.
    bool enqueue(uint64_t now, const MemRequest& request);
    /// Issues at most one command per channel in cycle `now`. Call once per cycle, in order.
    void tick(uint64_t now);
    /// Pops the next read reply whose data has fully arrived by `now`, in (ready, issue) order.
    bool pop_reply(uint64_t now, MemReply& reply);
    bool idle() const;
    /// Functional warming (Chip::warm) of an idle DRAM: the access leaves its row open.
    void warm(uint32_t addr) {
        const DramLocation where = locate(addr);
        channels_[where.channel].banks[where.bank].open_row = where.row;
    }
    /// Every request served (read or write) since the owner last cleared it, in issue order:
    /// the chip charges their bytes to regions, instructions and work items.
    std::vector<MemRequest>& served() { return served_; }

    const Counters& counters() const { return counters_; }
    void register_stats(stats::Registry& registry, std::string_view prefix) const;

private:
    static constexpr size_t kCommands = static_cast<size_t>(DramCommand::Count);
    static constexpr uint32_t kClosed = UINT32_MAX;
    struct Pending {
        MemRequest request;
        DramLocation where;
        uint64_t arrival;
        bool activated = false;   // an ACT was issued on this request's behalf
        bool precharged = false;  // a PRE was issued on this request's behalf
    };
    struct Bank {
        uint32_t open_row = kClosed;
        uint32_t queued_hits = 0;  // queued requests for open_row (kept current, not rescanned)
        std::array<uint64_t, kCommands> earliest{};
    };
    struct Channel {
        std::vector<Pending> queue;  // arrival order
        std::vector<Bank> banks;
        std::array<uint64_t, kCommands> earliest{};
    };
    struct Reply {
        uint64_t ready;
        uint64_t sequence;  // issue order breaks ties deterministically
        MemRequest request;
        bool operator>(const Reply& o) const {
            return ready != o.ready ? ready > o.ready : sequence > o.sequence;
        }
    };

    bool ready(const Channel& ch, const Bank& bank, DramCommand cmd, uint64_t now) const;
    void issue(Channel& ch, Bank& bank, DramCommand cmd, uint64_t now);
    void serve(Channel& ch, size_t index, uint64_t now);

    DramConfig config_;
    uint32_t line_bytes_;
    // rules_[prev] lists the constraints triggered by issuing `prev`.
    std::array<std::vector<DramConstraint>, kCommands> rules_;
    std::vector<Channel> channels_;
    std::priority_queue<Reply, std::vector<Reply>, std::greater<>> replies_;
    uint64_t next_sequence_ = 0;
    std::vector<MemRequest> served_;
    Counters counters_;
};

}  // namespace tpsim::timing
