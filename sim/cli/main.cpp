// The tpsim command: parses the command line and hands the chosen subcommand to the libraries.
// To add a subcommand, write an add_<name>_command() (commands.hpp) and list it below.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <iostream>
#include <string>

#include <fmt/format.h>

#include "sim/cli/commands.hpp"
#include "sim/core/fault.hpp"
#include "sim/core/huge_pages.hpp"

int main(int argc, char** argv) {
    tpsim::core::run_with_huge_page_malloc(argv);
    CLI::App app{"tpsim: a cycle-counting simulator of TRaX ray-tracing hardware"};
    // At most one; none is reported below, so that a misspelt subcommand is named as such
    // instead of "A subcommand is required".
    app.require_subcommand(0, 1);
    const tpsim::cli::Command commands[] = {
        tpsim::cli::add_render_command(app),   tpsim::cli::add_exec_command(app),
        tpsim::cli::add_compare_command(app),  tpsim::cli::add_report_command(app),
        tpsim::cli::add_check_command(app),    tpsim::cli::add_new_kernel_command(app),
        tpsim::cli::add_converge_command(app), tpsim::cli::add_sample_check_command(app),
        tpsim::cli::add_sweep_command(app)};
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // --help prints the help through CLI11. A usage error is one line like every other
        // error, naming the help of the subcommand it was made in.
        if (e.get_exit_code() == 0) return app.exit(e);
        std::string help = "tpsim --help";
        for (const tpsim::cli::Command& command : commands)
            if (command.parser->parsed()) help = "tpsim " + command.parser->get_name() + " --help";
        fmt::print(stderr, "tpsim: {} (see {})\n", e.what(), help);
        return 2;
    }
    if (app.get_subcommands().empty()) {
        fmt::print(
            stderr,
            "tpsim: give a subcommand: render, exec, compare, report, converge, sample-check, "
            "sweep, new-kernel or check (tpsim --help)\n");
        return 2;
    }
    int status = 0;
    try {
        for (const tpsim::cli::Command& command : commands)
            if (command.parser->parsed()) status = command.run();
    } catch (const tpsim::core::KernelError& e) {
        // A kernel that failed: first what it printed until then, since a student debugging it
        // with trax_printf needs that most now, then the error's line.
        tpsim::cli::print_kernel_output(e.output(),
                                        "kernel output before the error (by thread):\n");
        fmt::print(stderr, "tpsim: {}\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        // Every tpsim error is one line saying what, where and how to fix it.
        fmt::print(stderr, "tpsim: {}\n", e.what());
        return 2;
    }
    // A report lost on a full disk or a closed pipe is an error, not a success.
    std::cout.flush();
    if (!std::cout || std::fflush(stdout) != 0 || std::ferror(stdout)) {
        fmt::print(stderr,
                   "tpsim: cannot write the report to standard output ({}); free space "
                   "on its device or redirect it elsewhere\n",
                   std::strerror(errno));
        return 2;
    }
    return status;
}
