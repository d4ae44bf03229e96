// The tpsim subcommands. Each add_*_command() registers its options on the parser and returns
// the action to run when the user chose it; main() only parses and dispatches.
#pragma once
#include <functional>

#include <CLI/CLI.hpp>

namespace tpsim::cli {

struct Command {
    CLI::App* parser;
    std::function<int()> run;  ///< returns the process exit status
};

Command add_exec_command(CLI::App& app);
Command add_render_command(CLI::App& app);

}  // namespace tpsim::cli
