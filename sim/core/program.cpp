#include "sim/core/program.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>

#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>

#include "sim/core/error.hpp"

extern char** environ;

namespace tpsim {

bool ProgramExit::succeeded() const {
    return exit_code() == 0;
}

int ProgramExit::exit_code() const {
    return start_error == 0 && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

ProgramExit run_program(const std::vector<std::string>& args) {
    std::vector<char*> argv;
    for (const std::string& arg : args)
        argv.push_back(const_cast<char*>(arg.c_str()));
    argv.push_back(nullptr);
    std::cout.flush();
    std::fflush(stdout);
    ProgramExit exit;
    pid_t child = 0;
    exit.start_error = posix_spawnp(&child, argv[0], nullptr, nullptr, argv.data(), environ);
    if (exit.start_error != 0) return exit;
    while (waitpid(child, &exit.status, 0) < 0)
        if (errno != EINTR) throw Error(fmt::format("lost {}: {}", args[0], std::strerror(errno)));
    return exit;
}

}  // namespace tpsim
