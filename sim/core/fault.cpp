#include "sim/core/fault.hpp"

namespace tpsim::core {

std::string_view to_string(FaultKind kind) {
    switch (kind) {
    case FaultKind::NullAccess:
        return "null pointer access";
    case FaultKind::Unmapped:
        return "unmapped access";
    case FaultKind::Misaligned:
        return "misaligned access";
    case FaultKind::MisalignedJump:
        return "misaligned jump";
    case FaultKind::WriteToReadOnly:
        return "write to read-only memory";
    case FaultKind::StackOverflow:
        return "stack overflow";
    case FaultKind::FetchOutsideCode:
        return "jump outside the code";
    case FaultKind::IllegalInstruction:
        return "illegal instruction";
    case FaultKind::Breakpoint:
        return "breakpoint";
    case FaultKind::UnsupportedEcall:
        return "unsupported ecall";
    case FaultKind::BadGlobalRegister:
        return "bad global register";
    case FaultKind::InstructionLimit:
        return "instruction limit reached";
    case FaultKind::Deadlock:
        return "deadlock";
    case FaultKind::SemaphoreNotHeld:
        return "release of a free semaphore";
    }
    return "fault";
}

}  // namespace tpsim::core
