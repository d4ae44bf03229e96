// Parameter sweeps (docs/sweeps.md): a sweep file names axes of run settings and chip
// configuration keys; it expands into jobs with stable ids, which run as separate processes
// (GNU parallel on one machine, a Slurm job array on a cluster) into one results directory, and
// are collected into one table.
#pragma once
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sim/scene/accel_settings.hpp"
#include "sim/timing/config.hpp"

namespace tpsim::sweep {

using Json = nlohmann::ordered_json;

/// What one job renders, resolved from its settings: paths are absolute, the chip
/// configuration complete and valid.
struct JobRun {
    std::filesystem::path scene;
    std::filesystem::path kernel;
    /// The structure and its settings the sweep file gives (the key `accel` is the
    /// structure); the rest come from the scene file's [accel] table and the defaults.
    scene::AccelSettings accel;
    uint32_t width = 0, height = 0, spp = 0;  ///< 0: the scene's
    uint32_t seed = 0;
    std::string timing = "cycle";  ///< cycle, sampled or none (render --timing)
    timing::ChipConfig chip;
};

/// One setting as the sweep file gives it: a run setting ("scene", "bvh" ...) or a chip
/// configuration key ("l1.size_bytes"), and its value (a string, integer or boolean).
struct Setting {
    std::string name;
    Json value;
};

/// One swept setting and its values, in the file's order.
struct Axis {
    std::string name;
    std::vector<Json> values;
};

struct Job {
    /// 12 hex digits hashed from the job's settings (fixed and swept, sorted by name), so that
    /// adding values to an axis or reordering the file leaves every other job's id alone.
    std::string id;
    std::vector<Json> values;  ///< its value of each axis, in Sweep::axes order
    JobRun run;
};

struct Sweep {
    std::filesystem::path file;  ///< the sweep file, as given
    std::vector<Axis> axes;      ///< in the file's order
    std::vector<Setting> fixed;  ///< settings with one value, in the file's order
    /// Axes that advance together (zip); every other axis, and each group, is crossed.
    std::vector<std::vector<std::string>> zip;
    std::vector<Job> jobs;  ///< in expansion order: the first axis (or group) varies slowest

