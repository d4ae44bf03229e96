// The source-line profile: the chip's costs per instruction word (timing::PcProfile) rolled up
// by function and by source line, and printed as JSON, as a report section and as an annotated
// source listing (docs/statistics.md, "The profile").
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "sim/core/elf_loader.hpp"
#include "sim/timing/attribution.hpp"

namespace tpsim::render {

/// The stall causes in timing::Stall order, spelt as the statistics file spells them.
inline constexpr std::array<std::string_view, timing::kStallCauses> kStallNames = {
    "fetch_conflict", "branch", "fu_busy", "memory_port", "operand", "sync", "fetch_miss"};

/// Where the profile puts addresses without a function or a source line.
inline constexpr std::string_view kUnknown = "(unknown)";

/// What an instruction word, a line or a function costs.
struct ProfileCosts {
    uint64_t executions = 0;
    uint64_t cycles = 0;  ///< TP-cycles charged: executions + all stalls
    std::array<uint64_t, timing::kStallCauses> stalls{};
    uint64_t l1_misses = 0;
    uint64_t dram_bytes = 0;

    ProfileCosts& operator+=(const ProfileCosts& other);
    bool operator==(const ProfileCosts&) const = default;
};

/// One word's counters as costs.
ProfileCosts costs_of(const timing::PcCounters& word);

struct FunctionProfile {
    std::string function;  ///< demangled symbol name, or kUnknown
    uint32_t address = 0;  ///< the symbol's address; 0 for kUnknown
    ProfileCosts costs;
};

/// A source line, charged with the words whose innermost line it is: code inlined into a caller
/// counts on the inlined function's own line, as fault messages name it.
struct LineProfile {
    std::string file;      ///< file name (SourceLocation::file), or kUnknown
    std::string path;      ///< full path from DWARF, for reading the source; "" for kUnknown
    uint32_t line = 0;     ///< 0 for kUnknown
    std::string function;  ///< the function the line is in (Program::source_function_at)
    ProfileCosts costs;
};

/// Entries with any cost only, sorted by cycles descending, ties by address (functions) or by
/// path, line and function (lines). Both lists add up to `total` exactly.
struct Profile {
    ProfileCosts total;
    std::vector<FunctionProfile> functions;
    std::vector<LineProfile> lines;
};

/// Rolls the per-word costs up by function and by line of `program` (the ELF the chip ran).
Profile profile_of(const timing::PcProfile& words, const core::Program& program);

/// The "profile" object of the statistics file (docs/statistics.md).
nlohmann::ordered_json profile_json(const Profile& profile);

/// The report section: the hottest functions and lines with their share of the cycles,
/// executions, stalls by cause, L1 misses and DRAM bytes, in at most 100 columns.
void print_profile(const Profile& profile, std::ostream& out);

/// Writes the source of every file with costs, hottest file first, each line with its share of
/// the cycles, L1 misses and DRAM bytes in a left margin and the hottest lines ranked (the style
/// of `perf annotate`). `kernel` names the ELF in the heading. A source file that cannot be read
/// gets a note and its lines' costs without text. Throws tpsim::Error if `path` cannot be
/// written.
void write_annotated_listing(const std::filesystem::path& path, const Profile& profile,
                             const std::string& kernel);

/// "trax::rt::BvhTraversal::trace<false>" for "trax::rt::Hit trax::rt::BvhTraversal::trace<false>
/// (trax::rt::Vec3, float) const": the name without return type and parameters, for narrow
/// columns.
std::string short_function_name(std::string_view demangled);

}  // namespace tpsim::render
