// The tpsim subcommands. Each add_*_command() registers its options on the parser and returns
// the action to run when the user chose it; main() only parses and dispatches.
#pragma once
#include <charconv>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>

#include <CLI/CLI.hpp>

#include "kernel/kernel_output.hpp"

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

/// A whole number >= 0 (CLI11 wraps "-5" into an unsigned option silently).
inline const CLI::Validator kWholeNumber(
    [](std::string& value) -> std::string {
        uint64_t number = 0;
        const char* end = value.data() + value.size();
        const auto [parsed_to, error] = std::from_chars(value.data(), end, number);
        if (error == std::errc{} && parsed_to == end) return {};
        return "must be a whole number >= 0 (at most 18446744073709551615), got '" + value + "'";
    },
    "COUNT");

/// A whole number in [lo, hi] (image sizes, samples per pixel): the message says the limits.
inline CLI::Validator whole_number_in(uint32_t lo, uint32_t hi) {
    return CLI::Validator(
        [lo, hi](std::string& value) -> std::string {
            uint64_t number = 0;
            const char* end = value.data() + value.size();
            const auto [parsed_to, error] = std::from_chars(value.data(), end, number);
            if (error == std::errc{} && parsed_to == end && number >= lo && number <= hi) return {};
            return "must be a whole number in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                   "], got '" + value + "'";
        },
        std::to_string(lo) + ".." + std::to_string(hi));
}

/// Throws tpsim::Error unless a file can be created at `path` (its directory exists); `what`
/// names the file in the message ("the report").
void check_output_path(const std::filesystem::path& path, const std::string& what);
/// Makes the --output-dir folder (and its parents) unless it exists; throws tpsim::Error when it
/// is a file or cannot be made.
void make_output_dir(const std::filesystem::path& dir);
/// Writes `text` to `path`, throwing tpsim::Error naming both on failure.
void write_output(const std::filesystem::path& path, const std::string& text,
                  const std::string& what);

/// What the kernel printed, under `heading`, in thread order; then, on stderr, one note if some
/// of it was dropped. Nothing when it printed nothing.
void print_kernel_output(const trax::KernelOutput& output, std::string_view heading);

/// A kernel given by name is one of the built kernels (build/kernels/NAME.elf); anything with a
/// slash or ".elf" is a path. Throws tpsim::Error when no built kernel has the name.
std::filesystem::path resolve_kernel(const std::string& kernel);

Command add_exec_command(CLI::App& app);
Command add_render_command(CLI::App& app);
Command add_compare_command(CLI::App& app);
Command add_report_command(CLI::App& app);
Command add_check_command(CLI::App& app);
Command add_new_kernel_command(CLI::App& app);
Command add_converge_command(CLI::App& app);
Command add_sample_check_command(CLI::App& app);
Command add_sweep_command(CLI::App& app);

}  // namespace tpsim::cli
