// `tpsim exec PROGRAM.elf`: runs a bare-metal RV32IMF program on one thread.
#include <memory>
#include <string>

#include <fmt/format.h>

#include "sim/cli/commands.hpp"
#include "sim/core/elf_loader.hpp"
#include "sim/core/machine.hpp"

namespace tpsim::cli {

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
    command
        ->add_option("--max-instructions", options->machine.max_instructions,
                     "Instructions a thread may run before it is stopped as a runaway")
        ->capture_default_str()
        ->check(kPositiveCount);
    command
        ->add_option("--local-store", options->machine.local_store_bytes,
                     "Bytes of per-thread local store (stack); multiple of 16 in [256, 1048576]")
        ->capture_default_str();
    return {command, [options] {
                tpsim::core::Machine machine(tpsim::core::load_elf(options->program),
                                             options->machine);
                machine.run();
                fmt::print("{}", machine.output().tagged());
                return machine.thread(0).exit_code;
            }};
}

}  // namespace tpsim::cli
