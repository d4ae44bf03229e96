// `tpsim compare A.json B.json ...`: statistics files side by side, each later run as a ratio
// to the first, as text, markdown, CSV or JSON, and optionally as an HTML page.
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>

#include "sim/analysis/compare.hpp"
#include "sim/analysis/html_report.hpp"
#include "sim/analysis/images.hpp"
#include "sim/cli/commands.hpp"
#include "sim/core/error.hpp"

namespace tpsim::cli {
namespace {

struct CompareCommandOptions {
    std::vector<std::string> files;
    std::string format = "text";
    std::string output;
    std::string html;
    std::string diff_images;
    std::vector<std::string> keys;
};

/// Writes a difference image of each later run's image against A's where the two differ, and
/// says on standard error which files it wrote.
void write_difference_images(const std::vector<analysis::StatsFile>& runs,
                             const analysis::Comparison& comparison,
                             const std::filesystem::path& dir) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec)
        throw Error(fmt::format("cannot make the --diff-images folder '{}': {}; give a folder "
                                "that can be written",
                                dir.string(), ec.message()));
    bool any = false;
    for (size_t i = 1; i < runs.size(); ++i) {
        const auto& d = comparison.images[i - 1];
        if (!d || !d->compared() || d->differing_pixels == 0) continue;
        const std::string b = analysis::run_letter(i);
        const analysis::Rgb8 image = analysis::read_rgb8(*runs[i].run_file("image"), "image");
        const analysis::Rgb8 base = analysis::read_rgb8(*runs[0].run_file("image"), "image");
        const auto files =
            analysis::write_difference_images(image, base, 0, dir / fmt::format("{}-vs-A", b));
        std::vector<std::string> names;
        for (const auto& file : files)
            names.push_back(file.string());
        std::cerr << fmt::format("difference image of {} against A (red: {} brighter, blue: {} "
                                 "darker): {}\n",
                                 b, b, b, fmt::join(names, ", "));
        any = true;
    }
    if (!any) std::cerr << "difference images: none written, no image differs from A's\n";
}

int run_compare(const CompareCommandOptions& o) {
    if (o.files.size() < 2)
        throw Error(fmt::format("compare needs at least two statistics files, got {}; e.g. tpsim "
                                "compare a.json b.json",
                                o.files.size()));
    // Bad output paths are found before any file is read.
    if (!o.output.empty()) check_output_path(o.output, "the comparison");
    if (!o.html.empty()) check_output_path(o.html, "the HTML comparison");
    std::vector<analysis::StatsFile> runs;
    for (const std::string& file : o.files)
        runs.push_back(analysis::load_stats_file(file));
    const analysis::Comparison comparison = analysis::compare(runs, o.keys);
    const analysis::Format format = o.format == "markdown" ? analysis::Format::markdown
                                    : o.format == "csv"    ? analysis::Format::csv
                                    : o.format == "json"   ? analysis::Format::json
                                                           : analysis::Format::text;
    // Files first: a reader that closes standard output early (| head) must not cost them.
    if (!o.diff_images.empty()) write_difference_images(runs, comparison, o.diff_images);
    if (!o.html.empty())
        write_output(o.html, analysis::comparison_page(runs, comparison, analysis::load_chart_js()),
                     "the HTML comparison");
    if (!o.output.empty()) {
        std::ostringstream text;
        analysis::write_comparison(comparison, format, text);
        write_output(o.output, text.str(), "the comparison");
    } else {
        // Colour only for a person at a terminal, never in a file or pipe.
        analysis::write_comparison(comparison, format, std::cout,
                                   format == analysis::Format::text && isatty(STDOUT_FILENO));
    }
    return 0;
}

}  // namespace

Command add_compare_command(CLI::App& app) {
    auto* command = app.add_subcommand(
        "compare", "Compare statistics files (tpsim render --stats-json) side by side: each "
                   "later run with its ratio to the first, and what differs in setup and image");
    auto o = std::make_shared<CompareCommandOptions>();
    command->add_option("files", o->files, "Statistics files (two or more); the first is the base")
        ->required();
    command->add_option("--format", o->format, "Output format")
        ->check(CLI::IsMember({"text", "markdown", "csv", "json"}))
        ->capture_default_str();
    command
        ->add_option("--keys", o->keys,
                     "Only these statistics (shell patterns, comma-separated), e.g. "
                     "--keys 'chip/cycles,region/bvh_nodes/*'")
        ->delimiter(',')
        ->allow_extra_args(false);
    command->add_option("-o,--output", o->output, "Write the comparison here [default: stdout]");
    command->add_option("--html", o->html,
                        "Also write a self-contained HTML page with charts here");
    command->add_option("--diff-images", o->diff_images,
                        "Write a difference image of each later run's image against A's into "
                        "this folder (made if missing) where the two differ: B-vs-A.diff.png, "
                        "and an enlarged copy of a small image");
    return {command, [o] { return run_compare(*o); }};
}

}  // namespace tpsim::cli
