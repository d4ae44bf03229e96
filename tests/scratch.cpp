#include "tests/scratch.hpp"

#include <system_error>

#include <unistd.h>

namespace tpsim::testing {

namespace {

struct ScratchDir {
    std::filesystem::path path =
        std::filesystem::temp_directory_path() / ("tpsim-test-" + std::to_string(getpid()));
    ScratchDir() {
        std::filesystem::remove_all(path);  // a crashed process's, whose pid came round again
        std::filesystem::create_directories(path);
    }
    ~ScratchDir() {
        std::error_code ignored;  // at exit nothing is left to report a failure to
        std::filesystem::remove_all(path, ignored);
    }
};

}  // namespace

const std::filesystem::path& scratch_dir() {
    static const ScratchDir dir;
    return dir.path;
}

std::filesystem::path fresh_scratch_dir(const std::string& name) {
    const std::filesystem::path dir = scratch_dir() / name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

}  // namespace tpsim::testing
