// A statistics file (`tpsim render --stats-json`, format version 2) read back as values: the
// analysis tools (compare, report) work only on these, never on a live chip.
#pragma once
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace tpsim::analysis {

using Json = nlohmann::ordered_json;

/// The format version this tpsim reads (and `tpsim render` writes).
inline constexpr int kStatsFormatVersion = 2;

/// Samples over cycles: each row holds one value per column, for the interval ending at its
/// "cycle" column.
struct Timeline {
    uint64_t interval_cycles = 0;
    std::vector<std::string> columns;
    std::vector<std::vector<double>> rows;

    /// Index of the column called `name`, if there is one.
    std::optional<size_t> column(std::string_view name) const;
};

/// One function or source line of the profile, with the cycles charged to it.
struct ProfileEntry {
    std::string function;
    std::string file;  ///< empty for functions
    int64_t line = 0;  ///< 0 for functions
    double executions = 0;
    double cycles = 0;
    std::vector<std::pair<std::string, double>> stalls;  ///< by cause, in file order
    double l1_misses = 0;
    double dram_bytes = 0;
};

struct Profile {
    double total_cycles = 0;  ///< TP-cycles charged: the 100 % of every entry's share
    std::vector<ProfileEntry> functions;
    std::vector<ProfileEntry> lines;
};

struct StatsFile {
    std::filesystem::path path;                         ///< as given to load_stats_file()
    Json run;                                           ///< what was run (an object)
    std::vector<std::pair<std::string, Json>> config;   ///< resolved chip configuration
    std::vector<std::pair<std::string, double>> stats;  ///< in file order; null reads as NaN
    std::map<std::string, std::string, std::less<>> units;
    std::vector<std::string> regions;  ///< empty unless the cycle-level engine ran
    std::optional<Timeline> timeline;
    std::optional<Profile> profile;
    /// A sampled run (render --timing sampled): what was sampled, and the half-width of each
    /// estimate's confidence interval (statistics absent here are exact; NaN: unknown).
    std::optional<Json> sampling;
    std::map<std::string, double, std::less<>> intervals;

    std::optional<double> stat(std::string_view name) const;
    /// The half-width of the estimate's interval; 0 for an exact value, NaN when unknown.
    double interval(std::string_view name) const;
    /// Are the statistics estimates (a sampled run)?
    bool estimated() const { return sampling && sampling->value("estimated", false); }
    std::string unit(std::string_view name) const;
    /// A run field as text ("" when absent): strings as they are, numbers printed.
    std::string run_text(std::string_view key) const;
    /// A file a run field names (image, heatmap), resolved against the JSON file's directory.
    std::optional<std::filesystem::path> run_file(std::string_view key) const;

    std::map<std::string, size_t, std::less<>> stat_index;  ///< name -> position in stats
};

/// Largest statistics file read, and deepest nesting accepted (the format nests 4 deep).
inline constexpr uintmax_t kMaxStatsFileBytes = uintmax_t(256) << 20;
inline constexpr int kMaxStatsDepth = 16;

/// Reads and checks a statistics file. Throws tpsim::Error with one line naming the file and
/// what is wrong (not JSON, not a tpsim statistics file, another format version, bad field).
StatsFile load_stats_file(const std::filesystem::path& path);

/// The same from text already read; `path` names the file in messages and resolves run files.
StatsFile parse_stats_file(std::string_view text, const std::filesystem::path& path);

}  // namespace tpsim::analysis
