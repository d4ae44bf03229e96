// Running another program (the compiler, GNU parallel, sbatch) with tpsim's terminal, to its end.
#pragma once
#include <string>
#include <vector>

namespace tpsim {

/// How a program run by run_program() ended.
struct ProgramExit {
    int start_error = 0;  ///< errno when it could not be started (0: it ran)
    int status = 0;       ///< its wait status (<sys/wait.h>) when it ran

    /// It ran and exited with status 0.
    bool succeeded() const;
    /// Its exit status, or -1 when it did not start or a signal ended it.
    int exit_code() const;
};

/// Runs args[0] (looked up in PATH) with `args`, sharing tpsim's standard streams (flushed
/// first, so the order of the output holds), and waits for it. Throws tpsim::Error if it is
/// lost while waiting; a program that cannot be started is reported in start_error, for the
/// caller to say how to get it.
ProgramExit run_program(const std::vector<std::string>& args);

}  // namespace tpsim
