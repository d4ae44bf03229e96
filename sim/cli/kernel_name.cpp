#include <fmt/format.h>

#include "sim/cli/commands.hpp"
#include "sim/core/error.hpp"

namespace tpsim::cli {

std::filesystem::path resolve_kernel(const std::string& kernel) {
    if (kernel.find('/') != std::string::npos || kernel.ends_with(".elf")) return kernel;
    const std::filesystem::path built = std::filesystem::path(TPSIM_KERNEL_DIR) / (kernel + ".elf");
    if (!std::filesystem::exists(built))
        throw Error(fmt::format("no built kernel named '{}' (looked for {}); give a path to an ELF "
                                "or build the kernel's NAME_elf target",
                                kernel, built.string()));
    return built;
}

}  // namespace tpsim::cli
