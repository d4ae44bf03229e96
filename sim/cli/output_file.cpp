// Output of the subcommands: files checked before the work starts and written in one piece, and
// what a kernel printed.
#include <cstdio>
#include <fstream>

#include <fmt/format.h>

#include "sim/cli/commands.hpp"
#include "sim/core/error.hpp"
#include "sim/core/output_directory.hpp"

namespace tpsim::cli {

void check_output_path(const std::filesystem::path& path, const std::string& what) {
    require_output_directory(path, fmt::format("cannot write {} to '{}'", what, path.string()));
    if (std::error_code ec; std::filesystem::is_directory(path, ec))
        throw Error(fmt::format("cannot write {} to '{}': it is a directory; give a file name",
                                what, path.string()));
}

void make_output_dir(const std::filesystem::path& dir) {
    std::error_code ec;
    if (std::filesystem::create_directories(dir, ec); ec || !std::filesystem::is_directory(dir))
        throw Error(fmt::format("--output-dir '{}': cannot make the folder: {}", dir.string(),
                                ec ? ec.message() : "a file of that name is in the way"));
}

void write_output(const std::filesystem::path& path, const std::string& text,
                  const std::string& what) {
    std::ofstream out(path, std::ios::binary);
    out << text;
    if (!out.flush()) throw Error(fmt::format("cannot write {} to '{}'", what, path.string()));
}

void print_kernel_output(const trax::KernelOutput& output, std::string_view heading) {
    if (output.empty()) return;
    fmt::print("{}{}", heading, output.tagged());
    std::fflush(stdout);  // before the note (and an error line) on stderr
    if (const std::string note = output.truncation_note(); !note.empty())
        fmt::print(stderr, "tpsim: warning: {}\n", note);
}

}  // namespace tpsim::cli
