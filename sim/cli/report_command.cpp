// `tpsim report RUN.json`: one run's statistics as a self-contained HTML page with charts.
#include <memory>
#include <string>

#include "sim/analysis/html_report.hpp"
#include "sim/cli/commands.hpp"

namespace tpsim::cli {
namespace {

struct ReportCommandOptions {
    std::string file;
    std::string output;
};

int run_report(const ReportCommandOptions& o) {
    const std::filesystem::path output =
        o.output.empty() ? std::filesystem::path(o.file).replace_extension(".html")
                         : std::filesystem::path(o.output);
    check_output_path(output, "the report");
    const analysis::StatsFile run = analysis::load_stats_file(o.file);
    write_output(output, analysis::report_page(run, analysis::load_chart_js()), "the report");
    return 0;
}

}  // namespace

Command add_report_command(CLI::App& app) {
    auto* command = app.add_subcommand(
        "report", "Write one run's statistics file (tpsim render --stats-json) as a "
                  "self-contained HTML page: image, heat map, charts, profile, configuration");
    auto o = std::make_shared<ReportCommandOptions>();
    command->add_option("file", o->file, "Statistics file")->required();
    command->add_option("-o,--output", o->output,
                        "HTML page to write [default: FILE with extension .html]");
    return {command, [o] { return run_report(*o); }};
}

}  // namespace tpsim::cli
