// Runs a kernel's native twin (libNAME_native.so, see kernel/native_twin.h) over a memory image.
#pragma once
#include <cstdint>
#include <filesystem>
#include <vector>

#include "kernel/kernel_output.hpp"
#include "sim/render/kernel_params.hpp"

namespace tpsim::render {

/// The twin library that belongs to a kernel ELF: dir/NAME.elf -> dir/libNAME_native.so.
std::filesystem::path native_twin_of(const std::filesystem::path& kernel_elf);

/// Where the twin runs: in a child process, so that its crash is an error message (the
/// default), or in tpsim's own process, so that a debugger sees it (render --no-fork).
enum class TwinProcess { child, in_process };

/// Loads the twin, sets its parameters (every one: the library may still hold an earlier run's
/// values) and runs it over `global_words` (modified in place) with the given thread shape;
/// returns what the kernel printed. Throws tpsim::Error if the library cannot be loaded, lacks
/// a parameter, or the kernel reports an error.
trax::KernelOutput run_native_twin(const std::filesystem::path& library,
                                   std::vector<uint32_t>& global_words, uint32_t num_threads,
                                   uint32_t num_tms, uint32_t tm_size,
                                   const std::vector<KernelParam>& params = {},
                                   TwinProcess process = TwinProcess::child);

}  // namespace tpsim::render
