// `tpsim sweep list|run|slurm|collect|job`: parameter sweeps (docs/sweeps.md). A sweep file
// expands into jobs; `run` runs them on this machine through GNU parallel, `slurm` as a Slurm
// job array, both into one results directory that `collect` turns into a table and a page.
#include <chrono>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "sim/analysis/html_report.hpp"
#include "sim/cli/commands.hpp"
#include "sim/core/error.hpp"
#include "sim/core/host_threads.hpp"
#include "sim/core/program.hpp"
#include "sim/sweep/sweep.hpp"

namespace tpsim::cli {
namespace {

struct CollectOptions {
    std::vector<std::string> columns;  // NAME=KEY
    std::vector<std::string> metrics;
    std::string x;
    std::string by;
    bool no_host_time = false;
    std::string csv, markdown, html;
};

struct SweepCommandOptions {
    std::string file;
    std::string dir;
    unsigned workers = std::max(1u, std::thread::hardware_concurrency());
    std::vector<std::string> sbatch_options;
    bool submit = false;
    bool wait = false;
    std::string id;
    CollectOptions collect;
};

std::filesystem::path tpsim_executable() {
    std::error_code ec;
    const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (ec) throw Error("cannot find tpsim's own executable (/proc/self/exe) to run the jobs");
    return self;
}

/// The results directory: -o, or the sweep file's name without .toml in the working directory.
std::filesystem::path results_dir(const SweepCommandOptions& o) {
    return o.dir.empty() ? std::filesystem::path(o.file).stem() : std::filesystem::path(o.dir);
}

sweep::Sweep load(const SweepCommandOptions& o) {
    return sweep::load_sweep(o.file, resolve_kernel);
}

/// "36 jobs (scene 3 x bvh 2 x l1.size_bytes 3 x l2.size_bytes 2)"
std::string shape(const sweep::Sweep& s) {
    std::vector<std::string> parts;
    for (const sweep::Axis& axis : s.axes)
        parts.push_back(fmt::format("{} {}", axis.name, axis.values.size()));
    std::string text = fmt::format("{} job{}", s.jobs.size(), s.jobs.size() == 1 ? "" : "s");
    if (!parts.empty()) text += fmt::format(" ({})", fmt::join(parts, " x "));
    if (!s.zip.empty()) {
        std::vector<std::string> groups;
        for (const auto& group : s.zip)
            groups.push_back(fmt::format("{}", fmt::join(group, " with ")));
        text += fmt::format(", zipped: {}", fmt::join(groups, "; "));
    }
    return text;
}

std::vector<sweep::Column> columns(const CollectOptions& c) {
    std::vector<sweep::Column> list = sweep::default_columns();
    for (const std::string& spec : c.columns) {
        const size_t eq = spec.find('=');
        const std::string name = eq == std::string::npos ? spec : spec.substr(0, eq);
        const std::string key = eq == std::string::npos ? spec : spec.substr(eq + 1);
        if (name.empty() || key.empty())
            throw Error(fmt::format("--column '{}': give NAME=KEY (e.g. "
                                    "operand_stalls=chip/stalls/operand) or a statistic's KEY",
                                    spec));
        list.push_back({name, key, true});
    }
    return list;
}

/// Collects the results directory into the table files and the page; prints the table.
/// Returns the number of jobs that have not finished.
size_t collect_and_write(const sweep::Sweep& s, const std::filesystem::path& dir,
                         const CollectOptions& c) {
    const auto or_default = [&](const std::string& given, const char* name) {
        return given.empty() ? dir / name : std::filesystem::path(given);
    };
    const std::filesystem::path csv = or_default(c.csv, "table.csv");
    const std::filesystem::path markdown = or_default(c.markdown, "table.md");
    const std::filesystem::path html = or_default(c.html, "sweep.html");
    for (const auto& [path, what] :
         {std::pair(csv, "the CSV table"), std::pair(markdown, "the Markdown table"),
          std::pair(html, "the page")})
        check_output_path(path, what);
    const std::string chart_js = analysis::load_chart_js();
    const sweep::Table table = sweep::collect(s, dir, columns(c));
    sweep::ChartChoice charts = sweep::default_charts(table);
    if (!c.metrics.empty()) charts.metrics = c.metrics;
    if (!c.x.empty()) charts.x = c.x;
    charts.by = c.by;
    const sweep::Json document =
        sweep::table_document(table, charts, std::filesystem::path(s.file).stem().string());
    const bool host = !c.no_host_time;
    write_output(csv, sweep::table_csv(table, host), "the CSV table");
    const std::string md = sweep::table_markdown(table, host);
    write_output(markdown, md, "the Markdown table");
    write_output(html, analysis::sweep_page(document, chart_js), "the page");
    std::cout << md;
    fmt::print("table    {} and {}\npage     {}\n", csv.string(), markdown.string(), html.string());
    size_t unfinished = 0;
    for (const sweep::Table::Row& row : table.rows)
        unfinished += row.status != "ok";
    return unfinished;
}

/// Lists the jobs that did not finish; returns the exit status (2 when some did not).
int report_failures(const sweep::Sweep& s, const std::filesystem::path& dir) {
    const std::vector<sweep::Failure> failed = sweep::failures(s, dir);
    if (failed.empty()) return 0;
    fmt::print("unfinished {} of {} jobs:\n", failed.size(), s.jobs.size());
    for (const sweep::Failure& f : failed)
        fmt::print("           {}  {}: {}\n", f.job->id, s.describe(*f.job), f.reason);
    std::fflush(stdout);
    fmt::print(stderr,
               "tpsim: {} of {} jobs did not finish (listed above); fix the cause and run the "
               "same command again: finished jobs are skipped\n",
               failed.size(), s.jobs.size());
    return 2;
}

int run_list(const SweepCommandOptions& o) {
    const sweep::Sweep s = load(o);
    fmt::print("sweep    {}: {}\n", o.file, shape(s));
    for (const sweep::Job& job : s.jobs)
        fmt::print("{}  {}\n", job.id, s.describe(job));
    return 0;
}

int run_local(const SweepCommandOptions& o) {
    const sweep::Sweep s = load(o);
    const std::filesystem::path dir = results_dir(o);
    sweep::write_plan(s, dir);
    const size_t to_run = sweep::pending(s, dir).size();
    fmt::print("sweep    {}: {}; {} finished, {} to run with {} worker{} (GNU parallel)\n", o.file,
               shape(s), s.jobs.size() - to_run, to_run, o.workers, o.workers == 1 ? "" : "s");
    sweep::run_parallel(s, dir, o.workers, tpsim_executable());
    collect_and_write(s, dir, o.collect);
    return report_failures(s, dir);
}

int run_slurm(const SweepCommandOptions& o) {
    if (o.wait && !o.submit) throw Error("--wait waits for the submitted array: give --submit too");
    const sweep::Sweep s = load(o);
    const std::filesystem::path dir = results_dir(o);
    sweep::write_plan(s, dir);
    const size_t to_run = sweep::pending(s, dir).size();
    fmt::print("sweep    {}: {}; {} finished, {} to run as a Slurm job array\n", o.file, shape(s),
               s.jobs.size() - to_run, to_run);
    if (to_run == 0) {
        collect_and_write(s, dir, o.collect);
        return 0;
    }
    const std::filesystem::path script = dir / "sweep.sbatch";
    write_output(script, sweep::slurm_script(s, dir, tpsim_executable(), o.sbatch_options),
                 "the batch script");
    fmt::print("script   {}\n", script.string());
    if (!o.submit) {
        fmt::print("next     sbatch {}; when it is done: tpsim sweep collect {}\n", script.string(),
                   dir.string());
        return 0;
    }
    std::vector<std::string> args = {"sbatch"};
    if (o.wait) args.push_back("--wait");
    args.push_back(script.string());
    const ProgramExit ran = run_program(args);
    if (ran.start_error != 0)
        throw Error(fmt::format("cannot run sbatch ({}): run this on a Slurm cluster's login "
                                "node, or submit {} there yourself",
                                std::strerror(ran.start_error), script.string()));
    // With --wait, sbatch's status says whether every task succeeded; failures() says which.
    if (!o.wait && !ran.succeeded())
        throw Error(fmt::format("sbatch refused {} (its message is above)", script.string()));
    if (!o.wait) {
        fmt::print("next     when the array is done: tpsim sweep collect {}\n", dir.string());
        return 0;
    }
    collect_and_write(s, dir, o.collect);
    return report_failures(s, dir);
}

int run_collect(const SweepCommandOptions& o) {
    const std::filesystem::path dir = o.dir;
    const sweep::Sweep s = sweep::read_plan(dir);
    collect_and_write(s, dir, o.collect);
    return report_failures(s, dir);
}

int run_one_job(const SweepCommandOptions& o) {
    const std::filesystem::path dir = o.dir;
    const sweep::Sweep s = sweep::read_plan(dir);
    const sweep::Job* job = s.find(o.id);
    if (!job)
        throw Error(fmt::format("the sweep in '{}' has no job {}; tpsim sweep list names them",
                                dir.string(), o.id));
    // A sweep's parallelism is its jobs (one per core under GNU parallel, one per Slurm task):
    // each runs on one host thread rather than wait for threads of its own without a core.
    core::set_host_threads(1);
    const auto started = std::chrono::steady_clock::now();
    try {
        sweep::run_job(s, *job, dir);
    } catch (const std::exception& e) {
        throw Error(fmt::format("job {} ({}): {}", job->id, s.describe(*job), e.what()));
    }
    fmt::print("done     {}  {} ({:.1f} s)\n", job->id, s.describe(*job),
               std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
    return 0;
}

void add_collect_options(CLI::App* command, CollectOptions& c) {
    command
        ->add_option("--column", c.columns,
                     "Add a statistic to the table as NAME=KEY, or KEY named by itself (e.g. "
                     "operand_stalls=chip/stalls/operand; docs/statistics.md lists the keys)")
        ->allow_extra_args(false);
    command
        ->add_option("--metric", c.metrics,
                     "Chart this table column against --x; repeat for more [default: cycles "
                     "and dram_bytes_read]")
        ->allow_extra_args(false);
    command->add_option("--x", c.x,
                        "The axis the charts' x axis follows [default: the first axis that is "
                        "not the scene]");
    command->add_option("--by", c.by,
                        "One line per value of this axis, one chart per combination of the "
                        "others [default: one chart per scene, one line per combination of the "
                        "other axes]");
    command->add_flag("--no-host-time", c.no_host_time,
                      "Leave the host time out of the CSV and Markdown tables, so that two "
                      "runs of a sweep compare byte for byte");
    command->add_option("--csv", c.csv, "Write the CSV table here [default: DIR/table.csv]");
    command->add_option("--markdown", c.markdown,
                        "Write the Markdown table here [default: DIR/table.md]");
    command->add_option("--html", c.html,
                        "Write the page with the charts here [default: DIR/sweep.html]");
}

}  // namespace

Command add_sweep_command(CLI::App& app) {
    auto* command = app.add_subcommand(
        "sweep", "Parameter sweeps: expand a sweep file (axes of chip configuration keys, "
                 "scenes, kernels, BVH builders ...) into jobs, run them with GNU parallel or "
                 "as a Slurm job array, and collect one table with charts (docs/sweeps.md)");
    command->require_subcommand(1);
    auto o = std::make_shared<SweepCommandOptions>();
    const auto sweep_file = [&](CLI::App* sub) {
        sub->add_option("file", o->file, "Sweep file (TOML; docs/sweeps.md)")
            ->required()
            ->check(CLI::ExistingFile);
    };
    const auto output_dir = [&](CLI::App* sub) {
        sub->add_option("-o,--output", o->dir,
                        "Results directory (created; a rerun into it skips finished jobs) "
                        "[default: the sweep file's name without .toml]");
    };

    auto* list = command->add_subcommand("list", "Print the jobs a sweep file expands into "
                                                 "(id and axis values) without running them");
    sweep_file(list);

    auto* run = command->add_subcommand(
        "run", "Run the sweep's unfinished jobs on this machine through GNU parallel, collect "
               "the table and page, and list the jobs that did not finish");
    sweep_file(run);
    output_dir(run);
    run->add_option("-j,--jobs", o->workers, "Jobs run at once [default: the number of cores]")
        ->check(whole_number_in(1, 4096));
    add_collect_options(run, o->collect);

    auto* slurm = command->add_subcommand(
        "slurm", "Write a Slurm batch script that runs the sweep's unfinished jobs as a job "
                 "array (one task per job) into a results directory on a shared file system; "
                 "optionally submit it");
    sweep_file(slurm);
    output_dir(slurm);
    slurm
        ->add_option("--sbatch", o->sbatch_options,
                     "An sbatch option for the script, e.g. --sbatch=--partition=long "
                     "--sbatch=--mem=2G")
        ->allow_extra_args(false);
    slurm->add_flag("--submit", o->submit, "Submit the script with sbatch");
    slurm->add_flag("--wait", o->wait,
                    "With --submit: wait until the array has finished, then list the failed "
                    "jobs and collect, as run does");
    add_collect_options(slurm, o->collect);

    auto* collect = command->add_subcommand(
        "collect", "Collect a results directory into one table of every job (CSV, Markdown) "
                   "and a page with charts; list the jobs without results");
    collect->add_option("dir", o->dir, "Results directory")->required();
    add_collect_options(collect, o->collect);

    auto* job = command->add_subcommand(
        "job", "Run one job of a results directory's sweep (what GNU parallel and the Slurm "
               "array tasks run); its statistics file appears only when it succeeded");
    job->add_option("dir", o->dir, "Results directory")->required();
    job->add_option("id", o->id, "Job id (tpsim sweep list)")->required();

    return {command, [o, list, run, slurm, collect] {
                if (list->parsed()) return run_list(*o);
                if (run->parsed()) return run_local(*o);
                if (slurm->parsed()) return run_slurm(*o);
                if (collect->parsed()) return run_collect(*o);
                return run_one_job(*o);
            }};
}

}  // namespace tpsim::cli
