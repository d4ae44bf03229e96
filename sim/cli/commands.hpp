// The tpsim subcommands. Each add_*_command() registers its options on the parser and returns
// the action to run when the user chose it; main() only parses and dispatches.
#pragma once
#include <charconv>
#include <cstdint>
#include <functional>
#include <string>

#include <CLI/CLI.hpp>

namespace tpsim::cli {

struct Command {
    CLI::App* parser;
    std::function<int()> run;  ///< returns the process exit status
};

/// A whole number >= 1 (CLI::PositiveNumber accepts fractions and prints its range as a
/// 300-digit double).
inline const CLI::Validator kPositiveCount(
    [](std::string& value) -> std::string {
        uint64_t number = 0;
        const char* end = value.data() + value.size();
        const auto [parsed_to, error] = std::from_chars(value.data(), end, number);
        if (error == std::errc{} && parsed_to == end && number > 0) return {};
        return "must be a whole number >= 1 (at most 18446744073709551615), got '" + value + "'";
    },
    "COUNT");

Command add_exec_command(CLI::App& app);
Command add_render_command(CLI::App& app);

}  // namespace tpsim::cli
