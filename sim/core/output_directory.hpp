// The check every output file gets before a run starts: a long render must not end in a path
// that cannot be written.
#pragma once
#include <filesystem>
#include <string_view>

#include <fmt/format.h>

#include "sim/core/error.hpp"

namespace tpsim {

/// Throws tpsim::Error "<cannot_write>: directory 'D' does not exist" unless the directory
/// `path` would be written into exists; `cannot_write` names the file ("cannot write image 'x'").
inline void require_output_directory(const std::filesystem::path& path,
                                     std::string_view cannot_write) {
    const std::filesystem::path directory =
        path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
    if (std::error_code ec; !std::filesystem::is_directory(directory, ec))
        throw Error(
            fmt::format("{}: directory '{}' does not exist", cannot_write, directory.string()));
}

}  // namespace tpsim
