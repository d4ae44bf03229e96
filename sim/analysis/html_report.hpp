// `tpsim report` and `tpsim compare --html`: one self-contained HTML page (images as base64
// PNG, Chart.js inlined, all chart data in one JSON blob) that opens offline.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "sim/analysis/compare.hpp"
#include "sim/analysis/stats_file.hpp"

namespace tpsim::analysis {

/// Chart.js's UMD build from Debian's libjs-chart.js, read to be inlined in a page. Throws
/// tpsim::Error naming the package when it is not installed.
std::string load_chart_js();

/// The report of one run.
/// `source` says where the statistics are kept, in the page's header: by default "statistics
/// file <run.path>"; `render --html` names its --stats-json file, or says there is none.
std::string report_page(const StatsFile& run, const std::string& chart_js,
                        const std::string& source = "");

/// The runs side by side, with grouped bar charts; `comparison` is compare(runs).
std::string comparison_page(const std::vector<StatsFile>& runs, const Comparison& comparison,
                            const std::string& chart_js);

/// The page of `tpsim converge` (its JSON document, converge.hpp): the chart of image error
/// against frame cycles, the table and the images, read from files relative to `base`.
std::string converge_page(const Json& document, const std::filesystem::path& base,
                          const std::string& chart_js);

/// The page of `tpsim sample-check` (its JSON document, sample_check.hpp): speedups, each
/// statistic's error against speedup with its interval, coverage over the seeds, and the tables.
std::string sample_check_page(const Json& document, const std::string& chart_js);

/// The page of `tpsim sweep collect` (its table document, sweep/sweep.hpp table_document): a
/// chart of each chosen metric against the chosen axis, one per scene, and every job's row.
std::string sweep_page(const Json& document, const std::string& chart_js);

}  // namespace tpsim::analysis
