// The tpsim command: parses the command line and hands each subcommand to the libraries.
// To add a subcommand, write an add_<name>_command() that registers its options and returns
// the action to run, and list it in main().
#include <cstdio>
#include <functional>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "sim/core/elf_loader.hpp"
#include "sim/core/error.hpp"
#include "sim/core/machine.hpp"

namespace {

/// A registered subcommand and what to do when the user chose it.
struct Command {
    CLI::App* parser;
    std::function<int()> run;  ///< returns the process exit status
};

/// `tpsim exec PROGRAM.elf`: one thread, exit code = the program's exit code.
Command add_exec_command(CLI::App& app) {
    auto* command = app.add_subcommand(
        "exec", "Run a program on one thread; exit with its exit code (ecall a7=93), or 2 on a "
                "fault");
    struct Options {
        std::string program;
        tpsim::core::MachineConfig machine;
    };
    auto options = std::make_shared<Options>();
    command->add_option("program", options->program, "RV32IMF ELF executable")
        ->required()
        ->check(CLI::ExistingFile);
    command->add_option("--max-instructions", options->machine.max_instructions,
                        "Instructions a thread may run before it is stopped as a runaway")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    command->add_option("--local-store", options->machine.local_store_bytes,
                        "Bytes of per-thread local store (stack); multiple of 16 in [256, 1048576]")
        ->capture_default_str();
    return {command, [options] {
        tpsim::core::Machine machine(tpsim::core::load_elf(options->program), options->machine);
        machine.run();
        return machine.thread(0).exit_code;
    }};
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"tpsim: a cycle-counting simulator of TRaX ray-tracing hardware"};
    app.require_subcommand(1);
    const Command commands[] = {add_exec_command(app)};
    CLI11_PARSE(app, argc, argv);
    try {
        for (const Command& command : commands)
            if (command.parser->parsed()) return command.run();
    } catch (const tpsim::Error& e) {
        fmt::print(stderr, "tpsim: {}\n", e.what());
        return 2;
    }
    return 0;
}