    const Job* find(std::string_view id) const;
    /// "scene=cornell.toml, l1.size_bytes=8192": a job's axis values as a person reads them.
    std::string describe(const Job& job) const;
};

/// Resolves a kernel given by name (not a path) to its built ELF; throws tpsim::Error.
using KernelResolver = std::function<std::filesystem::path(const std::string&)>;

/// The settings a sweep file may name besides chip configuration keys.
inline constexpr const char* kRunSettings[] = {"scene",
                                               "kernel",
                                               "config",
                                               "accel",
                                               "grid_resolution",
                                               "grid_density",
                                               "kdtree_max_depth",
                                               "kdtree_max_references",
                                               "octree_max_depth",
                                               "bvh",
                                               "max_leaf",
                                               "bvh_order",
                                               "bvh_align_pairs",
                                               "bvh_boxes",
                                               "width",
                                               "height",
                                               "spp",
                                               "seed",
                                               "timing"};

/// Reads, checks and expands a sweep file. Throws tpsim::Error with one line naming
/// file:line for anything wrong (unknown key, bad value, missing scene, empty axis, zip groups
/// of unequal lengths, a combination the chip configuration refuses).
Sweep load_sweep(const std::filesystem::path& file, const KernelResolver& resolve_kernel);

/// The results directory's layout.
std::filesystem::path plan_path(const std::filesystem::path& dir);  ///< DIR/sweep.json
std::filesystem::path stats_path(const std::filesystem::path& dir, const std::string& id);
std::filesystem::path error_path(const std::filesystem::path& dir, const std::string& id);
std::filesystem::path log_dir(const std::filesystem::path& dir);

/// Writes the expanded sweep to DIR/sweep.json (creating DIR and its subdirectories): what
/// `tpsim sweep job` runs from, on this machine or a cluster node.
void write_plan(const Sweep& sweep, const std::filesystem::path& dir);
/// Reads DIR/sweep.json back; throws tpsim::Error naming the file when it is not one.
Sweep read_plan(const std::filesystem::path& dir);

/// A job is finished when its statistics file exists: it is written under a temporary name
/// and renamed, so it is complete whenever it exists.
bool finished(const std::filesystem::path& dir, const Job& job);
/// The jobs not finished yet, in plan order.
std::vector<const Job*> pending(const Sweep& sweep, const std::filesystem::path& dir);

/// Runs one job in this process: renders, then writes DIR/jobs/ID.png and DIR/jobs/ID.json
/// (each atomically). On failure writes the error's line to DIR/jobs/ID.error and rethrows.
void run_job(const Sweep& sweep, const Job& job, const std::filesystem::path& dir);

/// A job that did not finish, and why (its error line, or what the launcher saw).
struct Failure {
    const Job* job;
    std::string reason;
};
/// The jobs of the plan without a statistics file, with the error each recorded.
std::vector<Failure> failures(const Sweep& sweep, const std::filesystem::path& dir);

/// Runs the pending jobs through GNU parallel with `workers` processes, each `tpsim sweep job
/// DIR ID` (tpsim being `tpsim_exe`); a progress bar on a terminal, one line per job otherwise.
/// Throws tpsim::Error when parallel cannot be started. Failed jobs do not stop the rest.
void run_parallel(const Sweep& sweep, const std::filesystem::path& dir, unsigned workers,
                  const std::filesystem::path& tpsim_exe);

/// The Slurm batch script: one array task per pending job (there must be one), each `tpsim
/// sweep job DIR ID`, its output in DIR/logs; `sbatch_options` are added as #SBATCH lines (e.g.
/// "--mem=2G").
std::string slurm_script(const Sweep& sweep, const std::filesystem::path& dir,
                         const std::filesystem::path& tpsim_exe,
                         const std::vector<std::string>& sbatch_options);

/// A column of the collected table: a short name and the statistic it reads.
struct Column {
    std::string name;  ///< e.g. "cycles"
    std::string stat;  ///< e.g. "chip/cycles"
    /// Named by the user: a statistic that no finished job has is a mistake, not a blank column
    /// (the default columns may be absent, e.g. cycles of a `--timing none` job).
    bool given = false;
    std::string unit = "";  ///< as the finished jobs' statistics files give it (collect fills it)
};
/// The table's statistics unless the user adds more (docs/sweeps.md).
std::vector<Column> default_columns();

/// Every job of the plan with its axis values and statistics (absent: null), in plan order.
struct Table {
    std::vector<std::string> axes;
    std::vector<Setting> fixed;
    std::vector<Column> columns;
    struct Row {
        std::string id;
        std::string status;  ///< "ok", "failed" or "missing"
        std::vector<Json> values;
        std::vector<std::optional<double>> stats;  ///< by column
        std::optional<double> host_seconds;        ///< load + BVH build + run, host wall time
    };
    std::vector<Row> rows;
};
Table collect(const Sweep& sweep, const std::filesystem::path& dir,
              const std::vector<Column>& columns);

/// The table as CSV (numbers exact) and as Markdown (readable numbers); host time last, or
/// not at all when `host_time` is false (so that two runs' tables compare byte for byte).
std::string table_csv(const Table& table, bool host_time);
std::string table_markdown(const Table& table, bool host_time);

/// What the page charts: `metrics` (column names) against axis `x`, one line (or bar group) per
/// value of axis `by` and one chart per combination of the other axes; without `by`, one chart
/// per scene (when the scene is an axis) and one line per combination of the other axes.
struct ChartChoice {
    std::vector<std::string> metrics;
    std::string x;
    std::string by;  ///< may be empty
};
/// The default: frame cycles and DRAM bytes read against the first axis that is not the scene.
ChartChoice default_charts(const Table& table);
/// The table and chart choice as the JSON document analysis::sweep_page() draws. Throws
/// tpsim::Error for a metric or axis the table does not have.
Json table_document(const Table& table, const ChartChoice& charts, const std::string& title);

}  // namespace tpsim::sweep
