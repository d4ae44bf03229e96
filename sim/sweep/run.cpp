// Running a sweep's jobs: one job in this process, all of them through GNU parallel, or a
// Slurm job array's batch script.
#include <cstring>
#include <fstream>

#include <fmt/format.h>
#include <unistd.h>

#include "sim/core/error.hpp"
#include "sim/core/program.hpp"
#include "sim/render/image_file.hpp"
#include "sim/render/render.hpp"
#include "sim/render/report.hpp"
#include "sim/sweep/sweep.hpp"

namespace tpsim::sweep {
namespace {

/// Writes `path` by writing a temporary file beside it and renaming it into place, so the
/// file is complete whenever it exists (even when the job is killed half way).
template <class Write> void write_atomically(const std::filesystem::path& path, Write write) {
    // The temporary keeps the extension: the image writer picks the format by it.
    const std::filesystem::path temporary =
        path.parent_path() /
        fmt::format(".{}.tmp{}", path.stem().string(), path.extension().string());
    write(temporary);
    std::error_code ec;
    std::filesystem::rename(temporary, path, ec);
    if (ec) throw Error(fmt::format("cannot write '{}': {}", path.string(), ec.message()));
}

void write_text(const std::filesystem::path& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    out << text;
    if (!out.flush()) throw Error(fmt::format("cannot write '{}'", path.string()));
}

render::RenderOptions render_options(const JobRun& run) {
    render::RenderOptions options;
    options.scene = run.scene;
    options.kernel = run.kernel;
    options.engine = run.timing == "none" ? render::Engine::functional : render::Engine::timing;
    if (run.timing == "sampled") options.sampling = render::SamplingOptions{};
    options.accel = run.accel;
    options.image_width = run.width;
    options.image_height = run.height;
    options.samples_per_pixel = run.spp;
    options.seed = run.seed;
    options.chip = run.chip;
    return options;
}

/// A word for a POSIX shell: in single quotes, with any single quote spelt '\''.
std::string shell_quote(const std::string& word) {
    std::string quoted = "'";
    for (char ch : word)
        quoted += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
    return quoted + "'";
}

}  // namespace

bool finished(const std::filesystem::path& dir, const Job& job) {
    std::error_code ec;
    return std::filesystem::is_regular_file(stats_path(dir, job.id), ec);
}

std::vector<const Job*> pending(const Sweep& sweep, const std::filesystem::path& dir) {
    std::vector<const Job*> list;
    for (const Job& job : sweep.jobs)
        if (!finished(dir, job)) list.push_back(&job);
    return list;
}

void run_job(const Sweep& sweep, const Job& job, const std::filesystem::path& dir) {
    const std::filesystem::path json = stats_path(dir, job.id);
    const std::filesystem::path image = json.parent_path() / (job.id + ".png");
    std::filesystem::remove(error_path(dir, job.id));
    try {
        render::RenderOptions options = render_options(job.run);
        const render::RenderResult result = render::render(options);
        write_atomically(image, [&](const std::filesystem::path& p) {
            render::write_image(p, result.rgb, result.scene.width, result.scene.height);
        });
        const render::RunStatistics statistics = render::run_statistics(result);
        Json doc = render::stats_document(options, result, statistics, json, {image, {}});
        doc["sweep"] = {{"id", job.id}, {"file", sweep.file.string()}};
        write_atomically(
            json, [&](const std::filesystem::path& p) { write_text(p, doc.dump(1) + '\n'); });
    } catch (const std::exception& e) {
        write_atomically(error_path(dir, job.id), [&](const std::filesystem::path& p) {
            write_text(p, std::string(e.what()) + '\n');
        });
        throw;
    }
}

std::vector<Failure> failures(const Sweep& sweep, const std::filesystem::path& dir) {
    std::vector<Failure> list;
    for (const Job& job : sweep.jobs) {
        if (finished(dir, job)) continue;
        std::string reason = fmt::format("no error recorded: not run yet, still running, or "
                                         "killed (see {})",
                                         log_dir(dir).string());
        if (std::ifstream in(error_path(dir, job.id)); in && std::getline(in, reason)) {
        }
        list.push_back({&job, reason});
    }
    return list;
}

void run_parallel(const Sweep& sweep, const std::filesystem::path& dir, unsigned workers,
                  const std::filesystem::path& tpsim_exe) {
    const std::vector<const Job*> jobs = pending(sweep, dir);
    if (jobs.empty()) return;
    const std::filesystem::path list = dir / "pending.txt";
    std::string ids;
    for (const Job* job : jobs)
        ids += job->id + '\n';
    write_text(list, ids);
    std::vector<std::string> args = {"parallel",   "--will-cite",
                                     "--jobs",     std::to_string(workers),
                                     "--joblog",   (log_dir(dir) / "parallel.log").string(),
                                     "--arg-file", list.string()};
    if (isatty(STDERR_FILENO) == 1) args.push_back("--bar");
    // -q: the words reach tpsim as they are, whatever the directory's name holds.
    for (const std::string& word : {std::string("-q"), tpsim_exe.string(), std::string("sweep"),
                                    std::string("job"), dir.string(), std::string("{}")})
        args.push_back(word);
    const ProgramExit ran = run_program(args);
    if (ran.start_error != 0)
        throw Error(fmt::format("cannot start GNU parallel ({}): install the Debian package "
                                "'parallel' (scripts/setup does)",
                                std::strerror(ran.start_error)));
    // parallel's status counts failed jobs, which failures() lists; only a parallel that
    // could not run at all (255) is an error here.
    if (ran.exit_code() == 255)
        throw Error(fmt::format("GNU parallel failed (exit status 255); see its messages above "
                                "and {}",
                                (log_dir(dir) / "parallel.log").string()));
}

std::string slurm_script(const Sweep& sweep, const std::filesystem::path& dir,
                         const std::filesystem::path& tpsim_exe,
                         const std::vector<std::string>& sbatch_options) {
    const std::vector<const Job*> jobs = pending(sweep, dir);
    const std::filesystem::path results = std::filesystem::absolute(dir).lexically_normal();
    std::string script = fmt::format(
        "#!/bin/bash\n"
        "# tpsim sweep {}: {} of its {} jobs as one Slurm job array, one array task per job.\n"
        "# Written by tpsim sweep slurm; submit with sbatch, then: tpsim sweep collect {}\n"
        "#SBATCH --job-name=tpsim-sweep\n"
        "#SBATCH --array=0-{}\n"
        "#SBATCH --ntasks=1\n"
        "#SBATCH --cpus-per-task=1\n"
        "#SBATCH --output={}/slurm-%A_%a.out\n",
        sweep.file.string(), jobs.size(), sweep.jobs.size(), results.string(), jobs.size() - 1,
        log_dir(results).string());
    for (const std::string& option : sbatch_options)
        script += "#SBATCH " + option + "\n";
    // The ids are written here, not looked up by index in the plan at run time: a plan
    // rewritten while the array waits in the queue cannot shift them.
    script += "ids=(";
    for (size_t i = 0; i < jobs.size(); ++i)
        script += (i % 6 ? " " : i ? "\n     " : "") + jobs[i]->id;
    script += ")\n";
    script += fmt::format("exec {} sweep job {} \"${{ids[$SLURM_ARRAY_TASK_ID]}}\"\n",
                          shell_quote(std::filesystem::absolute(tpsim_exe).string()),
                          shell_quote(results.string()));
    return script;
}

}  // namespace tpsim::sweep
