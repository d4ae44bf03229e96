// What a render reports: its statistics registered under hierarchical names
// (docs/statistics.md), printed as text or JSON by the stats printers.
#pragma once
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sim/render/render.hpp"
#include "sim/stats/estimate.hpp"
#include "sim/stats/registry.hpp"

namespace tpsim::render {

/// Registers the scene, memory-image, BVH, instruction and host-time statistics of `result`.
/// `result` must outlive every use of `registry`.
void register_stats(const RenderResult& result, stats::Registry& registry);

/// A render's statistics as values: every registered statistic read at the end of the run, or
/// for a sampled run estimated from its units, with intervals. The registry refers to
/// `result`, which must outlive it.
struct RunStatistics {
    stats::Registry registry;
    stats::Snapshot values;
    std::optional<stats::Estimate> estimate;  ///< a sampled run's (not one its head covered)
};
RunStatistics run_statistics(const RenderResult& result);

/// A path as a person reads it: relative to the working directory when it lies below it.
std::string display_path(const std::filesystem::path& path);

/// "the defaults (configs/trax.toml) except l1.size_bytes=16384": the chip configuration as the
/// fields that differ from the defaults.
std::string describe_config(const timing::ChipConfig& chip);

/// The human summary the report leads with: scene, kernel and chip (the configuration fields
/// that differ from the defaults), memory image by section, BVH, rays, cycles, run speed; for
/// a sampled run, what was sampled and the key estimates with their intervals.
void print_summary(const RenderOptions& options, const RenderResult& result,
                   const RunStatistics& statistics, std::ostream& out);

/// The regions of the region/<r>/... statistics, in registration order (the table's rows).
std::vector<std::string> region_names(const stats::Snapshot& snapshot);

/// The compact traffic table: per region, L1 accesses and hit rate, L2 reads and hit rate, DRAM
/// bytes read and written (whole lines of `line_bytes`) and the store payload they carried.
void print_traffic(const stats::Snapshot& snapshot, uint32_t line_bytes, std::ostream& out);

/// The energy and area table: per part of the chip (energy/<part>, area/<part>), its energy
/// over the run and area, each with its share of the total. Nothing without energy statistics.
void print_energy(const stats::Snapshot& snapshot, std::ostream& out);

/// What a render wrote beside its statistics, named in the statistics file.
struct OutputPaths {
    std::filesystem::path image;    ///< the rendered image
    std::filesystem::path heatmap;  ///< the heat-map PNG, or empty
};

/// The statistics file of a render (docs/statistics.md, "The statistics file"): run, config,
/// the statistics' values and units, regions, timeline and profile; for a sampled run also
/// the sampling and every estimate's interval. Output paths are stored
/// relative to the directory of `json_path`, so the files can move together.
nlohmann::ordered_json stats_document(const RenderOptions& options, const RenderResult& result,
                                      const RunStatistics& statistics,
                                      const std::filesystem::path& json_path,
                                      const OutputPaths& outputs);

/// The version of the statistics file this tpsim writes (and its analysis tools read).
constexpr int kStatsFileVersion = 2;

}  // namespace tpsim::render
