// `tpsim check ASSIGNMENT --kernel my.elf`: renders the kernel on the assignment's scenes on the
// simulated chip, compares the images with the references and checks the budgets
// (docs/course/README.md). Exit 0 when every check passes, 1 when one fails.
#include <iostream>
#include <memory>
#include <set>
#include <string>

#include <fmt/format.h>

#include "sim/cli/commands.hpp"
#include "sim/cli/progress_line.hpp"
#include "sim/core/error.hpp"
#include "sim/course/assignment.hpp"
#include "sim/course/check.hpp"

namespace tpsim::cli {
namespace {

struct CheckCommandOptions {
    std::string assignment;
    std::string kernel;
    std::string course = TPSIM_COURSE_DIR;
    std::string output_dir = ".";
    bool update_references = false;
};

int run_check(const CheckCommandOptions& o) {
    const std::filesystem::path dir = course::find_assignment(o.course, o.assignment);
    const course::Assignment assignment = course::load_assignment(dir / "assignment.toml");
    std::error_code ec;
    make_output_dir(o.output_dir);
    course::CheckOptions options;
    options.kernel = o.kernel;
    if (!assignment.baseline.empty()) {
        options.baseline_kernel =
            std::filesystem::path(TPSIM_KERNEL_DIR) / (assignment.baseline + ".elf");
        if (!std::filesystem::is_regular_file(options.baseline_kernel, ec))
            throw Error(fmt::format("assignment {} compares with tpsim's kernel '{}', which is not "
                                    "built (no {}); build it: cmake --build build --target {}_elf",
                                    assignment.id, assignment.baseline,
                                    options.baseline_kernel.string(), assignment.baseline));
    }
    options.output_dir = o.output_dir;
    options.update_references = o.update_references;
    ProgressLine progress;
    options.on_scene = [&](size_t i, const course::AssignmentScene& scene) {
        progress.start(fmt::format("check {}: scene {} ({} of {}) ", assignment.id, scene.name,
                                   i + 1, assignment.scenes.size()));
    };
    options.on_baseline = [&](const course::AssignmentScene& scene) {
        progress.start(fmt::format("check {}: scene {}, baseline {} ", assignment.id, scene.name,
                                   assignment.baseline));
    };
    options.on_progress = [&](const render::Progress& p) { progress.update(p); };
    std::set<std::string> warned;  // each scene's render warns again of the same kernel
    options.on_warning = [&](const std::string& warning) {
        if (!warned.insert(warning).second) return;
        progress.clear();
        fmt::print(stderr, "tpsim: warning: {}\n", warning);
    };

    const course::CheckReport report = course::check(assignment, options);
    progress.clear();
    fmt::print("check    {}{} with {}\n", assignment.id,
               assignment.title.empty() ? "" : " (" + assignment.title + ")", o.kernel);

    std::string scene;
    size_t passed = 0;
    for (const course::CheckResult& r : report.results) {
        if (r.scene != scene) fmt::print("scene    {}\n", scene = r.scene);
        fmt::print("  {:<7}{}  {}\n", r.what, r.passed ? "pass" : "FAIL", r.detail);
        passed += r.passed;
    }
    for (const std::filesystem::path& file : report.files)
        fmt::print("wrote    {}\n", file.string());
    fmt::print("verdict  {} ({} of {} checks passed)\n",
               !report.passed()      ? "FAIL"
               : o.update_references ? "references written"
                                     : "PASS",
               passed, report.results.size());
    return report.passed() ? 0 : 1;
}

}  // namespace

Command add_check_command(CLI::App& app) {
    auto* command = app.add_subcommand(
        "check", "Check a kernel against a course assignment: render it on the assignment's "
                 "scenes on the simulated chip, compare with the reference images, check the "
                 "budgets; exit 0 pass, 1 fail");
    auto o = std::make_shared<CheckCommandOptions>();
    command
        ->add_option("assignment", o->assignment,
                     "Assignment folder name (3-shadows) or number (3)")
        ->required();
    command->add_option("-k,--kernel", o->kernel, "The kernel ELF to check")
        ->required()
        ->check(CLI::ExistingFile);
    command->add_option("--course", o->course, "The course folder (holds assignments/)")
        ->capture_default_str();
    command
        ->add_option("--output-dir", o->output_dir,
                     "Where the kernel's images and the difference images go")
        ->capture_default_str();
    command->add_flag("--update-references", o->update_references,
                      "Instructors: write the kernel's images as the assignment's reference "
                      "images (run it with the reference solution)");
    return {command, [o] { return run_check(*o); }};
}

}  // namespace tpsim::cli
