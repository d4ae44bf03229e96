// Where the cycles and the bytes go: what the chip counts beyond its totals — traffic by memory
// region, costs by instruction address (the source-line profile) and costs by work item (the
// per-pixel heat map). docs/statistics.md defines every figure.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace tpsim::timing {

/// Why a TP did not issue in a cycle (exactly one cause per TP-cycle).
enum class Stall : uint8_t {
    FetchConflict,  ///< lost the I-cache bank to another thread
    Branch,         ///< bubble after a branch (tp.branch_*_penalty)
    FuBusy,         ///< operands ready but every unit of the pool was taken
    MemoryPort,     ///< a previous load/store still waits for an L1 bank or MSHR
    Operand,        ///< an operand is not ready; attributed to its producing pool
    Sync,           ///< waiting at the barrier or for a semaphore (tp.barrier, tp.semacq ...)
    FetchMiss,      ///< waiting for an instruction line from the L2 (finite I-cache only)
    Count
};
constexpr size_t kStallCauses = static_cast<size_t>(Stall::Count);

/// A named range [begin, end) of guest byte addresses: a section of the memory image or a
/// segment of the kernel ELF. The chip tags each global load/store with its region once, when
/// it issues, and every level counts by that tag.
struct Region {
    std::string name;  ///< a statistics-name segment, e.g. "bvh_nodes"
    uint32_t begin = 0, end = 0;
};

/// One region's traffic at one level (l1, l2 or dram); docs/statistics.md defines each figure
/// per level. DRAM has no hits or misses (they stay 0).
struct LevelTraffic {
    uint64_t reads = 0, writes = 0, hits = 0, misses = 0, merged_misses = 0;
    uint64_t payload_bytes = 0;  ///< bytes the kernel's loads and stores asked of this level
    uint64_t moved_bytes = 0;    ///< bytes this level moved to or from the level below
};

/// Instruction words [base, base + 4 * words) of the kernel's code.
struct TextRange {
    uint32_t base = 0, words = 0;
};

/// What the chip is told about the program and the memory it runs over (not configuration:
/// it follows from the scene and the kernel).
struct ChipLayout {
    /// Non-overlapping, any order. Global accesses outside all of them count as "other".
    std::vector<Region> regions;
    /// The kernel's code (its executable segments, by address): one profile entry per word.
    std::vector<TextRange> text;
    /// Work items handed out by atomicinc on global register 0 (the pixel counter of the
    /// kernels): 0..work_items-1 are charged per item, others to WorkItemCosts::unassigned.
    uint32_t work_items = 0;
    /// Collect the per-instruction profile (PcProfile); off: profile() is empty.
    bool profile = false;
};

/// One instruction address's costs.
struct PcCounters {
    uint64_t executions = 0;                      ///< times issued
    std::array<uint64_t, kStallCauses> stalls{};  ///< TP-cycles its thread stalled on it
    uint64_t l1_misses = 0;                       ///< its loads that missed in the L1
    uint64_t dram_bytes = 0;                      ///< DRAM bytes moved for its misses and stores
};

/// Costs by instruction address: one entry per word of each text range, the ranges' words
/// back to back in `words`.
struct PcProfile {
    std::vector<TextRange> text;
    std::vector<PcCounters> words;

    /// The counters of the instruction at `pc`, or nullptr outside the text.
    PcCounters* at(uint32_t pc) {
        size_t first = 0;
        for (const TextRange& range : text) {
            const uint32_t index = (pc - range.base) / 4;
            if (index < range.words) return &words[first + index];
            first += range.words;
        }
        return nullptr;
    }
};

/// One work item's costs: a thread's cycles, instructions and DRAM bytes from the atomicinc(0)
/// that returned the item to the thread's next atomicinc(0) (or its exit).
struct WorkItemCounters {
    uint64_t cycles = 0;
    uint64_t instructions = 0;
    uint64_t dram_bytes = 0;
};

struct WorkItemCosts {
    std::vector<WorkItemCounters> items;  ///< ChipLayout::work_items entries
    /// Before a thread's first atomicinc(0), and while it holds a value >= work_items (the
    /// fetch past the end that tells it to stop).
    WorkItemCounters unassigned;
};

}  // namespace tpsim::timing
