#include "native_twin.hpp"

#include <dlfcn.h>

#include <array>
#include <memory>

#include <fmt/format.h>

#include "kernel/native_twin.h"
#include "sim/core/error.hpp"

namespace tpsim::render {

std::filesystem::path native_twin_of(const std::filesystem::path& kernel_elf) {
    return kernel_elf.parent_path() / ("lib" + kernel_elf.stem().string() + "_native.so");
}

void run_native_twin(const std::filesystem::path& library, std::vector<uint32_t>& global_words,
                     uint32_t num_threads, uint32_t num_tms, uint32_t tm_size) {
    // RTLD_LOCAL keeps each twin's copy of the trax runtime to itself.
    const std::unique_ptr<void, int (*)(void*)> handle(
        dlopen(std::filesystem::absolute(library).c_str(), RTLD_NOW | RTLD_LOCAL), dlclose);
    if (!handle)
        throw Error(fmt::format("cannot load native twin '{}': {} (build it with the kernel's "
                                "NAME_native target)",
                                library.string(), dlerror()));
    const auto run = reinterpret_cast<TpsimNativeRunFn>(dlsym(handle.get(), TPSIM_NATIVE_RUN_SYMBOL));
    if (run == nullptr)
        throw Error(fmt::format("'{}' is not a tpsim native twin (no {} symbol)", library.string(),
                                TPSIM_NATIVE_RUN_SYMBOL));
    std::array<char, 1024> error{};
    const TraxNativeContext context{global_words.data(), uint32_t(global_words.size()),
                                    num_threads,         num_tms,
                                    tm_size,             error.data(),
                                    uint32_t(error.size())};
    if (run(&context) != 0) throw Error(error.data());
}

}  // namespace tpsim::render
