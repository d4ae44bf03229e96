// Guest faults: what a thread did wrong, before and after the machine adds where it happened.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "isa/hart.hpp"
#include "kernel/kernel_output.hpp"
#include "sim/core/error.hpp"

namespace tpsim::core {

enum class FaultKind : uint8_t {
    NullAccess,          ///< load/store below kCodeBase
    Unmapped,            ///< load/store to an address no region maps
    Misaligned,          ///< load/store not aligned to its size (TRaX has no unaligned access)
    MisalignedJump,      ///< jump or taken branch to a target that is not 4-byte aligned
    WriteToReadOnly,     ///< store into text/rodata
    StackOverflow,       ///< access just below the thread's local store
    FetchOutsideCode,    ///< pc left the executable segments
    IllegalInstruction,  ///< word that decodes to no instruction, or an unknown CSR
    Breakpoint,          ///< ebreak
    UnsupportedEcall,    ///< ecall other than exit, with no trap handler installed
    BadGlobalRegister,   ///< atomic on a global register that does not exist
    InstructionLimit,    ///< thread ran past --max-instructions
    Deadlock,            ///< every thread still running waits (barrier, semaphore)
    SemaphoreNotHeld,    ///< tp.semrel of a semaphore nobody holds
};

std::string_view to_string(FaultKind kind);

/// GuestFault::mcause of a fault that stops the thread even when it has a trap handler.
constexpr uint32_t kNoTrap = UINT32_MAX;

/// Raised inside an instruction by memory or the environment; the machine catches it and
/// either traps to the thread's handler (mcause set and mtvec != 0, as the privileged spec
/// has it) or rethrows a Fault that names the thread, pc, function, source line and
/// instruction.
struct GuestFault {
    FaultKind kind;
    std::string detail;         ///< what the instruction did, e.g. "writes 0x7ffff7fc, below ..."
    std::string hint;           ///< how to fix it
    uint32_t mcause = kNoTrap;  ///< isa::cause of the exception a handler may take
    uint32_t mtval = 0;         ///< its mtval (the faulting address)
};

/// A run of a kernel that stopped with an error (a fault, on any engine), carrying what the
/// kernel printed until then: the command shows it before the error's one line, because a
/// student debugging with trax_printf needs it most when the kernel fails.
class KernelError : public Error {
public:
    KernelError(const std::string& message, trax::KernelOutput output)
        : Error(message), output_(std::make_shared<const trax::KernelOutput>(std::move(output))) {}
    const trax::KernelOutput& output() const { return *output_; }

private:
    std::shared_ptr<const trax::KernelOutput> output_;  ///< shared: exceptions are copied
};

/// The one-line, user-facing fault of a simulated thread: "<problem>; <hint>".
class Fault : public KernelError {
public:
    Fault(FaultKind kind, uint32_t thread, uint32_t pc, const std::string& problem,
          const std::string& hint, trax::KernelOutput output)
        : KernelError(problem + "; " + hint, std::move(output)), kind_(kind), thread_(thread),
          pc_(pc), problem_size_(problem.size()) {}
    FaultKind kind() const { return kind_; }
    uint32_t thread() const { return thread_; }
    uint32_t pc() const { return pc_; }
    /// What went wrong and where, without the hint (for callers with a better one).
    std::string problem() const { return std::string(what()).substr(0, problem_size_); }
    std::string hint() const { return std::string(what()).substr(problem_size_ + 2); }
    /// The same fault carrying what the kernel printed until `output` was taken.
    Fault with_output(trax::KernelOutput output) const {
        return Fault(kind_, thread_, pc_, problem(), hint(), std::move(output));
    }

private:
    FaultKind kind_;
    uint32_t thread_;
    uint32_t pc_;
    size_t problem_size_;
};

}  // namespace tpsim::core
