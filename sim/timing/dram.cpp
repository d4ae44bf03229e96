#include "sim/timing/dram.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

namespace tpsim::timing {

std::vector<DramConstraint> dram_constraints(const DramConfig& c) {
    using enum DramCommand;
    const uint32_t column_to_column = std::max(c.tCCD, c.tBURST);  // bus stays one burst busy
    // Read-to-write: the read data must clear the bus before the write data starts.
    const uint32_t read_to_write =
        c.tCL + c.tBURST + 1 > c.tCWL ? c.tCL + c.tBURST + 1 - c.tCWL : 1;
    return {
        {Activate, Read, true, c.tRCD},
        {Activate, Write, true, c.tRCD},
        {Activate, Precharge, true, c.tRAS},
        {Activate, Activate, false, c.tRRD},
        {Precharge, Activate, true, c.tRP},
        {Read, Read, false, column_to_column},
        {Read, Write, false, read_to_write},
        {Read, Precharge, true, c.tRTP},
        {Write, Write, false, column_to_column},
        {Write, Read, false, c.tCWL + c.tBURST + c.tWTR},
        {Write, Precharge, true, c.tCWL + c.tBURST + c.tWR},
    };
}

Dram::Dram(const DramConfig& config, uint32_t line_bytes)
    : config_(config), line_bytes_(line_bytes), channels_(config.channels) {
    if (line_bytes == 0 || config.row_bytes < line_bytes || config.row_bytes % line_bytes != 0)
        throw std::invalid_argument(
            "Dram: row_bytes must be a multiple of the line size; validate the ChipConfig first");
    for (const DramConstraint& rule : dram_constraints(config))
        rules_[static_cast<size_t>(rule.prev)].push_back(rule);
    for (Channel& ch : channels_) {
        ch.banks.resize(config.banks);
        ch.queue.reserve(config.queue_depth);
    }
}

DramLocation Dram::locate(uint32_t addr) const {
    const uint32_t chunk = addr / config_.row_bytes;
    return {chunk % config_.channels, (chunk / config_.channels) % config_.banks,
            chunk / config_.channels / config_.banks, addr % config_.row_bytes};
}

bool Dram::can_accept(uint32_t addr) const {
    return channels_[locate(addr).channel].queue.size() < config_.queue_depth;
}

bool Dram::enqueue(uint64_t now, const MemRequest& request) {
    if (!can_accept(request.addr)) {
        ++counters_.queue_full;
        return false;
    }
    const DramLocation where = locate(request.addr);
    Channel& ch = channels_[where.channel];
    ch.queue.push_back({request, where, now});
    Bank& bank = ch.banks[where.bank];
    bank.queued_hits += bank.open_row == where.row;
    return true;
}

bool Dram::ready(const Channel& ch, const Bank& bank, DramCommand cmd, uint64_t now) const {
    const size_t i = static_cast<size_t>(cmd);
    return now >= bank.earliest[i] && now >= ch.earliest[i];
}

void Dram::issue(Channel& ch, Bank& bank, DramCommand cmd, uint64_t now) {
    for (const DramConstraint& rule : rules_[static_cast<size_t>(cmd)]) {
        if (rule.per_bank) {
            uint64_t& e = bank.earliest[static_cast<size_t>(rule.next)];
            e = std::max(e, now + rule.delay);
        } else {
            // A channel rule binds every bank of the channel, the issuing one included.
            uint64_t& e = ch.earliest[static_cast<size_t>(rule.next)];
            e = std::max(e, now + rule.delay);
        }
    }
}

void Dram::serve(Channel& ch, size_t index, uint64_t now) {
    const Pending p = ch.queue[index];
    ch.queue.erase(ch.queue.begin() + static_cast<std::ptrdiff_t>(index));
    --ch.banks[p.where.bank].queued_hits;  // served requests always hit the open row
    if (p.precharged)
        ++counters_.row_conflicts;
    else if (p.activated)
        ++counters_.row_misses;
    else
        ++counters_.row_hits;
    counters_.bus_busy_cycles += config_.tBURST;
    served_.push_back(p.request);
    if (p.request.write) {
        ++counters_.writes;
        counters_.bytes_written += line_bytes_;
        counters_.store_payload_bytes += p.request.bytes;
        return;  // stores need no reply
    }
    ++counters_.reads;
    counters_.bytes_read += line_bytes_;
    replies_.push({now + config_.tCL + config_.tBURST, next_sequence_++, p.request});
}

void Dram::tick(uint64_t now) {
    using enum DramCommand;
    for (Channel& ch : channels_) {
        // First ready: the oldest request whose row is open and whose column command may issue.
        bool issued = false;
        for (size_t i = 0; i < ch.queue.size() && !issued; ++i) {
            const Pending& p = ch.queue[i];
            Bank& bank = ch.banks[p.where.bank];
            const DramCommand column = p.request.write ? Write : Read;
            if (bank.open_row == p.where.row && ready(ch, bank, column, now)) {
                issue(ch, bank, column, now);
                serve(ch, i, now);
                issued = true;
            }
        }
        // Otherwise first come: open the row of the oldest request that can make progress.
        for (size_t i = 0; i < ch.queue.size() && !issued; ++i) {
            Pending& p = ch.queue[i];
            Bank& bank = ch.banks[p.where.bank];
            if (bank.open_row == kClosed) {
                if (!ready(ch, bank, Activate, now)) continue;
                issue(ch, bank, Activate, now);
                bank.open_row = p.where.row;
                bank.queued_hits = static_cast<uint32_t>(
                    std::count_if(ch.queue.begin(), ch.queue.end(), [&](const Pending& q) {
                        return q.where.bank == p.where.bank && q.where.row == p.where.row;
                    }));
                p.activated = true;
                ++counters_.activates;
                issued = true;
            } else if (bank.open_row != p.where.row && bank.queued_hits == 0) {
                // Close a row only when no queued request still hits it.
                if (!ready(ch, bank, Precharge, now)) continue;
                issue(ch, bank, Precharge, now);
                bank.open_row = kClosed;  // queued_hits is already 0
                p.precharged = true;
                ++counters_.precharges;
                issued = true;
            }
        }
    }
}

bool Dram::pop_reply(uint64_t now, MemReply& reply) {
    if (replies_.empty() || replies_.top().ready > now) return false;
    reply = {replies_.top().ready, replies_.top().request};
    replies_.pop();
    return true;
}

bool Dram::idle() const {
    return replies_.empty() && std::all_of(channels_.begin(), channels_.end(),
                                           [](const Channel& ch) { return ch.queue.empty(); });
}

void Dram::register_stats(stats::Registry& r, std::string_view prefix) const {
    auto name = [&](std::string_view leaf) { return fmt::format("{}/{}", prefix, leaf); };
    r.add_counter(name("reads"), counters_.reads, "line reads served", "requests");
    r.add_counter(name("writes"), counters_.writes, "line writes served", "requests");
    r.add_counter(name("bytes_read"), counters_.bytes_read, "bytes read", "B");
    r.add_counter(name("bytes_written"), counters_.bytes_written, "bytes written (whole lines)",
                  "B");
    r.add_counter(name("store_payload_bytes"), counters_.store_payload_bytes,
                  "bytes of those line writes that stores wrote", "B");
    r.add_counter(name("row_hits"), counters_.row_hits, "requests served from an open row",
                  "requests");
    r.add_counter(name("row_misses"), counters_.row_misses, "requests that activated a closed bank",
                  "requests");
    r.add_counter(name("row_conflicts"), counters_.row_conflicts,
                  "requests that closed another row first", "requests");
    r.add_counter(name("activates"), counters_.activates, "ACT commands", "commands");
    r.add_counter(name("precharges"), counters_.precharges, "PRE commands", "commands");
    r.add_counter(name("bus_busy_cycles"), counters_.bus_busy_cycles,
                  "data-bus busy cycles summed over channels", "cycles");
    r.add_counter(name("queue_full"), counters_.queue_full,
                  "requests refused because a channel queue was full", "requests");
}

}  // namespace tpsim::timing
