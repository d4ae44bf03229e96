// Output files of the subcommands: checked before the work starts, written in one piece.
#include <fstream>

#include <fmt/format.h>

#include "commands.hpp"
#include "sim/core/error.hpp"

namespace tpsim::cli {

void check_output_path(const std::filesystem::path& path, const std::string& what) {
    const std::filesystem::path directory =
        path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
    std::error_code ec;
    if (!std::filesystem::is_directory(directory, ec))
        throw Error(fmt::format("cannot write {} to '{}': directory '{}' does not exist", what,
                                path.string(), directory.string()));
    if (std::filesystem::is_directory(path, ec))
        throw Error(fmt::format("cannot write {} to '{}': it is a directory; give a file name",
                                what, path.string()));
}

void write_output(const std::filesystem::path& path, const std::string& text,
                  const std::string& what) {
    std::ofstream out(path, std::ios::binary);
    out << text;
    if (!out.flush()) throw Error(fmt::format("cannot write {} to '{}'", what, path.string()));
}

}  // namespace tpsim::cli
