// Scratch files for the C++ tests and the fuzz harnesses: each process has a directory of its
// own under the system's temporary directory (ctest runs test cases as parallel processes, so
// names never collide), removed with everything in it when the process exits.
#pragma once
#include <filesystem>
#include <string>

namespace tpsim::testing {

/// The process's scratch directory, made on first use.
const std::filesystem::path& scratch_dir();

/// `name` in the scratch directory (a file to write; nothing is made).
inline std::filesystem::path scratch_path(const std::string& name) {
    return scratch_dir() / name;
}

/// A directory `name` in the scratch directory, made empty.
std::filesystem::path fresh_scratch_dir(const std::string& name);

}  // namespace tpsim::testing
