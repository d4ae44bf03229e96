#include "sim/core/stack_bound.hpp"

#include <algorithm>
#include <cstring>
#include <map>
#include <optional>

#include <fmt/format.h>

#include "isa/isa.hpp"

namespace tpsim::core {
namespace {

constexpr uint8_t kRa = 1;  // x1, the link register: rd of a call
constexpr uint8_t kX0 = isa::kSink;
/// Longest call chain walked; the walk recurses once per call, on the host stack.
constexpr size_t kMaxChain = 4096;

/// What one function does with the stack: its frame and whom it calls.
struct Calls {
    std::vector<uint32_t> calls;       ///< callees' addresses
    std::vector<uint32_t> tail_calls;  ///< jumps to other functions (the frame is gone by then)
    std::string unknown;               ///< set when a call's target cannot be known
};

std::optional<uint32_t> word_at(const Program& program, uint32_t pc) {
    const Segment* segment = program.segment_at(pc);
    if (!segment || !segment->executable || pc - segment->vaddr + 4 > segment->bytes.size())
        return std::nullopt;
    uint32_t word = 0;
    std::memcpy(&word, segment->bytes.data() + (pc - segment->vaddr), 4);
    return word;
}

Calls calls_of(const Program& program, const Symbol& function) {
    Calls out;
    const uint32_t end = function.address + function.size;
    // The value the instruction before put in auipc_reg, if it was an auipc (kNoReg: it was not).
    uint32_t auipc_value = 0;
    uint8_t auipc_reg = isa::kNoReg;
    for (uint32_t pc = function.address; pc < end; pc += 4) {
        const std::optional<uint32_t> word = word_at(program, pc);
        if (!word) break;
        const isa::Decoded d = isa::decode(*word);
        const bool from_auipc = auipc_reg != isa::kNoReg && d.rs1 == auipc_reg;
        if (d.op == isa::Op::jal || d.op == isa::Op::jalr) {
            std::optional<uint32_t> target;
            if (d.op == isa::Op::jal) target = pc + uint32_t(d.imm);
            if (d.op == isa::Op::jalr && from_auipc) target = auipc_value + uint32_t(d.imm);
            const bool is_return = d.op == isa::Op::jalr && d.rd == kX0 && d.rs1 == kRa;
            const bool local = target && *target >= function.address && *target < end;
            if (d.rd == kRa) {
                if (target)
                    out.calls.push_back(*target);
                else if (out.unknown.empty())
                    out.unknown = fmt::format("{} calls through a pointer at {:#x}",
                                              demangle(function.name), pc);
            } else if (target && !local) {
                out.tail_calls.push_back(*target);
            } else if (!target && !is_return && out.unknown.empty()) {
                // An indirect tail call, or a switch's jump table (add_trax_kernel compiles
                // with -fno-jump-tables, so a kernel has none): the target cannot be known.
                out.unknown = fmt::format("{} jumps through a register at {:#x}",
                                          demangle(function.name), pc);
            }
        }
        auipc_reg = d.op == isa::Op::auipc ? d.rd : isa::kNoReg;
        auipc_value = pc + uint32_t(d.imm);
    }
    return out;
}

class Walk {
public:
    explicit Walk(const Program& program) : program_(program) {
        for (const Program::FrameSize& frame : program.frame_sizes)
            frames_[frame.address] = frame.bytes;
    }

    /// The deepest need from `address`; nullopt (with reason_ set) when there is no bound.
    std::optional<uint32_t> need(uint32_t address) {
        if (const auto done = needs_.find(address); done != needs_.end()) return done->second;
        const Symbol* function = program_.function_at(address);
        if (!function || function->address != address || function->size == 0) {
            reason_ =
                fmt::format("a call goes to {:#x}, which is not the start of a function", address);
            return std::nullopt;
        }
        if (path_.size() >= kMaxChain) {  // only a damaged or generated ELF nests this deep
            reason_ = fmt::format("its calls nest more than {} deep", kMaxChain);
            return std::nullopt;
        }
        if (std::find(path_.begin(), path_.end(), address) != path_.end()) {
            reason_ = fmt::format("{} is recursive", demangle(function->name));
            return std::nullopt;
        }
        const Calls calls = calls_of(program_, *function);
        if (!calls.unknown.empty()) {
            reason_ = calls.unknown;
            return std::nullopt;
        }
        path_.push_back(address);
        const auto frame = frames_.find(address);
        const uint32_t own = frame == frames_.end() ? 0 : frame->second;
        uint32_t deepest = own;
        uint32_t via = 0;  // the callee on the deepest chain, 0 = none
        // A call's callee runs below this frame; a tail call's replaces it.
        const auto deepen = [&](const std::vector<uint32_t>& callees, uint32_t above) {
            for (uint32_t callee : callees) {
                const std::optional<uint32_t> below = need(callee);
                if (!below) return false;
                if (above + *below > deepest) {
                    deepest = above + *below;
                    via = callee;
                }
            }
            return true;
        };
        if (!deepen(calls.calls, own) || !deepen(calls.tail_calls, 0)) return std::nullopt;
        path_.pop_back();
        needs_[address] = deepest;
        deepest_callee_[address] = via;
        return deepest;
    }

    std::vector<std::string> chain(uint32_t address) const {
        std::vector<std::string> names;
        for (size_t step = 0; address != 0 && step < needs_.size(); ++step) {
            const auto frame = frames_.find(address);
            names.push_back(fmt::format("{} ({} B)", demangle(program_.function_at(address)->name),
                                        frame == frames_.end() ? 0 : frame->second));
            address = deepest_callee_.at(address);
        }
        return names;
    }

    const std::string& reason() const { return reason_; }

private:
    const Program& program_;
    std::map<uint32_t, uint32_t> frames_;
    std::map<uint32_t, uint32_t> needs_;
    std::map<uint32_t, uint32_t> deepest_callee_;
    std::vector<uint32_t> path_;
    std::string reason_;
};

}  // namespace

StackBound stack_bound(const Program& program) {
    StackBound bound;
    if (program.frame_sizes.empty()) {
        bound.reason = "the ELF records no stack frames (build it with add_trax_kernel, which "
                       "compiles with -fstack-size-section)";
        return bound;
    }
    const Symbol* entry = program.function_at(program.entry);
    if (!entry || entry->address != program.entry) {
        bound.reason = fmt::format("the entry point {:#x} is not a function", program.entry);
        return bound;
    }
    Walk walk(program);
    const std::optional<uint32_t> bytes = walk.need(entry->address);
    if (!bytes) {
        bound.reason = walk.reason();
        return bound;
    }
    bound.bounded = true;
    bound.bytes = *bytes;
    bound.chain = walk.chain(entry->address);
    return bound;
}

}  // namespace tpsim::core
