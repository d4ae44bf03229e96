// Run-time kernel parameters (TRAX_PARAM in kernel/trax.hpp; docs/kernel-api.md): read from the
// ELF's symbol table with their defaults, set from NAME=VALUE text, written into the program's
// .data for the simulator and by name into the native twin.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "sim/core/elf_loader.hpp"

namespace tpsim::render {

/// One parameter a kernel declares, and the value a run gives it.
struct KernelParam {
    enum class Type { float32, int32 };

    std::string name;  ///< as declared: TRAX_PARAM(float, threshold, ...) is "threshold"
    Type type = Type::float32;
    uint32_t address = 0;       ///< of its 4 bytes in the kernel's .data
    uint32_t default_bits = 0;  ///< the value the ELF holds
    uint32_t bits = 0;          ///< the value the run uses: the default unless set
    bool set = false;           ///< given for this run (render --param)

    /// The global the macro defines, trax_param_<type>_<name>: the name the twin is set by.
    std::string symbol() const;
    const char* type_name() const { return type == Type::float32 ? "float" : "int"; }
    /// The value as the shortest text that reads back to the same bits ("0.05", "4").
    std::string text(uint32_t value_bits) const;
    std::string text() const { return text(bits); }
};

/// The parameters `program` declares, with their defaults, by name. Throws tpsim::Error for a
/// trax_param_ symbol the macro cannot have made (another type or size).
std::vector<KernelParam> kernel_params(const core::Program& program);

/// Sets parameters from "NAME=VALUE" assignments; `kernel` names the kernel in messages. Throws
/// tpsim::Error with one line for text without '=', a name the kernel does not declare (listing
/// those it does), a value that is not a number of the parameter's type, and a name given twice.
void set_params(std::vector<KernelParam>& params, const std::vector<std::string>& assignments,
                const std::string& kernel);

/// Writes every parameter's value into the program's .data, where each engine that loads the
/// program (functional, cycle-level) reads it.
void write_params(core::Program& program, const std::vector<KernelParam>& params);

/// "threshold=0.02, first_samples=4": every parameter with the value the run uses.
std::string describe_params(const std::vector<KernelParam>& params);

}  // namespace tpsim::render
